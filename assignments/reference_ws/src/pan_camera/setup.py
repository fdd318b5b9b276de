from setuptools import find_packages, setup

package_name = 'pan_camera'

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
    description='The services_actions assignment: the pan camera\'s service markers_in_view and action find_pictures.',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'pan_camera_node = pan_camera.pan_camera_node:main',
        ],
    },
)
