"""Crop the cat and dog pictures out of a camera frame: a plain function of numpy arrays.

The marker convention (dictionary, marker ids per picture, which marker corner touches the
picture, crop corners) is course_lib.scenes'; this module only applies it:

1. detect the ArUco markers in the frame;
2. for each picture whose four markers were all found, take the picture's four corners from
   the markers (scenes.picture_corners);
3. warp that quadrilateral onto a width x height crop (scenes.crop_corners).

Example::

    from readmarker.crop import crop_pictures
    crops = crop_pictures(frame)          # {'cat': (240, 320, 3) uint8, ...}
"""

import cv2
import numpy as np

from course_lib import scenes

_DEFAULT_DETECTOR = None


def default_detector():
    """The course's ArucoDetector (scenes.detector()), made once and reused."""
    global _DEFAULT_DETECTOR
    if _DEFAULT_DETECTOR is None:
        _DEFAULT_DETECTOR = scenes.detector()
    return _DEFAULT_DETECTOR


def find_markers(frame, detector=None):
    """Detect markers and keep one instance per id: the largest one.

    A frame can show one id twice (a spare sticker on the table, a reflection). Taking the
    largest instance is a consistent choice: it is the one seen best, and a spare marker far
    away from the camera never replaces a close one. When two instances are equally large, the
    one OpenCV lists first is kept.

    Args:
        frame: a BGR (height, width, 3) or grey (height, width) uint8 image.
        detector: a cv2.aruco.ArucoDetector; the course's DICT_4X4_50 detector when None.

    Returns:
        dict marker id -> float32 array (4, 2) of its corners in OpenCV order.
    """
    detector = detector or default_detector()
    corners, ids, _ = detector.detectMarkers(frame)
    found = {}
    if ids is None:
        return found
    for marker, marker_id in zip(corners, ids.ravel()):
        marker = np.asarray(marker, dtype=np.float32).reshape(4, 2)
        marker_id = int(marker_id)
        area = abs(cv2.contourArea(marker))
        if marker_id not in found or area > found[marker_id][0]:
            found[marker_id] = (area, marker)
    return {marker_id: marker for marker_id, (_, marker) in found.items()}


def _is_picture_shape(corners):
    """True when top-left, top-right, bottom-right, bottom-left make a convex, unmirrored quad.

    A real camera never mirrors the board, so a picture seen from the front always has its
    corners clockwise on the screen (y points down). Markers that were mixed up (a spare
    duplicate chosen) usually break that; such a picture is left out rather than warped into
    nonsense.
    """
    crossings = []
    for i in range(4):
        a, b, c = corners[i], corners[(i + 1) % 4], corners[(i + 2) % 4]
        ab, bc = b - a, c - b
        crossings.append(float(ab[0] * bc[1] - ab[1] * bc[0]))
    return all(value > 0 for value in crossings)


def _check_size(size):
    try:
        width, height = (int(value) for value in size)
    except (TypeError, ValueError):
        raise ValueError(f'size must be (width, height), e.g. {scenes.DEFAULT_SIZE}, '
                         f'not {size!r}') from None
    if width < 2 or height < 2:
        raise ValueError(f'size must be at least 2x2 pixels (width, height), not {size!r}')
    return width, height


def _check_frame(frame_bgr):
    frame = np.asarray(frame_bgr)
    if frame.dtype != np.uint8:
        raise ValueError(f'frame_bgr must be uint8, not {frame.dtype}; convert with '
                         'np.clip(frame, 0, 255).astype(np.uint8)')
    if frame.ndim == 3 and frame.shape[2] == 1:
        frame = frame[:, :, 0]
    if not (frame.ndim == 2 or (frame.ndim == 3 and frame.shape[2] == 3)) or 0 in frame.shape:
        raise ValueError(f'frame_bgr must be a BGR image (height, width, 3) or a grey one '
                         f'(height, width), not shape {frame.shape}')
    return frame


def crop_pictures(frame_bgr, size=scenes.DEFAULT_SIZE, detector=None):
    """The pictures of the board that are fully framed in this frame, cropped and straightened.

    Args:
        frame_bgr: a camera frame, BGR uint8 (height, width, 3); a grey (height, width) frame
            works too (its crops are grey turned BGR).
        size: (width, height) of each crop, as OpenCV takes sizes.
        detector: a cv2.aruco.ArucoDetector; the course's DICT_4X4_50 detector when None.

    Returns:
        dict picture name ('cat', 'dog') -> BGR uint8 array (height, width, 3). A picture is
        present only when all four of its markers were found (for an id seen twice, the
        largest instance counts; see find_markers) and they make a plausible picture outline.

    Raises:
        ValueError: a frame that is not a uint8 BGR or grey image, or a bad size.
    """
    frame = _check_frame(frame_bgr)
    width, height = _check_size(size)
    markers = find_markers(frame, detector)
    target = scenes.crop_corners((width, height))
    crops = {}
    for name in scenes.PICTURES:
        corners = scenes.picture_corners(markers, name)
        if corners is None or not _is_picture_shape(corners):
            continue
        homography = cv2.getPerspectiveTransform(corners, target)
        crop = cv2.warpPerspective(frame, homography, (width, height), flags=cv2.INTER_LINEAR)
        if crop.ndim == 2:
            crop = cv2.cvtColor(crop, cv2.COLOR_GRAY2BGR)
        crops[name] = crop
    return crops
