"""Images between ROS 2 messages and numpy arrays, without cv_bridge.

Two message types carry camera images in ROS 2:

- ``sensor_msgs/msg/Image``: raw pixels, row by row. ``msg_to_image`` and ``image_to_msg``
  convert it to and from a numpy array shaped the way OpenCV expects: ``(height, width)`` for
  mono images, ``(height, width, channels)`` for colour ones.
- ``sensor_msgs/msg/CompressedImage``: a PNG or JPEG file in a message.
  ``compressed_to_image`` and ``image_to_compressed`` decode and encode it with OpenCV.

Receiving costs no copy: the array returned by ``msg_to_image`` is a view over the message's
own bytes (``msg.data``), so writing into the array writes into the message. The one exception
is a 16-bit image whose byte order differs from this computer's: its bytes have to be swapped,
which needs a copy. Sending copies the pixels once into an ``array.array('B')``, which rclpy's
generated ``data`` setter keeps as it is (with ROS_PYTHON_CHECK_FIELDS=1) or copies with a
single memcpy (the default); going through a Python list of pixel values
(``arr.ravel().tolist()``) is tens to hundreds of times slower (benchmarks/bench_images.py).

Typical use in a node::

    def on_image(self, msg):
        frame = images.msg_to_image(msg, want="bgr8")   # mono8, rgb8, ... all arrive as BGR
        edges = find_edges(frame)                        # a plain numpy function
        self.publisher.publish(images.image_to_msg(edges, "mono8", header=msg.header))
"""

from __future__ import annotations

import array
from typing import NamedTuple

import cv2
import numpy as np
from sensor_msgs.msg import CompressedImage, Image
from std_msgs.msg import Header


class Encoding(NamedTuple):
    """How one ROS image encoding lays out a pixel.

    Attributes:
        channels: values per pixel (1 for mono).
        dtype: numpy type of one value, little-endian for 16-bit encodings (the byte order
            image_to_msg writes; msg_to_image reads either).
        opencv: the name OpenCV's colour-conversion codes use for this layout (``GRAY``,
            ``BGR``, ...), e.g. ``cv2.COLOR_GRAY2BGR``.
    """

    channels: int
    dtype: np.dtype
    opencv: str


#: The encodings this module reads and writes (names as in sensor_msgs/image_encodings.hpp).
ENCODINGS: dict[str, Encoding] = {
    "bgr8": Encoding(3, np.dtype(np.uint8), "BGR"),
    "rgb8": Encoding(3, np.dtype(np.uint8), "RGB"),
    "bgra8": Encoding(4, np.dtype(np.uint8), "BGRA"),
    "rgba8": Encoding(4, np.dtype(np.uint8), "RGBA"),
    "mono8": Encoding(1, np.dtype(np.uint8), "GRAY"),
    "mono16": Encoding(1, np.dtype("<u2"), "GRAY"),
}

#: Compressed formats: the name in CompressedImage.format -> the file extension for cv2.imencode.
COMPRESSED_FORMATS = {"png": ".png", "jpeg": ".jpg", "jpg": ".jpg"}


# ---------------------------------------------------------------------------------------------
# sensor_msgs/Image
# ---------------------------------------------------------------------------------------------

def msg_to_image(msg: Image, want: str | None = None) -> np.ndarray:
    """The pixels of an Image message as a numpy array that shares memory with the message.

    Args:
        msg: a sensor_msgs/msg/Image in one of the ENCODINGS. Rows may be padded
            (``step`` larger than width × channels × bytes per value).
        want: an encoding to convert to, e.g. ``"bgr8"`` for a node that works on BGR and
            should accept mono8, rgb8, bgra8 and rgba8 too. None keeps ``msg.encoding``.

    Returns:
        An array of shape ``(height, width)`` for mono encodings and
        ``(height, width, channels)`` otherwise, uint8 or native-order uint16. Without a
        conversion it is a view over ``msg.data`` (padded rows give a strided view whose
        ``strides[0]`` is ``step``): writing into it changes the message, and while it exists
        ``msg.data`` cannot be resized. Call ``.copy()`` to keep an independent image.
        A copy is made when the 16-bit byte order differs from this computer's, or when
        ``want`` asks for another encoding.

    Raises:
        ValueError: the encoding is not supported, width or height is 0, ``step`` is too small
            for a row, or ``len(msg.data)`` is not step × height.
    """
    layout = _layout(msg.encoding, "msg.encoding")
    height, width, step = msg.height, msg.width, msg.step
    if height == 0 or width == 0:
        raise ValueError(f"Image is {width}×{height} pixels (width×height) and has no pixels to convert; "
                         "the publisher must set msg.width and msg.height (image_to_msg does)")
    row_bytes = width * layout.channels * layout.dtype.itemsize
    if step < row_bytes:
        raise ValueError(f"Image step {step} is smaller than one row of {msg.encoding} pixels "
                         f"({width} × {layout.channels} × {layout.dtype.itemsize} = {row_bytes} bytes); "
                         f"set msg.step to at least {row_bytes}")
    size = len(msg.data)
    if size != step * height:
        raise ValueError(f"Image data has {size} bytes but step×height is {step * height} "
                         f"(step {step}, height {height}); the message is truncated or its step, "
                         f"height or encoding is wrong: data must hold exactly step×height bytes")

    # np.frombuffer wraps the array.array (or bytes) that rclpy put in msg.data without copying;
    # the reshape, the crop of the row padding and the dtype view are all views too.
    flat = np.frombuffer(msg.data, dtype=np.uint8)
    rows = flat.reshape(height, step)[:, :row_bytes]
    stored = layout.dtype.newbyteorder(">" if msg.is_bigendian else "<")
    pixels = rows.view(stored)
    if not stored.isnative:
        pixels = pixels.astype(stored.newbyteorder("="))  # byte swap: the one unavoidable copy
    image = pixels.reshape(height, width, layout.channels)
    if layout.channels == 1:
        image = image[:, :, 0]
    if want is not None:
        image = convert_encoding(image, msg.encoding, want)
    return image


def image_to_msg(array_like, encoding: str = "bgr8", *, header: Header | None = None,
                 stamp=None, frame_id: str = "") -> Image:
    """A sensor_msgs/msg/Image holding a copy of a numpy image.

    Args:
        array_like: the pixels, shaped ``(height, width)`` for mono8/mono16 (``(height, width,
            1)`` works too) or ``(height, width, channels)``; uint8, or uint16 for mono16
            (any byte order). Non-contiguous arrays such as crops are fine.
        encoding: one of ENCODINGS; it must match the array (OpenCV images are bgr8).
        header: the header to send, typically the header of the message the image was made
            from, so that time stamp and frame travel along.
        stamp: instead of header: a builtin_interfaces Time or an rclpy Time
            (``node.get_clock().now()``).
        frame_id: instead of header: the coordinate frame of the camera.

    Returns:
        The message: rows without padding (step = width × channels × bytes per value),
        16-bit values little-endian with ``is_bigendian = 0``, data an ``array.array('B')``.

    Raises:
        ValueError: unknown encoding, an array whose dtype or shape does not fit the encoding,
            an empty array, or header given together with stamp/frame_id.
    """
    layout = _layout(encoding, "encoding")
    image = _check_array(np.asarray(array_like), encoding, layout)
    height, width = image.shape[:2]
    msg = Image()
    msg.header = _make_header(header, stamp, frame_id)
    msg.height = height
    msg.width = width
    msg.encoding = encoding
    msg.is_bigendian = 0
    msg.step = width * layout.channels * layout.dtype.itemsize
    msg.data = _to_byte_array(image, layout.dtype)
    return msg


def _check_array(image: np.ndarray, encoding: str, layout: Encoding) -> np.ndarray:
    """The image if its dtype and shape fit the encoding, with a mono (h, w, 1) made (h, w)."""
    if image.dtype.kind != layout.dtype.kind or image.dtype.itemsize != layout.dtype.itemsize:
        name = layout.dtype.name
        if name == "uint8":
            fix = "convert with np.clip(image, 0, 255).astype(np.uint8)"
            if image.dtype == np.uint16:
                fix += " (or send it as mono16)"
        else:
            fix = f"convert with np.clip(image, 0, 65535).astype(np.{name})"
        raise ValueError(f"{encoding} needs a {name} array but got {image.dtype}; {fix}")
    if layout.channels == 1 and image.ndim == 3 and image.shape[2] == 1:
        image = image[:, :, 0]
    expected = "(height, width)" if layout.channels == 1 else f"(height, width, {layout.channels})"
    fits = image.ndim == 2 if layout.channels == 1 else (image.ndim == 3 and image.shape[2] == layout.channels)
    if not fits:
        raise ValueError(f"{encoding} needs an array of shape {expected} but got shape {image.shape}; "
                         f"{_encoding_for_shape_hint(image)}")
    if image.size == 0:
        raise ValueError(f"Cannot send an empty image of shape {image.shape}; "
                         "an Image needs at least one row and one column")
    return image


def _encoding_for_shape_hint(image: np.ndarray) -> str:
    if image.ndim == 2:
        return "for a grey image use encoding 'mono8' (uint8) or 'mono16' (uint16)"
    if image.ndim == 3 and image.shape[2] in (3, 4):
        names = " or ".join(repr(n) for n, e in ENCODINGS.items() if e.channels == image.shape[2])
        return f"for {image.shape[2]} channels use encoding {names}"
    return "give one image shaped (height, width) or (height, width, 3 or 4)"


def _to_byte_array(image: np.ndarray, dtype: np.dtype) -> array.array:
    """The image's bytes, in dtype's byte order, as the array.array('B') rclpy stores in data.

    The generated setter keeps an array.array('B') as it is (with ROS_PYTHON_CHECK_FIELDS=1)
    or copies it with one memcpy; bytes would be checked value by value under
    ROS_PYTHON_CHECK_FIELDS=1, and a list always goes through every value in Python.
    """
    contiguous = np.ascontiguousarray(image, dtype=dtype)  # no copy if it already is
    data = array.array("B")
    data.frombytes(contiguous.reshape(-1).view(np.uint8))
    return data


def _make_header(header: Header | None, stamp, frame_id: str) -> Header:
    if header is not None:
        if stamp is not None or frame_id:
            raise ValueError("Pass either header or stamp/frame_id, not both; to change a copied "
                             "header, set its fields before passing it")
        return header
    if stamp is None:
        return Header(frame_id=frame_id)
    if hasattr(stamp, "to_msg"):  # rclpy.time.Time
        stamp = stamp.to_msg()
    return Header(stamp=stamp, frame_id=frame_id)


def _layout(encoding: str, what: str) -> Encoding:
    try:
        return ENCODINGS[encoding]
    except KeyError:
        supported = ", ".join(ENCODINGS)
        hint = ""
        if encoding.lower() in ENCODINGS:
            hint = f" (encodings are lower case: {encoding.lower()!r})"
        raise ValueError(f"Unsupported image encoding {encoding!r} in {what}{hint}; "
                         f"supported encodings are {supported}") from None


# ---------------------------------------------------------------------------------------------
# Converting between encodings
# ---------------------------------------------------------------------------------------------

def convert_encoding(image: np.ndarray, encoding: str, want: str) -> np.ndarray:
    """The image converted from one encoding to another with cv2.cvtColor.

    Args:
        image: pixels in ``encoding`` (as msg_to_image returns them).
        encoding: what the image is, one of ENCODINGS.
        want: what it should become, one of ENCODINGS.

    Returns:
        The image itself when the encodings are equal, else a new array.

    Raises:
        ValueError: an unknown encoding, or a conversion between 16-bit and 8-bit, which needs
            a scale only the caller can choose.
    """
    source = _layout(encoding, "encoding")
    target = _layout(want, "want")
    if encoding == want:
        return image
    if source.dtype.itemsize != target.dtype.itemsize:
        raise ValueError(f"Cannot convert {encoding} to {want}: 16-bit and 8-bit images need a scale "
                         "that depends on the sensor; scale it yourself, e.g. "
                         "(image >> 8).astype(np.uint8) or cv2.normalize(image, None, 0, 255, "
                         "cv2.NORM_MINMAX, dtype=cv2.CV_8U), then convert the mono8 result")
    if source.opencv == target.opencv:  # e.g. mono8 <-> mono16 would be caught above
        return image
    code = getattr(cv2, f"COLOR_{source.opencv}2{target.opencv}")
    return cv2.cvtColor(image, code)


def to_bgr(image: np.ndarray, encoding: str) -> np.ndarray:
    """The image as bgr8, from mono8, rgb8, bgra8, rgba8 or bgr8 (returned as it is)."""
    return convert_encoding(image, encoding, "bgr8")


# ---------------------------------------------------------------------------------------------
# sensor_msgs/CompressedImage
# ---------------------------------------------------------------------------------------------

def compressed_to_image(msg: CompressedImage, want: str | None = None) -> np.ndarray:
    """Decode a CompressedImage (PNG or JPEG) with OpenCV.

    Args:
        msg: the message. ``format`` may be the short form (``"png"``, ``"jpeg"``) or the one
            compressed_image_transport writes (``"bgr8; jpeg compressed bgr8"``); an empty
            format lets OpenCV recognise the file by its first bytes.
        want: an encoding to convert to (see msg_to_image), e.g. ``"bgr8"``.

    Returns:
        A new array as OpenCV decodes it: ``(height, width)`` for grey images,
        ``(height, width, 3)`` BGR for colour, 4 channels when a PNG has alpha, uint16 for
        16-bit PNGs. The colour order is BGR even if the original image was rgb8.

    Raises:
        ValueError: an unknown format (e.g. compressedDepth), empty data, or bytes OpenCV
            cannot decode.
    """
    codec = parse_compressed_format(msg.format)
    size = len(msg.data)
    if size == 0:
        raise ValueError("CompressedImage data is empty; the publisher must fill msg.data with "
                         f"{codec or 'PNG or JPEG'} bytes (image_to_compressed does)")
    buffer = np.frombuffer(msg.data, dtype=np.uint8)
    image = cv2.imdecode(buffer, cv2.IMREAD_UNCHANGED)
    if image is None:
        raise ValueError(f"OpenCV could not decode the {size} bytes of this CompressedImage as "
                         f"{codec or 'an image'} (format {msg.format!r}, first bytes "
                         f"{bytes(buffer[:8])!r}); the data is corrupt or not a PNG/JPEG file")
    if want is not None:
        image = convert_encoding(image, _decoded_encoding(image), want)
    return image


def image_to_compressed(array_like, format: str = "png", *, quality: int = 90, encoding: str | None = None,
                        header: Header | None = None, stamp=None, frame_id: str = "") -> CompressedImage:
    """Encode a numpy image as a CompressedImage, as compressed_image_transport would.

    Args:
        array_like: a BGR image ``(height, width, 3)`` or a grey one ``(height, width)``, uint8
            (uint16 grey works with png).
        format: ``"png"`` (lossless) or ``"jpeg"`` (lossy, smaller).
        quality: JPEG quality from 0 to 100; png ignores it.
        encoding: what the array is when it is not bgr8/mono8/mono16, e.g. ``"rgb8"``; it is
            converted to BGR first, like image_transport does. None: mono8/mono16 for 2-D
            arrays, bgr8 otherwise.
        header, stamp, frame_id: as for image_to_msg.

    Returns:
        The message; its format reads like ``"bgr8; png compressed bgr8"`` (original encoding;
        codec; the layout inside the file), which image_transport subscribers understand.

    Raises:
        ValueError: an unknown format, quality outside 0-100, or an array that does not fit.
    """
    codec = format.strip().lower()
    if codec not in COMPRESSED_FORMATS:
        raise ValueError(f"Unknown compressed format {format!r}; use 'png' (lossless) or 'jpeg'")
    if codec == "jpg":
        codec = "jpeg"
    if not 0 <= quality <= 100:
        raise ValueError(f"JPEG quality {quality} is outside 0-100; 90 is a good default")
    image = np.asarray(array_like)
    if encoding is None:
        encoding = ("mono16" if image.dtype == np.uint16 else "mono8") if image.ndim == 2 else "bgr8"
    layout = _layout(encoding, "encoding")
    image = _check_array(image, encoding, layout)
    if layout.channels == 1:
        target = encoding
    else:
        target = "bgr8"
        image = convert_encoding(image, encoding, target)
    if codec == "jpeg" and image.dtype != np.uint8:
        raise ValueError(f"JPEG holds 8-bit images only, got {encoding}; use format='png' for 16 bits")
    params = [cv2.IMWRITE_JPEG_QUALITY, int(quality)] if codec == "jpeg" else []
    ok, encoded = cv2.imencode(COMPRESSED_FORMATS[codec], image, params)
    if not ok:  # pragma: no cover - OpenCV refuses only images the checks above already reject
        raise ValueError(f"OpenCV could not encode a {image.shape} {image.dtype} image as {codec}")
    msg = CompressedImage()
    msg.header = _make_header(header, stamp, frame_id)
    msg.format = f"{encoding}; {codec} compressed {target}"
    data = array.array("B")
    data.frombytes(encoded.reshape(-1))
    msg.data = data
    return msg


def parse_compressed_format(format: str) -> str:
    """The codec named in a CompressedImage.format: "png", "jpeg", or "" when format is empty.

    Raises:
        ValueError: a format this module cannot decode, with the supported ones.
    """
    text = format.strip()
    if not text:
        return ""
    # image_transport: "<encoding>; <codec> compressed <layout>"; older publishers: "<codec>".
    codec_part = text.split(";", 1)[1] if ";" in text else text
    words = codec_part.split()
    codec = words[0].lower() if words else ""
    if codec not in COMPRESSED_FORMATS:
        hint = ""
        if "compresseddepth" in text.lower():
            hint = " (compressedDepth images carry an extra header; decode them with the " \
                   "compressed_depth_image_transport plugin)"
        raise ValueError(f"Unknown compressed image format {format!r}{hint}; supported are png and "
                         "jpeg, written as 'png', 'jpeg' or e.g. 'bgr8; jpeg compressed bgr8'")
    return "jpeg" if codec == "jpg" else codec


def _decoded_encoding(image: np.ndarray) -> str:
    """The encoding of an array as cv2.imdecode returns it."""
    if image.ndim == 2:
        return "mono16" if image.dtype == np.uint16 else "mono8"
    if image.dtype != np.uint8:
        raise ValueError(f"The decoded image is {image.dtype} with {image.shape[2]} channels; only "
                         "8-bit colour images can be converted, read it without want= instead")
    return {3: "bgr8", 4: "bgra8"}[image.shape[2]]
