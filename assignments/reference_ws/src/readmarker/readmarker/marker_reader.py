"""The marker reader node: camera images in, cropped cat and dog pictures out.

``ros2 run readmarker marker_reader`` subscribes ``image`` (sensor_msgs/Image, sensor-data
QoS) and publishes each fully framed picture on ``cropped_img`` as a
catdog_interfaces/CroppedPicture: which picture (``picture``: CAT = 1, DOG = 2) and the crop as a
PNG sensor_msgs/CompressedImage (``image``), with the header (stamp, frame) of the image it was
cut from. The work is readmarker.crop.crop_pictures; this node only converts messages.
``ros2 launch readmarker catdog_warp.launch.xml`` starts it with the webcam's image_publisher.
"""

from catdog_interfaces.msg import CroppedPicture
import cv2
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image

from course_lib import images, marker_board
from course_lib.ros import sigterm
from readmarker.crop import crop_pictures

#: Seconds between two warnings about bad input images.
WARNING_PERIOD = 5.0

#: The picture number of each picture name (CroppedPicture.picture).
PICTURE_NUMBERS = {'cat': CroppedPicture.CAT, 'dog': CroppedPicture.DOG}


def make_detector(dictionary_name):
    """An ArucoDetector for a dictionary named like 'DICT_4X4_50'.

    Raises:
        ValueError: an unknown name; the message lists the valid ones.
    """
    code = None
    if dictionary_name.startswith('DICT_'):
        code = getattr(cv2.aruco, dictionary_name, None)
    if not isinstance(code, int):
        names = ', '.join(sorted(name for name in dir(cv2.aruco) if name.startswith('DICT_')))
        raise ValueError(f'Unknown ArUco dictionary {dictionary_name!r}; use one of {names} '
                         '(the course board uses DICT_4X4_50)')
    if code == marker_board.ARUCO_DICTIONARY:
        return marker_board.detector()
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(code),
                                   cv2.aruco.DetectorParameters())


class MarkerReader(Node):
    """Crops the pictures framed by ArUco markers out of every camera image.

    Parameters:
        width, height (int, 320, 240): size of the crops.
        dictionary (string, 'DICT_4X4_50'): the ArUco dictionary of the markers.
        image_topic (string, 'image'): where the camera images come from.
        output_topic (string, 'cropped_img'): where the crops go.

    Raises:
        ValueError: a crop size below 2x2 or an unknown dictionary.
    """

    def __init__(self, **kwargs):
        super().__init__('marker_reader', **kwargs)
        width = int(self.declare_parameter('width', marker_board.DEFAULT_SIZE[0]).value)
        height = int(self.declare_parameter('height', marker_board.DEFAULT_SIZE[1]).value)
        dictionary = str(self.declare_parameter('dictionary', 'DICT_4X4_50').value)
        image_topic = str(self.declare_parameter('image_topic', 'image').value)
        output_topic = str(self.declare_parameter('output_topic', 'cropped_img').value)
        if width < 2 or height < 2:
            raise ValueError(f'width and height must be at least 2, not {width}x{height}; '
                             'for example width:=320 height:=240')
        self.size = (width, height)
        self.detector = make_detector(dictionary)
        self.frames_received = 0
        self.bad_frames = 0
        ### BEGIN SOLUTION
        self.crop_publisher = self.create_publisher(CroppedPicture, output_topic, 10)
        self.subscription = self.create_subscription(
            Image, image_topic, self.on_image, qos_profile_sensor_data)
        ### END SOLUTION
        self.get_logger().info(
            f'Reading {dictionary} markers on {self.subscription.topic_name}; '
            f'{width}x{height} crops go to {self.crop_publisher.topic_name}')

    def on_image(self, msg):
        """Crop the fully framed pictures of one image and publish each as PNG."""
        self.frames_received += 1
        try:
            frame = images.msg_to_image(msg, want='bgr8')
            crops = crop_pictures(frame, self.size, self.detector)
        except (ValueError, cv2.error) as error:
            # A bad frame must not stop the stream: say why (not on every frame) and go on.
            self.bad_frames += 1
            self.get_logger().warning(
                f'Skipping an image that cannot be read ({self.bad_frames} so far): {error}',
                throttle_duration_sec=WARNING_PERIOD)
            return
        ### BEGIN SOLUTION
        for name, crop in crops.items():
            self.crop_publisher.publish(CroppedPicture(
                picture=PICTURE_NUMBERS[name],
                image=images.image_to_compressed(crop, 'png', header=msg.header)))
        ### END SOLUTION


def main(args=None):
    sigterm.end_spin_as_ctrl_c()  # `kill` ends the node as Ctrl-C does (see course_lib.ros.sigterm)
    rclpy.init(args=args)
    node = None
    try:
        node = MarkerReader()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
