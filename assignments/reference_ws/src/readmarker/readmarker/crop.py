"""Crop the cat and dog pictures out of a camera frame: a plain function of numpy arrays.

The marker convention (dictionary, marker ids per picture, which marker corner touches the
picture, crop corners) is course_lib.marker_board's; this module only applies it:

1. detect the ArUco markers in the frame, and look again for board markers that merged with a
   dark picture corner (find_board_markers);
2. for each picture whose four markers were all found, take the picture's four corners from
   the markers (marker_board.picture_corners);
3. warp that quadrilateral onto a width x height crop (marker_board.crop_corners).

Example::

    from readmarker.crop import crop_pictures
    crops = crop_pictures(frame)          # {'cat': (240, 320, 3) uint8, ...}
"""

import cv2
import numpy as np

from course_lib import boards, marker_board

_DEFAULT_DETECTOR = None


def default_detector():
    """The course's ArucoDetector (marker_board.detector()), made once and reused."""
    global _DEFAULT_DETECTOR
    if _DEFAULT_DETECTOR is None:
        _DEFAULT_DETECTOR = marker_board.detector()
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
    ### BEGIN SOLUTION
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
    ### END SOLUTION


_BOARD_IDS = tuple(i for ids in marker_board.PICTURES.values() for i in ids)

#: (scale, kernel) of the second looks: lighten the frame with a kernel x kernel maximum filter
#: at that scale, which thins every dark area by kernel // 2 / scale pixels.
ERODE_PASSES = ((1, 3), (2, 5))


def find_board_markers(frame, detector=None, erode_passes=ERODE_PASSES, paint_pictures=True):
    """find_markers, then a second look for board markers that merged with a dark picture.

    A marker touches its picture with one corner. Where the picture's corner is dark, the
    thresholded marker and the dark picture are one blob, whose outline is no square, and the
    detector misses the marker. Two second looks separate them:

    1. thin every dark area by a pixel or so (a maximum filter) and detect again: the one-point
       contact breaks while the marker's cells survive; the corners found are moved back out by
       the amount thinned;
    2. when at least two board markers are known, they give the board's homography; paint the
       pictures white where it puts them and detect again, then refine the corners on the frame.

    Args:
        frame, detector: as for find_markers.
        erode_passes: (scale, kernel) pairs of step 1, tried in order until no board marker is
            missing; () skips step 1.
        paint_pictures: run step 2.

    Returns:
        dict marker id -> float32 (4, 2) corners, as find_markers.
    """
    ### BEGIN SOLUTION
    found = find_markers(frame, detector)
    if all(i in found for i in _BOARD_IDS):
        return found
    grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    for scale, kernel in erode_passes:
        bigger = grey if scale == 1 else cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_LINEAR)
        lighter = cv2.dilate(bigger, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (kernel, kernel)))
        thinned = kernel // 2 / scale
        for marker_id, corners in find_markers(lighter, detector).items():
            if marker_id in _BOARD_IDS and marker_id not in found:
                corners = (corners + 0.5) / scale - 0.5
                outward = corners - corners.mean(axis=0)
                outward /= np.linalg.norm(outward, axis=1, keepdims=True)
                found[marker_id] = (corners + outward * thinned * np.sqrt(2)).astype(np.float32)
        if all(i in found for i in _BOARD_IDS):
            return found
    known = [i for i in _BOARD_IDS if i in found]
    if paint_pictures and len(known) >= 2:
        found.update(_markers_beside_painted_pictures(grey, found, known, detector))
    return found
    ### END SOLUTION


def _markers_beside_painted_pictures(grey, found, known, detector):
    ### BEGIN SOLUTION
    board = boards.default_board()  # only its geometry (board units) is used, the same for any pictures
    square = np.concatenate([board.marker_square(i) for i in known])
    seen = np.concatenate([found[i] for i in known])
    homography, _ = cv2.findHomography(square.astype(np.float32), seen.astype(np.float32))
    if homography is None:
        return {}
    painted = grey.copy()
    for name in marker_board.PICTURES:
        slot = cv2.perspectiveTransform(board.picture_slot(name)[None].astype(np.float32), homography)[0]
        cv2.fillConvexPoly(painted, np.round(slot * 16).astype(np.int32), 255, cv2.LINE_AA, shift=4)
    new = {i: c for i, c in find_markers(painted, detector).items() if i in _BOARD_IDS and i not in found}
    if not new:
        return {}
    points = np.concatenate(list(new.values())).reshape(-1, 1, 2).astype(np.float32)
    cv2.cornerSubPix(grey, points, (3, 3), (-1, -1), (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.01))
    return {marker_id: points[4 * k:4 * k + 4].reshape(4, 2) for k, marker_id in enumerate(new)}
    ### END SOLUTION


def _is_picture_shape(corners):
    """True when top-left, top-right, bottom-right, bottom-left make a convex, unmirrored quad.

    A real camera never mirrors the board, so a picture seen from the front always has its
    corners clockwise on the screen (y points down). Markers that were mixed up (a spare
    duplicate chosen) usually break that; such a picture is left out rather than warped into
    nonsense.
    """
    ### BEGIN SOLUTION
    crossings = []
    for i in range(4):
        a, b, c = corners[i], corners[(i + 1) % 4], corners[(i + 2) % 4]
        ab, bc = b - a, c - b
        crossings.append(float(ab[0] * bc[1] - ab[1] * bc[0]))
    return all(value > 0 for value in crossings)
    ### END SOLUTION


def _check_size(size):
    try:
        width, height = (int(value) for value in size)
    except (TypeError, ValueError):
        raise ValueError(f'size must be (width, height), e.g. {marker_board.DEFAULT_SIZE}, '
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


def crop_pictures(frame_bgr, size=marker_board.DEFAULT_SIZE, detector=None, second_look=True):
    """The pictures of the board that are fully framed in this frame, cropped and straightened.

    Args:
        frame_bgr: a camera frame, BGR uint8 (height, width, 3); a grey (height, width) frame
            works too (its crops are grey turned BGR).
        size: (width, height) of each crop, as OpenCV takes sizes.
        detector: a cv2.aruco.ArucoDetector; the course's DICT_4X4_50 detector when None.
        second_look: look again for board markers merged with a dark picture corner
            (find_board_markers); False takes the detector's markers only (find_markers).

    Returns:
        dict picture name ('cat', 'dog') -> BGR uint8 array (height, width, 3). A picture is
        present only when all four of its markers were found (for an id seen twice, the
        largest instance counts; see find_markers; markers merged with a dark picture corner
        are looked for again, see find_board_markers) and they make a plausible picture outline.

    Raises:
        ValueError: a frame that is not a uint8 BGR or grey image, or a bad size.
    """
    ### BEGIN SOLUTION
    frame = _check_frame(frame_bgr)
    width, height = _check_size(size)
    markers = find_board_markers(frame, detector) if second_look else find_markers(frame, detector)
    target = marker_board.crop_corners((width, height))
    crops = {}
    for name in marker_board.PICTURES:
        corners = marker_board.picture_corners(markers, name)
        if corners is None or not _is_picture_shape(corners):
            continue
        homography = cv2.getPerspectiveTransform(corners, target)
        crop = cv2.warpPerspective(frame, homography, (width, height), flags=cv2.INTER_LINEAR)
        if crop.ndim == 2:
            crop = cv2.cvtColor(crop, cv2.COLOR_GRAY2BGR)
        crops[name] = crop
    return crops
    ### END SOLUTION
