from glob import glob

from setuptools import find_packages, setup

package_name = 'pillar'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.launch.xml')),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='ROS 2 and OpenCV course',
    maintainer_email='course@example.com',
    description='The pillar assignment: find the pillar in the laser scan, mark it and drive to it.',
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'pillar_node = pillar.pillar_node:main',
        ],
    },
)
