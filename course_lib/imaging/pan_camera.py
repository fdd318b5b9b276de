"""A camera on a pan head in front of the marker board: what it sees when turned to an angle.

The lessons' and the services_actions assignment's simulated camera for "find the cat": the board
hangs straight ahead (pan 0 degrees); turning the head to ``pan`` degrees (positive: to the right)
moves the board to the left of the frame, and between about 15 and 32 degrees its markers leave
the frame. Angles wrap to [-180, 180). Nothing here draws unless asked (``frame_at``): which
markers are in view is computed from the board's geometry (``scenes.detectable_from``), so
answering a question about an angle costs well under a millisecond.

The answers are what OpenCV's ArUco detector finds in ``frame_at(pan)``: the markers it surely
finds (``markers_in_view``), and the few it may find or miss (``uncertain_markers``: a marker
touching the frame's border band, or a small one), which a check of a node's answers counts
neither way.
"""

from __future__ import annotations

import math

import numpy as np

from course_lib.imaging import scenes
from course_lib.imaging.camera_views import Look, Pose
from course_lib.imaging.marker_board import PICTURES

#: Degrees the head turns per step of a search, and the seconds a step takes (the head's speed).
STEP_DEGREES = 5.0
STEP_SECONDS = 0.1
#: Where the head points when a node starts without being told (the board is out of view).
START_PAN = -60.0
#: Apparent board width at pan 0, as a fraction of the frame width.
BOARD_SCALE = 0.6
#: Beyond this angle the board is outside the field of view (and nearly edge-on): nothing is seen.
_OUT_OF_VIEW = 60.0
#: The frame size the answers are computed for.
FRAME_SIZE = (640, 480)
#: The shortest side (pixels) of a marker that is surely found. The pan camera's frames are clean
#: (camera_views.Look(): no noise, blur or JPEG), where OpenCV's detector with its default
#: parameters finds far smaller markers than in the scenes' hard frames (scenes.MIN_MARKER_SIDE):
#: on clean frames of the board at many sizes and angles it found every marker of 17 pixels or
#: more, some of 9 to 16, none below 8.9. A marker must also lie scenes.FRAME_MARGIN pixels inside
#: the frame (the detector skips candidates within 3 pixels of the border).
SURE_SIDE = 18.0
#: A marker smaller than this, or not whole in the frame, is never found.
SEEN_SIDE = 8.0
#: A corner this far outside the pixel centres is still in the picture (the frame's edge).
_EDGE = -0.5


def wrap(pan: float) -> float:
    """`pan` in degrees, wrapped to [-180, 180).

    Raises:
        ValueError: pan is not a finite number (NaN or infinite), with the fix.
    """
    pan = float(pan)
    if not math.isfinite(pan):
        raise ValueError(f"pan must be a finite number of degrees, not {pan}: for example pan: -30.0")
    return (pan + 180.0) % 360.0 - 180.0


def pose_at(pan: float) -> Pose:
    """The camera pose when the head is turned to `pan` degrees (|pan| below 60).

    Turning the camera right by pan moves the board's centre to the left, to tan(pan) focal
    lengths off the optical axis, and turns the board away by the same angle."""
    pan = wrap(pan)
    if abs(pan) >= _OUT_OF_VIEW:
        raise ValueError(f"at pan {pan:g} the board is out of view; poses exist for |pan| < {_OUT_OF_VIEW:g}")
    angle = math.radians(pan)
    return Pose(tilt_y=pan, scale=BOARD_SCALE * math.cos(angle), center=(-math.tan(angle), 0.0), focal=1.0)


def markers_in_view(pan: float) -> tuple[int, ...]:
    """The board markers (1-8) in view with the head at `pan` degrees, ascending: whole, off the
    frame's border and big enough that a detector surely finds them (see SURE_SIDE)."""
    return _found(pan, SURE_SIDE, scenes.FRAME_MARGIN)


def uncertain_markers(pan: float) -> tuple[int, ...]:
    """The board markers a detector may find or miss at `pan` degrees, ascending: whole in the
    frame, but within scenes.FRAME_MARGIN pixels of its border or smaller than SURE_SIDE."""
    sure = set(markers_in_view(pan))
    return tuple(i for i in _found(pan, SEEN_SIDE, _EDGE) if i not in sure)


def framed_at(pan: float) -> tuple[str, ...]:
    """The pictures ("cat", "dog") whose four markers are all in view at `pan` degrees."""
    return _framed(markers_in_view(pan))


def maybe_framed_at(pan: float) -> tuple[str, ...]:
    """The pictures a detector may or may not find framed at `pan` degrees: each of their markers
    is in view or uncertain, and one at least is uncertain."""
    sure = framed_at(pan)
    return tuple(name for name in _framed(markers_in_view(pan) + uncertain_markers(pan)) if name not in sure)


def _found(pan: float, min_side: float, margin: float) -> tuple[int, ...]:
    pan = wrap(pan)
    if abs(pan) >= _OUT_OF_VIEW:
        return ()
    return scenes.detectable_from(pose_at(pan), size=FRAME_SIZE, min_side=min_side, margin=margin)


def _framed(ids) -> tuple[str, ...]:
    return tuple(name for name, markers in PICTURES.items() if set(ids).issuperset(markers))


def markers_of(pictures) -> tuple[int, ...]:
    """The markers framing `pictures` (names as in marker_board.PICTURES; empty: both), ascending.

    Raises:
        ValueError: a name that is no picture, naming the pictures there are.
    """
    names = list(pictures) or list(PICTURES)
    unknown = [name for name in names if name not in PICTURES]
    if unknown:
        raise ValueError(f"no picture {unknown[0]!r} on the board: use {' or '.join(map(repr, PICTURES))}")
    return tuple(sorted({marker for name in names for marker in PICTURES[name]}))


def frame_at(pan: float) -> np.ndarray:
    """The BGR frame the camera sees at `pan` degrees (about 50 ms: for pictures in a notebook)."""
    pan = wrap(pan)
    shown = max(-_OUT_OF_VIEW + 1, min(_OUT_OF_VIEW - 1, pan))  # beyond: the board is off the frame anyway
    return scenes.render_scene(0, size=FRAME_SIZE, pose=pose_at(shown), look=Look()).frame


def search_pans(start: float, pictures) -> list[float]:
    """The angles a search turns to, a step of STEP_DEGREES at a time from `start`, until every
    one of `pictures` (empty: both) is framed: what its feedback says, the last being where it
    stops (no step when they are framed at `start`; a whole turn at most)."""
    wanted = set(pictures) or set(PICTURES)
    markers_of(wanted)  # a name that is no picture: ValueError naming the pictures
    pans, pan = [], wrap(start)
    while not wanted <= set(framed_at(pan)) and len(pans) < round(360 / STEP_DEGREES):
        pan = wrap(pan + STEP_DEGREES)
        pans.append(pan)
    return pans


def search_stops(start: float, pictures) -> list[float]:
    """The angles where a search from `start` for `pictures` may stop: the last of search_pans
    (or `start` when it takes no step), and any angle before it where a detector may find the
    pictures framed (maybe_framed_at), since a node that looks with a real detector stops there."""
    wanted = set(pictures) or set(PICTURES)
    pans = [wrap(start), *search_pans(start, pictures)]
    return [pan for pan in pans if wanted <= set(framed_at(pan)) | set(maybe_framed_at(pan))]
