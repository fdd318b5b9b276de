"""The course webcam as a ROS 2 executable: ``ros2 run webcam image_publisher``.

The node (``image_publisher``, topic ``image``, parameters rate, width, height, source, seed)
is course_lib.imaging.camera.WebcamNode; this module only gives it a package and an entry point.
"""

from course_lib import camera


def main(args=None):
    """Run the webcam node until Ctrl-C."""
    camera.main(args=args)


if __name__ == '__main__':
    main()
