from setuptools import find_packages, setup

package_name = 'brightness'

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ROS 2 and OpenCV course',
    maintainer_email='course@example.com',
    description='The brightness assignment: the average brightness of camera images, as a plain function and a node.',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'brightness_node = brightness.brightness_node:main',
        ],
    },
)
