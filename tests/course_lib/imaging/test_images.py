"""Tests for course_lib.imaging.images: Image/CompressedImage <-> numpy without cv_bridge."""

import array
import sys
import time

import numpy as np
import pytest
import sensor_msgs.msg._image as generated_image_module
from sensor_msgs.msg import CompressedImage, Image

from course_lib.imaging.images import (
    ENCODINGS,
    compressed_to_image,
    convert_encoding,
    image_to_compressed,
    image_to_msg,
    msg_to_image,
    parse_compressed_format,
    to_bgr,
)


def random_image(encoding, height=5, width=7, seed=0):
    """A seeded random image in the shape and dtype of an encoding (odd sizes catch row mix-ups)."""
    layout = ENCODINGS[encoding]
    shape = (height, width) if layout.channels == 1 else (height, width, layout.channels)
    high = np.iinfo(layout.dtype).max + 1
    return np.random.default_rng(seed).integers(0, high, shape).astype(layout.dtype.newbyteorder("="))


def padded_msg(image, encoding, pad, big_endian=False):
    """An Image built by hand with `pad` junk bytes after every row, as some camera drivers send."""
    layout = ENCODINGS[encoding]
    stored = layout.dtype.newbyteorder(">" if big_endian else "<")
    rows = image.astype(stored).reshape(image.shape[0], -1).view(np.uint8)
    junk = np.full((image.shape[0], pad), 0xAB, np.uint8)
    data = np.hstack([rows, junk])
    msg = Image(height=image.shape[0], width=image.shape[1], encoding=encoding,
                is_bigendian=int(big_endian), step=data.shape[1])
    msg.data = array.array("B", data.tobytes())
    return msg


# --- round trips --------------------------------------------------------------------------------

@pytest.mark.parametrize("encoding", list(ENCODINGS))
def test_every_encoding_survives_a_round_trip(encoding):
    """image_to_msg then msg_to_image gives back the same pixels, shape and dtype."""
    image = random_image(encoding)
    msg = image_to_msg(image, encoding)
    layout = ENCODINGS[encoding]
    assert (msg.height, msg.width, msg.encoding, msg.is_bigendian) == (5, 7, encoding, 0)
    assert msg.step == 7 * layout.channels * layout.dtype.itemsize
    back = msg_to_image(msg)
    assert back.dtype == image.dtype and back.dtype.isnative
    np.testing.assert_array_equal(back, image)


@pytest.mark.parametrize("encoding", list(ENCODINGS))
@pytest.mark.parametrize("pad", [1, 3, 64])
def test_padded_rows_are_read_as_a_strided_view(encoding, pad):
    """A step larger than a row is honoured: the padding is skipped, not copied."""
    image = random_image(encoding, seed=pad)
    msg = padded_msg(image, encoding, pad)
    back = msg_to_image(msg)
    np.testing.assert_array_equal(back, image)
    assert back.strides[0] == msg.step
    assert np.shares_memory(back, np.frombuffer(msg.data, np.uint8))


@pytest.mark.parametrize("pad", [0, 2])
def test_big_endian_mono16_arrives_in_native_order(pad):
    """is_bigendian=1 data is byte-swapped into a native uint16 array (a documented copy)."""
    image = random_image("mono16", seed=3)
    msg = padded_msg(image, "mono16", pad, big_endian=True)
    back = msg_to_image(msg)
    assert back.dtype == np.dtype("=u2")
    np.testing.assert_array_equal(back, image)
    assert not np.shares_memory(back, np.frombuffer(msg.data, np.uint8))


def test_a_big_endian_array_is_sent_little_endian():
    """A '>u2' array goes out as little-endian bytes with is_bigendian=0."""
    image = random_image("mono16", seed=4)
    msg = image_to_msg(image.astype(">u2"), "mono16")
    assert msg.is_bigendian == 0
    assert msg.data.tobytes() == image.astype("<u2").tobytes()
    np.testing.assert_array_equal(msg_to_image(msg), image)


def test_little_endian_bytes_on_the_wire():
    """mono16 value 0x0102 is written as bytes 02 01, whatever this computer's byte order."""
    msg = image_to_msg(np.array([[0x0102]], np.uint16), "mono16")
    assert list(msg.data) == [0x02, 0x01]


def test_a_non_contiguous_crop_is_sent_correctly():
    """A crop (a strided view) is copied row by row into the message."""
    image = random_image("bgr8", height=20, width=30, seed=5)
    crop = image[3:11, 4:25:2]
    np.testing.assert_array_equal(msg_to_image(image_to_msg(crop)), crop)


def test_mono_accepts_a_single_channel_axis():
    """A (h, w, 1) array is a valid mono8 image and comes back as (h, w)."""
    image = random_image("mono8")
    back = msg_to_image(image_to_msg(image[:, :, None], "mono8"))
    np.testing.assert_array_equal(back, image)


# --- zero copy and the fast path ------------------------------------------------------------------

def test_receiving_does_not_copy():
    """msg_to_image returns a view over msg.data: a write into it shows up in the message."""
    msg = image_to_msg(random_image("bgr8"))
    view = msg_to_image(msg)
    assert np.shares_memory(view, np.frombuffer(msg.data, np.uint8))
    view[0, 0] = (1, 2, 3)
    assert list(msg.data[:3]) == [1, 2, 3]


def profile_events(function):
    """The Python functions and builtins called while function() runs, in order."""
    events = []

    def record(frame, event, arg):
        if event == "call":
            events.append(frame.f_code.co_name)
        elif event == "c_call":
            events.append(getattr(arg, "__name__", repr(arg)))

    sys.setprofile(record)
    try:
        function()
    finally:
        sys.setprofile(None)
    return events


@pytest.fixture(params=["", "1"], ids=["default", "ROS_PYTHON_CHECK_FIELDS=1"])
def field_checks(request, monkeypatch):
    """Run with rclpy's generated field checks off (the default) and on."""
    monkeypatch.setattr(generated_image_module, "ros_python_check_fields", request.param)
    return request.param


def test_sending_does_not_go_through_python_lists(field_checks):
    """Building a 1080p message does the same Python-level work as a 4x4 one, and no tolist()."""
    small = random_image("bgr8", 4, 4)
    large = random_image("bgr8", 1080, 1920, seed=1)
    messages = []
    small_events = profile_events(lambda: messages.append(image_to_msg(small)))
    large_events = profile_events(lambda: messages.append(image_to_msg(large)))
    assert large_events == small_events  # nothing per pixel, e.g. no generator over values
    assert not {"tolist", "list"} & set(large_events)
    assert type(messages[1].data) is array.array and messages[1].data.typecode == "B"
    assert messages[1].data.tobytes() == large.tobytes()


def test_the_list_detector_can_fail(field_checks):
    """Control: the checks above do catch the naive list path and per-value validation."""
    image = random_image("bgr8", 16, 16)

    def naive():
        msg = Image()
        msg.data = image.ravel().tolist()

    assert "tolist" in profile_events(naive)
    if field_checks:
        # bytes are validated value by value when field checks are on: work grows with the image
        def with_bytes(size):
            return len(profile_events(lambda: setattr(Image(), "data", bytes(size))))
        assert with_bytes(1000) > with_bytes(10)


# --- conversions -----------------------------------------------------------------------------------

def test_mono8_becomes_bgr_with_equal_channels():
    """want='bgr8' turns each grey value v into (v, v, v)."""
    grey = random_image("mono8")
    bgr = msg_to_image(image_to_msg(grey, "mono8"), want="bgr8")
    assert bgr.shape == (5, 7, 3)
    for channel in range(3):
        np.testing.assert_array_equal(bgr[:, :, channel], grey)


@pytest.mark.parametrize("encoding", ["rgb8", "rgba8", "bgra8"])
def test_colour_encodings_become_bgr(encoding):
    """rgb8/rgba8/bgra8 arrive as BGR: channels reordered, alpha dropped."""
    image = random_image(encoding)
    bgr = msg_to_image(image_to_msg(image, encoding), want="bgr8")
    order = [2, 1, 0] if encoding.startswith("rgb") else [0, 1, 2]
    np.testing.assert_array_equal(bgr, image[:, :, order])
    np.testing.assert_array_equal(to_bgr(image, encoding), bgr)


def test_bgr8_to_bgr_is_the_same_view():
    """Asking for the encoding a message already has costs no copy."""
    msg = image_to_msg(random_image("bgr8"))
    assert np.shares_memory(msg_to_image(msg, want="bgr8"), np.frombuffer(msg.data, np.uint8))


def test_bgr_to_mono_matches_opencv_weights():
    """bgr8 -> mono8 uses OpenCV's luma weights (a pure blue pixel is dark)."""
    blue = np.zeros((1, 1, 3), np.uint8)
    blue[..., 0] = 255
    assert convert_encoding(blue, "bgr8", "mono8")[0, 0] == 29  # round(0.114 * 255)


def test_mono16_to_bgr_asks_for_a_scale():
    """16-bit to 8-bit is refused with the ways to scale."""
    msg = image_to_msg(random_image("mono16"), "mono16")
    with pytest.raises(ValueError, match=r"Cannot convert mono16 to bgr8.*>> 8"):
        msg_to_image(msg, want="bgr8")


# --- headers ---------------------------------------------------------------------------------------

def test_header_stamp_and_frame_travel_along():
    """header=, or stamp= (rclpy Time or a Time message) and frame_id=, end up in the header."""
    from builtin_interfaces.msg import Time
    from rclpy.time import Time as RclpyTime
    from std_msgs.msg import Header

    image = random_image("mono8")
    original = Header(stamp=Time(sec=12, nanosec=34), frame_id="camera")
    assert image_to_msg(image, "mono8", header=original).header == original
    assert image_to_msg(image, "mono8", stamp=Time(sec=12, nanosec=34), frame_id="camera").header == original
    from_clock = image_to_msg(image, "mono8", stamp=RclpyTime(seconds=12, nanoseconds=34), frame_id="camera")
    assert from_clock.header == original
    assert image_to_compressed(image, stamp=original.stamp, frame_id="camera").header == original
    with pytest.raises(ValueError, match="either header or stamp/frame_id"):
        image_to_msg(image, "mono8", header=original, frame_id="camera")


# --- compressed images -----------------------------------------------------------------------------

def smooth_bgr(height=48, width=64):
    """A smooth colour image: what JPEG is made for (noise would make any tolerance meaningless)."""
    y, x = np.mgrid[0:height, 0:width]
    return np.dstack([x * 255 // width, y * 255 // height, (x + y) * 255 // (width + height)]).astype(np.uint8)


@pytest.mark.parametrize("encoding", ["bgr8", "mono8", "mono16"])
def test_png_is_lossless(encoding):
    """PNG gives back exactly the pixels, for colour, grey and 16-bit grey."""
    image = random_image(encoding, 24, 32, seed=6)
    msg = image_to_compressed(image, "png")
    assert msg.format == f"{encoding}; png compressed {encoding}"
    back = compressed_to_image(msg)
    assert back.dtype == image.dtype
    np.testing.assert_array_equal(back, image)


def test_jpeg_is_close():
    """JPEG at quality 90 stays within a few grey levels of a smooth image."""
    image = smooth_bgr()
    msg = image_to_compressed(image, "jpeg", quality=90)
    assert msg.format == "bgr8; jpeg compressed bgr8"
    back = compressed_to_image(msg)
    assert back.shape == image.shape
    error = np.abs(back.astype(int) - image.astype(int))
    assert error.mean() < 2.0 and error.max() <= 16


def test_jpeg_quality_changes_size():
    """Lower quality gives fewer bytes (the parameter reaches OpenCV)."""
    image = random_image("bgr8", 64, 64, seed=7)
    assert len(image_to_compressed(image, "jpeg", quality=20).data) < len(
        image_to_compressed(image, "jpeg", quality=95).data)


def test_rgb_input_is_compressed_as_bgr():
    """encoding='rgb8' is converted to BGR before encoding, and the format says so."""
    image = random_image("rgb8", 8, 8, seed=8)
    msg = image_to_compressed(image, "png", encoding="rgb8")
    assert msg.format == "rgb8; png compressed bgr8"
    np.testing.assert_array_equal(compressed_to_image(msg), image[:, :, ::-1])
    np.testing.assert_array_equal(compressed_to_image(msg, want="rgb8"), image)


@pytest.mark.parametrize("text, codec", [
    ("png", "png"), ("jpeg", "jpeg"), ("JPG", "jpeg"), ("", ""),
    ("bgr8; png compressed bgr8", "png"), ("rgb8; jpeg compressed bgr8", "jpeg"),
    ("mono8; png compressed ", "png"),
])
def test_compressed_formats_are_parsed(text, codec):
    """Short formats and image_transport's '<enc>; <codec> compressed <enc>' name the codec."""
    assert parse_compressed_format(text) == codec


def test_short_format_and_empty_format_decode():
    """A message with format 'png', or none, is decoded from its bytes."""
    image = random_image("bgr8", 8, 8, seed=9)
    msg = image_to_compressed(image)
    for text in ("png", ""):
        msg.format = text
        np.testing.assert_array_equal(compressed_to_image(msg), image)


# --- malformed input: every error names the numbers and the fix -------------------------------------

def broken(**changes):
    msg = image_to_msg(np.zeros((480, 640, 3), np.uint8))
    for name, value in changes.items():
        setattr(msg, name, value)
    return msg


@pytest.mark.parametrize("msg, message", [
    (broken(data=array.array("B", bytes(921599))),
     r"Image data has 921599 bytes but step×height is 921600 \(step 1920, height 480\)"),
    (broken(step=1919), r"step 1919 is smaller than one row .*640 × 3 × 1 = 1920.*at least 1920"),
    (broken(encoding="yuv422"), r"Unsupported image encoding 'yuv422'.*bgr8, rgb8, bgra8, rgba8, mono8, mono16"),
    (broken(encoding="BGR8"), r"lower case: 'bgr8'"),
    (broken(width=0), r"0×480 pixels.*set msg.width and msg.height"),
    (broken(height=0, data=array.array("B")), r"640×0 pixels"),
], ids=["short data", "small step", "unknown encoding", "upper case", "zero width", "zero height"])
def test_malformed_images_are_refused_with_the_fix(msg, message):
    """msg_to_image raises ValueError that says what is wrong and what to set."""
    with pytest.raises(ValueError, match=message):
        msg_to_image(msg)


@pytest.mark.parametrize("array_like, encoding, message", [
    (np.zeros((4, 4, 3)), "bgr8", r"bgr8 needs a uint8 array but got float64; convert with np.clip"),
    (np.zeros((4, 4), np.uint16), "mono8", r"mono8 needs a uint8 array but got uint16.*send it as mono16"),
    (np.zeros((4, 4), np.uint8), "mono16", r"mono16 needs a uint16 array but got uint8"),
    (np.zeros((4, 4), np.uint8), "bgr8", r"shape \(height, width, 3\) but got shape \(4, 4\).*'mono8'"),
    (np.zeros((4, 4, 4), np.uint8), "bgr8", r"got shape \(4, 4, 4\).*'bgra8' or 'rgba8'"),
    (np.zeros((4, 4, 3), np.uint8), "mono8", r"mono8 needs an array of shape \(height, width\)"),
    (np.zeros((0, 4, 3), np.uint8), "bgr8", r"empty image of shape \(0, 4, 3\)"),
    (np.zeros((4, 4, 3), np.uint8), "bgr", r"Unsupported image encoding 'bgr'.*supported encodings"),
], ids=["float", "uint16 as mono8", "uint8 as mono16", "grey as bgr8", "4 channels as bgr8",
        "colour as mono8", "empty", "unknown encoding"])
def test_arrays_that_do_not_fit_are_refused(array_like, encoding, message):
    """image_to_msg raises ValueError naming the dtype/shape it needs."""
    with pytest.raises(ValueError, match=message):
        image_to_msg(array_like, encoding)


def test_corrupt_compressed_bytes_are_refused():
    """Bytes OpenCV cannot decode, a truncated PNG, and empty data raise ValueError."""
    good = image_to_compressed(random_image("bgr8", 16, 16, seed=10))
    for data in (b"this is not an image", good.data.tobytes()[: len(good.data) // 2]):
        msg = CompressedImage(format="png", data=array.array("B", data))
        with pytest.raises(ValueError, match=rf"could not decode the {len(data)} bytes.*corrupt"):
            compressed_to_image(msg)
    with pytest.raises(ValueError, match="data is empty"):
        compressed_to_image(CompressedImage(format="jpeg"))


@pytest.mark.parametrize("text", ["tiff", "16UC1; compressedDepth png", "bgr8; webp compressed bgr8"])
def test_unknown_compressed_formats_are_refused(text):
    """Formats other than png/jpeg raise ValueError listing the supported ones."""
    good = image_to_compressed(random_image("bgr8", 4, 4))
    good.format = text
    with pytest.raises(ValueError, match=r"Unknown compressed image format.*supported are png and jpeg"):
        compressed_to_image(good)


@pytest.mark.parametrize("kwargs, message", [
    ({"format": "webp"}, r"Unknown compressed format 'webp'; use 'png'"),
    ({"format": "jpeg", "quality": 101}, r"quality 101 is outside 0-100"),
])
def test_bad_compression_settings_are_refused(kwargs, message):
    """image_to_compressed refuses formats and qualities it cannot honour."""
    with pytest.raises(ValueError, match=message):
        image_to_compressed(random_image("bgr8", 4, 4), **kwargs)


def test_jpeg_refuses_16_bit():
    """16-bit grey can go as PNG only."""
    with pytest.raises(ValueError, match="use format='png' for 16 bits"):
        image_to_compressed(random_image("mono16"), "jpeg")


# --- one real ROS round trip ------------------------------------------------------------------------

def test_an_image_survives_a_real_ros_round_trip():
    """Publish bgr8 and mono16 Images through Fast DDS in-process; the subscriber gets the same pixels."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    sent = {"bgr8": random_image("bgr8", 480, 640, seed=11), "mono16": random_image("mono16", 48, 64, seed=12)}
    received = {}
    context = rclpy.Context()  # own context: no interference with other tests in this process
    rclpy.init(context=context)
    try:
        node = Node("images_round_trip", context=context)
        publisher = node.create_publisher(Image, "images_round_trip", 10)

        def on_image(msg):
            received.setdefault(msg.encoding, msg)

        node.create_subscription(Image, "images_round_trip", on_image, 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        messages = [image_to_msg(image, encoding, frame_id="camera") for encoding, image in sent.items()]
        deadline = time.monotonic() + 20.0  # a bound, not a speed goal: fails only if nothing arrives
        while len(received) < len(sent) and time.monotonic() < deadline:
            for msg in messages:  # repeat: messages sent before discovery matched are lost
                if msg.encoding not in received:
                    publisher.publish(msg)
            executor.spin_once(timeout_sec=0.1)
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)

    assert set(received) == set(sent), f"received only {sorted(received)} within 20 s"
    for encoding, image in sent.items():
        msg = received[encoding]
        assert msg.header.frame_id == "camera"
        back = msg_to_image(msg)
        np.testing.assert_array_equal(back, image)
        assert np.shares_memory(back, np.frombuffer(msg.data, np.uint8))
