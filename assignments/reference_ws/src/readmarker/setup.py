from setuptools import find_packages, setup

package_name = 'readmarker'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', ['launch/catdog_warp.launch.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ROS 2 and OpenCV course',
    maintainer_email='course@example.com',
    description='Reference marker reader: crops the cat and dog pictures framed by ArUco markers.',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'marker_reader = readmarker.marker_reader:main',
        ],
    },
)
