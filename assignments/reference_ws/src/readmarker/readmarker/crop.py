"""Crop the cat and dog pictures out of a camera frame: a plain function of numpy arrays.

The marker convention (dictionary, marker ids per picture, which marker corner touches the
picture, crop corners) is course_lib.imaging.marker_board's; this module only applies it:

1. detect the ArUco markers in the frame, and look again, where a picture's own markers (or,
   when they cannot tell, the course board's layout) put them, for board markers that merged
   with a dark picture corner (find_board_markers);
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
    for marker, marker_id in zip(corners, ids.ravel(), strict=True):
        marker = np.asarray(marker, dtype=np.float32).reshape(4, 2)
        marker_id = int(marker_id)
        area = abs(cv2.contourArea(marker))
        if marker_id not in found or area > found[marker_id][0]:
            found[marker_id] = (area, marker)
    return {marker_id: marker for marker_id, (_, marker) in found.items()}
    ### END SOLUTION


_BOARD_IDS = tuple(i for ids in marker_board.PICTURES.values() for i in ids)

#: (scale, kernel) of the thinned looks: lighten the image with a kernel x kernel maximum filter
#: at that scale, which thins every dark area by kernel // 2 / scale pixels.
ERODE_PASSES = ((1, 3), (2, 5))

#: Board units of paper kept around a predicted marker (its quiet zone is 24 units wide).
KEPT_PAPER = 16

#: Board units by which the painted-out picture reaches into the predicted marker, tried in
#: order: a prediction a pixel or two off leaves no sliver of a dark picture touching the
#: marker at the larger overlap, while the smaller one notches a small marker's corner less.
PICTURE_OVERLAPS = (2, 5)

#: Half the side of cv2.cornerSubPix's window, as a fraction of the marker's side (the corners
#: of a marker found in a window are refined on the frame).
CORNER_WINDOW = 1 / 8

#: Pixels a marker found where it was predicted must lie inside the frame: it is cut by the
#: frame edge otherwise (the detector itself keeps 3 pixels).
FRAME_INSET = 2


def find_board_markers(frame, detector=None, erode_passes=ERODE_PASSES, predict=True):
    """find_markers, then a second look for board markers that merged with what they touch.

    A marker touches its picture with one corner. Where the picture's corner is dark (black,
    brown, navy, a dark texture), the thresholded marker and the picture are one blob, whose
    outline is no square, and the detector misses the marker. Two second looks separate them:

    1. a picture's markers found give its homography (the board's layout may be any), which
       predicts where each missing marker is; there, in a small window with everything but the
       marker and its paper painted over (look_where_predicted), the detector looks again;
    2. when fewer than two board markers are known, or (the first, cheapest pass only) a
       picture's markers found leave its shape open (one, or two on one side): thin every dark
       area by a pixel or so (a maximum filter) and detect again on the whole frame: the
       one-point contact breaks while the marker's cells survive; the corners found are moved
       back out by the amount thinned. Then step 1 again with the markers found.

    Args:
        frame, detector: as for find_markers.
        erode_passes: (scale, kernel) pairs of step 2, tried in order; () skips step 2.
        predict: run step 1.

    Returns:
        dict marker id -> float32 (4, 2) corners, as find_markers.
    """
    ### BEGIN SOLUTION
    found = find_markers(frame, detector)
    grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    if predict:
        found.update(look_where_predicted(grey, found, detector))
    for number, (scale, kernel) in enumerate(erode_passes):
        if sum(i in found for i in _BOARD_IDS) >= 2 and not (number == 0 and _shape_open(found)):
            break
        new = {i: c for i, c in thinned_markers(grey, scale, kernel, detector).items()
               if i in _BOARD_IDS and i not in found}
        found.update(new)
        if new and predict:
            found.update(look_where_predicted(grey, found, detector))
    return found
    ### END SOLUTION


def _shape_open(found):
    """True when a picture has markers found, but not all four, and they do not fix its shape
    (one, or two on one side: see picture_prediction)."""
    for ids in marker_board.PICTURES.values():
        where = {ids.index(i) for i in ids if i in found}
        if where and len(where) < 4 and not (where & {0, 3} and where & {1, 2} and where & {0, 1} and where & {2, 3}):
            return True
    return False


def thinned_markers(grey, scale, kernel, detector=None):
    """find_markers on `grey` enlarged `scale` times and thinned by a kernel x kernel maximum
    filter (kernel 1: not thinned), with the corners moved back to `grey`'s pixels and out by
    the amount thinned."""
    ### BEGIN SOLUTION
    image = grey if scale == 1 else cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_LINEAR)
    if kernel > 1:
        image = cv2.dilate(image, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (kernel, kernel)))
    thinned = kernel // 2 / scale
    markers = {}
    for marker_id, corners in find_markers(image, detector).items():
        corners = (corners + 0.5) / scale - 0.5
        outward = corners - corners.mean(axis=0)
        outward /= np.linalg.norm(outward, axis=1, keepdims=True)
        markers[marker_id] = (corners + outward * thinned * np.sqrt(2)).astype(np.float32)
    return markers
    ### END SOLUTION


#: (scale, kernel) of the looks in a predicted marker's window, tried in order: as it is, then
#: thinned (ERODE_PASSES) for a sliver of picture left by a prediction a pixel off.
WINDOW_LOOKS = ((1, 1), *ERODE_PASSES)


def look_where_predicted(grey, found, detector=None):
    """Board markers missing from `found`, looked for where the found ones predict them.

    A picture's missing marker is predicted from the picture's own markers when they fix its
    shape: three of four, or two diagonal ones. The markers are squares of one size that touch
    the picture's corners, so their corners give the picture's width and height and its
    homography (picture_prediction), whatever the board's layout. Where that finds nothing, or
    the markers do not fix the shape, the course board's homography (board units -> frame
    pixels), fitted to the corners of every board marker found, predicts it, when it fits all but
    one of them (course_prediction). A small window around the predicted marker keeps the
    marker and KEPT_PAPER units of paper around it and paints the rest, the picture it touches
    included, with the paper's grey: nothing dark touches the marker any more, whatever the
    colour of the picture's corner. The detector looks in that
    window (WINDOW_LOOKS); a marker counts when it has the predicted id and lies where it was
    predicted. Markers found refine the predictions for another round.

    Args:
        grey: the frame, grey uint8 (height, width).
        found: marker id -> corners (4, 2) found so far, as find_markers returns them.
        detector: as for find_markers.

    Returns:
        dict marker id -> float32 (4, 2) corners of the board markers found in this look only.
    """
    ### BEGIN SOLUTION
    new = {}
    while True:
        known = {i: new[i] if i in new else found[i] for i in _BOARD_IDS if i in found or i in new}
        if not known or len(known) == len(_BOARD_IDS):
            return new
        more, course = {}, course_prediction(known)
        for picture, ids in marker_board.PICTURES.items():
            missing = [i for i in ids if i not in known]
            own = picture_prediction({i: known[i] for i in ids if i in known}, picture) if missing else None
            predictions = [p for p in (own, course and course[picture]) if p]
            for marker_id in missing:
                for homography, squares, slot in predictions:  # the next only where one finds nothing
                    corners = _look_in_window(grey, homography, squares[marker_id], slot, marker_id, detector)
                    if corners is not None:
                        more[marker_id] = corners
                        break
        if not more:
            return new
        new.update(more)
    ### END SOLUTION


#: A marker's corners off a fitted homography by more than this fraction of its side do not fit it.
FIT_TOLERANCE = 0.2


def picture_prediction(markers, picture):
    """A picture's homography fitted to its own markers (id -> corners), whatever the board's layout.

    In picture units the picture spans (0, 0)-(width, height) and each marker is a square of side
    boards.Board.MARKER diagonally outside the corner it touches. Width and height are unknown:
    one linear least-squares step gives them (_linear_shape), then the homography is fitted to
    the markers' corners for them. Three markers fix both, and so do two diagonal ones (less
    well); two on one side leave one unknown (None).

    Returns:
        (homography picture units -> frame pixels, {id: its square in picture units}, the
        picture's corners in picture units), or None when the markers do not fix the shape or
        one of them does not fit (FIT_TOLERANCE).
    """
    ### BEGIN SOLUTION
    ids = marker_board.PICTURES[picture]
    where = [ids.index(i) for i in markers]  # 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left
    if len(markers) < 2 or _shape_open(markers):
        return None
    side = boards.Board.MARKER
    seen = np.concatenate([markers[i] for i in markers]).astype(np.float32).reshape(-1, 2)
    width, height = _linear_shape(markers, where, side)
    if width < side / 4 or height < side / 4:
        return None  # no picture: markers mixed up
    squares = _picture_squares(ids, width, height, side)
    model = np.concatenate([squares[i] for i in markers]).astype(np.float32)
    homography, _ = cv2.findHomography(model, seen, 0)
    if homography is None or _misfits(homography, model, seen):
        return None
    slot = np.array([[0, 0], [width, 0], [width, height], [0, height]], np.float64)
    return homography, squares, slot
    ### END SOLUTION


def _linear_shape(markers, where, side):
    """A picture's (width, height) from its markers (id -> corners; `where` their positions 0-3),
    solved in one linear least-squares step.

    A marker corner at picture point (x0 + a * width, y0 + b * height) (a: the marker is on the
    right, b: at the bottom) gives two equations of the homography that are linear in its eight
    entries h and in the six products width * h1, width * h4, width * h7, height * h2,
    height * h5 and height * h8, as in the direct linear transform; the frame points are
    centred and scaled first, so that the system is well conditioned.
    """
    seen = np.concatenate([markers[i] for i in markers]).astype(np.float64).reshape(-1, 2)
    seen = (seen - seen.mean(axis=0)) / max(1e-9, float(np.abs(seen - seen.mean(axis=0)).mean()))
    squares = _picture_squares(range(4), 0.0, 0.0, 1.0)
    rows, values = [], []
    for index, (u, v) in enumerate(seen):
        position = where[index // 4]
        x, y = squares[position][index % 4]
        a, b = float(position in (1, 2)), float(position in (2, 3))
        rows.append([x, y, 1, 0, 0, 0, -u * x, -u * y, a, 0, -u * a, b, 0, -u * b])
        rows.append([0, 0, 0, x, y, 1, -v * x, -v * y, 0, a, -v * a, 0, b, -v * b])
        values += [u, v]
    solution = np.linalg.lstsq(np.array(rows), np.array(values), rcond=None)[0]
    h, width_h, height_h = solution[:8], solution[8:11], solution[11:14]
    column_x, column_y = h[[0, 3, 6]], h[[1, 4, 7]]
    width = float(width_h @ column_x / max(1e-12, column_x @ column_x))
    height = float(height_h @ column_y / max(1e-12, column_y @ column_y))
    return width * side, height * side


def _picture_squares(ids, width, height, side):
    """Marker id -> its square (OpenCV corner order) in picture units, for a picture of this size."""
    origins = ((-side, -side), (width, -side), (width, height), (-side, height))
    return {i: np.array([[x, y], [x + side, y], [x + side, y + side], [x, y + side]], np.float64)
            for i, (x, y) in zip(ids, origins, strict=True)}


def _misfits(homography, model, seen):
    """How many markers (four rows of `model` and `seen` each) lie farther than FIT_TOLERANCE of
    their side from where `homography` puts them."""
    errors = np.linalg.norm(_project(homography, model) - seen, axis=1).reshape(-1, 4).max(axis=1)
    sides = np.linalg.norm(seen.reshape(-1, 4, 2) - np.roll(seen.reshape(-1, 4, 2), 1, axis=1), axis=2).min(axis=1)
    return int((errors > FIT_TOLERANCE * sides).sum())


def course_prediction(known):
    """Per picture, (homography board units -> frame pixels, {id: square}, slot) of the course's
    board, fitted to the `known` board markers (id -> corners); None when the course layout does
    not agree with them: its fit leaves out more than one of them (board_homography)."""
    ### BEGIN SOLUTION
    board = boards.default_board()  # only its geometry (board units) is used, the same for any pictures
    homography = board_homography(board, known)
    if homography is None:
        return None
    square = np.concatenate([board.marker_square(i) for i in known]).astype(np.float32)
    seen = np.concatenate([known[i] for i in known]).astype(np.float32).reshape(-1, 2)
    if _misfits(homography, square, seen) > 1:
        return None
    return {picture: (homography, {i: board.marker_square(i) for i in ids}, board.picture_slot(picture))
            for picture, ids in marker_board.PICTURES.items()}
    ### END SOLUTION


def board_homography(board, markers):
    """The homography from board units to frame pixels that the corners of `markers` (board id ->
    corners) give, fitted by least squares; a marker it does not fit within a fifth of the
    marker's side (misread, or a spare one chosen) is left out and the rest fitted again. None
    when no homography fits."""
    ### BEGIN SOLUTION
    ids = list(markers)
    while ids:
        square = np.concatenate([board.marker_square(i) for i in ids]).astype(np.float32)
        seen = np.concatenate([markers[i] for i in ids]).astype(np.float32).reshape(-1, 2)
        homography, _ = cv2.findHomography(square, seen, 0)
        if homography is None or len(ids) == 1:
            return homography
        errors = np.linalg.norm(_project(homography, square) - seen, axis=1).reshape(-1, 4).max(axis=1)
        sides = np.array([np.linalg.norm(markers[i] - np.roll(markers[i], 1, axis=0), axis=1).min() for i in ids])
        worst = int(np.argmax(errors / sides))
        if errors[worst] <= 0.2 * sides[worst]:
            return homography
        ids.pop(worst)
    return None
    ### END SOLUTION


def _project(homography, points):
    return cv2.perspectiveTransform(np.asarray(points, np.float32)[None], homography)[0]


def _inside(points, shape):
    """True when every point lies FRAME_INSET pixels or more inside a frame of this shape."""
    height, width = shape[:2]
    return bool(points.min() >= FRAME_INSET and points[:, 0].max() <= width - 1 - FRAME_INSET
                and points[:, 1].max() <= height - 1 - FRAME_INSET)


def _look_in_window(grey, homography, square, slot, marker_id, detector):
    """The corners of board marker `marker_id` found in the window where `homography` puts its
    `square`, next to the picture `slot` (both in the same units), or None."""
    ### BEGIN SOLUTION
    predicted = _project(homography, square)
    side = float(np.linalg.norm(predicted - np.roll(predicted, 1, axis=0), axis=1).min())
    height, width = grey.shape
    if side < 10 or not _inside(predicted, grey.shape):
        return None  # too small to read, or cut by the frame edge
    centre = square.mean(axis=0)
    unit = boards.Board.MARKER / float(np.linalg.norm(square[1] - square[0]))  # board units per unit
    kept = _project(homography, centre + (square - centre) * (1 + 2 * KEPT_PAPER / boards.Board.MARKER))
    x0, y0 = np.maximum(np.floor(kept.min(axis=0)).astype(int) - 2, 0)
    x1, y1 = np.minimum(np.ceil(kept.max(axis=0)).astype(int) + 3, (width, height))
    window = grey[y0:y1, x0:x1]
    offset = np.float32([x0, y0])
    pad = 8  # paper around the window, so that the detector's border rule keeps the marker
    for overlap, (scale, kernel) in ((o, look) for o in PICTURE_OVERLAPS for look in WINDOW_LOOKS):
        if (scale, kernel) == WINDOW_LOOKS[0]:  # a new overlap: paint the window again
            mask = np.zeros(window.shape, np.uint8)
            cv2.fillConvexPoly(mask, np.round((kept - offset) * 16).astype(np.int32), 255, cv2.LINE_8, shift=4)
            painted = _project(homography, slot + np.sign(slot - slot.mean(axis=0)) * overlap / unit)
            cv2.fillConvexPoly(mask, np.round((painted - offset) * 16).astype(np.int32), 0, cv2.LINE_8, shift=4)
            paper = float(np.percentile(window[mask > 0], 90))  # the marker's white cells and its paper
            clean = cv2.copyMakeBorder(np.where(mask > 0, window, np.uint8(paper)), pad, pad, pad, pad,
                                       cv2.BORDER_CONSTANT, value=paper)
        corners = thinned_markers(clean, scale, kernel, detector).get(marker_id)
        if corners is None:
            continue
        corners = corners + offset - pad
        if _inside(corners, grey.shape) and np.abs(corners - predicted).max() < max(3.0, 0.25 * side):
            # The painted-out picture notched the corner it touches: refine all four on the frame.
            points = corners.reshape(-1, 1, 2).astype(np.float32)
            half = max(2, round(side * CORNER_WINDOW))
            cv2.cornerSubPix(grey, points, (half, half), (-1, -1),
                             (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.01))
            return points.reshape(4, 2)
    return None
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
