from setuptools import find_packages, setup

package_name = 'pubsub'

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
    description=('The pubsub assignment: a publisher and a subscriber of tutorial_interfaces/MsgTutorial '
                 'on ros_tutorial_msg.'),
    license='Apache-2.0',
    extras_require={'test': ['pytest']},
    entry_points={
        'console_scripts': [
            'topic_publisher = pubsub.topic_publisher:main',
            'topic_subscriber = pubsub.topic_subscriber:main',
        ],
    },
)
