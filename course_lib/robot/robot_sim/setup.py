"""robot_sim for colcon, on a full ROS 2 install: ``colcon build`` in a workspace that holds this
folder (the pip install gets the same files from ``make setup``: course_lib.robot.install). Its
code is course_lib.robot: install the course's course_lib into the Python that ROS runs first."""

from glob import glob

from setuptools import setup

package_name = 'robot_sim'

setup(
    name=package_name,
    version='0.1.0',
    packages=[],  # the simulator is course_lib.robot.simulator_node
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.xml')),
        ('share/' + package_name + '/worlds', glob('worlds/*.xml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ROS 2 and OpenCV course',
    maintainer_email='course@example.com',
    description='The course\'s simulated mobile robot: ros2 launch robot_sim husky.launch.xml world:=pillar',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'simulator = course_lib.robot.simulator_node:main',
        ],
    },
)
