"""The marker board convention of the vision lessons and the catdog_warp assignment, written once here.

- Markers come from ArUco's ``DICT_4X4_50`` (:func:`dictionary`, :func:`detector`).
- The cat is framed by markers 1, 2, 3, 4 and the dog by markers 5, 6, 7, 8, in the order
  top-left, top-right, bottom-right, bottom-left (:data:`PICTURES`).
- Each marker sits just outside its picture corner and touches it with one of its own corners
  (OpenCV order: 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left of the upright marker).
  The picture's corners are marker 1's corner 2, marker 2's corner 3, marker 3's corner 0 and
  marker 4's corner 1 (:data:`CORNER_OF_MARKER`); no picture content is hidden by a marker.
- A crop maps the picture's top-left corner to pixel (0, 0) and its other corners to the other
  corner pixels of the crop (:func:`crop_corners`); the default crop is 320x240 (width x height),
  BGR, uint8 (:data:`DEFAULT_SIZE`).
- A crop is right when :func:`crop_similarity` with the expected one reaches
  :data:`SAME_CROP_THRESHOLD`.

Coordinates: frame and picture pixels follow OpenCV (the centre of pixel (0, 0) is the point (0, 0)).
"""

from __future__ import annotations

from collections.abc import Mapping

import cv2
import numpy as np

# --------------------------------------------------------------------------------------------
# The convention
# --------------------------------------------------------------------------------------------

#: The ArUco dictionary of every marker in the course.
ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50

#: Marker ids framing each picture, in the order top-left, top-right, bottom-right, bottom-left.
PICTURES: dict[str, tuple[int, int, int, int]] = {"cat": (1, 2, 3, 4), "dog": (5, 6, 7, 8)}

#: For the markers in PICTURES order: which of the marker's own corners is the picture's corner.
CORNER_OF_MARKER: tuple[int, int, int, int] = (2, 3, 0, 1)

#: Default crop size, (width, height) as OpenCV takes it.
DEFAULT_SIZE: tuple[int, int] = (320, 240)

#: crop_similarity at or above this means "the same crop". Measured on seeds 0-99 easy and
#: 0-299 hard with a reference detect + warp (as in tests/course_lib/imaging/test_scenes.py): correct crops of all 299
#: fully framed pictures scored 0.967 or more against expected_crops() (0.91 or more against the
#: printed picture, source="picture"), while crops with the corners in a wrong order (mirrored,
#: upside down, rotated by 90/180/270 degrees) or of the other picture scored 0.53 at most. The
#: threshold sits between the groups with a margin on both sides.
SAME_CROP_THRESHOLD = 0.8


def dictionary() -> cv2.aruco.Dictionary:
    """The course's ArUco dictionary (DICT_4X4_50)."""
    return cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY)


def detector(parameters: cv2.aruco.DetectorParameters | None = None) -> cv2.aruco.ArucoDetector:
    """An ArucoDetector for the course's markers.

    Args:
        parameters: detector parameters; OpenCV's defaults when None.

    Returns:
        ``cv2.aruco.ArucoDetector``; call ``detectMarkers(image)`` to get ``(corners, ids, rejected)``.
    """
    return cv2.aruco.ArucoDetector(dictionary(), parameters or cv2.aruco.DetectorParameters())


def picture_corners(marker_corners_by_id: Mapping[int, np.ndarray], picture: str) -> np.ndarray | None:
    """The four corners of a picture from the corners of its markers.

    Args:
        marker_corners_by_id: marker id -> that marker's 4 corners in OpenCV order, shape (4, 2)
            or (1, 4, 2) as ``detectMarkers`` returns them.
        picture: "cat" or "dog" (a key of PICTURES).

    Returns:
        float32 array (4, 2): the picture's top-left, top-right, bottom-right and bottom-left
        corners, or None when one of the picture's markers is missing from the mapping.

    Raises:
        KeyError: unknown picture name.
    """
    if picture not in PICTURES:
        raise KeyError(f"Unknown picture {picture!r}: use one of {sorted(PICTURES)}")
    corners = []
    for marker_id, corner in zip(PICTURES[picture], CORNER_OF_MARKER, strict=True):
        if marker_id not in marker_corners_by_id:
            return None
        marker = np.asarray(marker_corners_by_id[marker_id], dtype=np.float32).reshape(4, 2)
        corners.append(marker[corner])
    return np.array(corners, dtype=np.float32)


def crop_corners(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """Where a picture's four corners go in a crop of the given (width, height).

    Returns:
        float32 array (4, 2): (0, 0), (w-1, 0), (w-1, h-1), (0, h-1), the centres of the crop's
        corner pixels, in PICTURES order (top-left, top-right, bottom-right, bottom-left).
    """
    width, height = _check_size(size, "crop size")
    return np.array([[0, 0], [width - 1, 0], [width - 1, height - 1], [0, height - 1]], dtype=np.float32)


# --------------------------------------------------------------------------------------------
# Comparing crops
# --------------------------------------------------------------------------------------------

_COMPARE_WIDTH = 80


def crop_similarity(a: np.ndarray, b: np.ndarray) -> float:
    """How alike two crops are, from 0 (unrelated or inverted) to 1 (the same picture).

    Both crops are turned grey, shrunk to 80 pixels wide (b to a's shape), blurred a little,
    stripped of a 5 % border and compared by normalised cross-correlation, clipped at 0.
    Shrinking, blurring and the border forgive a corner that is off by a pixel or two;
    normalising forgives brightness and contrast changes; a crop that is mirrored, rotated or
    of the other picture correlates weakly.
    Compare the result with SAME_CROP_THRESHOLD.

    Args:
        a, b: images, BGR or grey, any dtype that OpenCV can convert (uint8 is usual).

    Returns:
        A float in [0, 1].

    Raises:
        ValueError: an input is not a 2-D or 3-D image with at least one pixel.
    """
    ga, gb = _grey(a, "a"), _grey(b, "b")
    height = max(1, round(_COMPARE_WIDTH * ga.shape[0] / ga.shape[1]))
    shape = (_COMPARE_WIDTH, height)
    ga = cv2.GaussianBlur(cv2.resize(ga, shape, interpolation=cv2.INTER_AREA), (0, 0), 1.0)
    gb = cv2.GaussianBlur(cv2.resize(gb, shape, interpolation=cv2.INTER_AREA), (0, 0), 1.0)
    # Leave out a 5 % border: a corner off by a pixel or two shows a sliver of board there,
    # which would otherwise dominate low-contrast pictures.
    my, mx = height // 20, _COMPARE_WIDTH // 20
    if height > 2 * my + 2:
        ga, gb = ga[my:height - my, mx:-mx], gb[my:height - my, mx:-mx]
    ga -= ga.mean()
    gb -= gb.mean()
    na, nb = float(np.sqrt((ga * ga).sum())), float(np.sqrt((gb * gb).sum()))
    flat = 1e-3 * ga.size  # below ~0.03 grey levels of spread, an image is flat
    if na < flat or nb < flat:
        # Correlation is undefined for a flat image: two flat crops are alike, one is not.
        return 1.0 if na < flat and nb < flat else 0.0
    return float(np.clip((ga * gb).sum() / (na * nb), 0.0, 1.0))


def _grey(image: np.ndarray, name: str) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim not in (2, 3) or image.shape[0] == 0 or image.shape[1] == 0:
        raise ValueError(f"{name} must be an image of shape (height, width) or (height, width, 3), "
                         f"not {image.shape}")
    if image.ndim == 3:
        if image.shape[2] == 1:
            image = image[:, :, 0]
        elif image.shape[2] in (3, 4):
            image = cv2.cvtColor(image.astype(np.float32), cv2.COLOR_BGR2GRAY if image.shape[2] == 3
                                 else cv2.COLOR_BGRA2GRAY)
        else:
            raise ValueError(f"{name} has {image.shape[2]} channels: pass a BGR or grey image")
    return image.astype(np.float32)


def _check_size(size, what: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be (width, height), for example (320, 240), not {size!r}") from None
    if width < 1 or height < 1:
        raise ValueError(f"{what} must be at least 1x1 pixels, not {width}x{height}")
    return width, height
