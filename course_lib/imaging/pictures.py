"""The cartoon cat and dog printed on the course's marker board, drawn procedurally (no files)."""

from __future__ import annotations

import math

import cv2
import numpy as np

from course_lib.imaging.marker_board import DEFAULT_SIZE, _check_size


def draw_cat(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """A cartoon cat sitting in a room (window on the left, ball of wool on the right).

    The drawing is deliberately not left-right symmetric, so a mirrored crop looks different.

    Args:
        size: (width, height) of the picture.

    Returns:
        BGR uint8 image of that size.
    """
    width, height = _check_size(size, "picture size")
    s = 4  # draw at 4x and shrink, for smooth edges at any size
    w, h = 320 * s, 240 * s
    img = np.empty((h, w, 3), np.uint8)
    img[:] = (214, 228, 246)                       # pale peach wall
    img[int(h * 0.72):] = (168, 200, 226)           # light wooden floor
    for x in range(0, w, 40 * s):                   # floor boards
        cv2.line(img, (x, int(h * 0.72)), (x - 30 * s, h), (150, 182, 210), 2 * s, cv2.LINE_AA)
    cv2.line(img, (0, int(h * 0.72)), (w, int(h * 0.72)), (120, 150, 180), 3 * s, cv2.LINE_AA)
    # Window, upper left.
    cv2.rectangle(img, (30 * s, 28 * s), (112 * s, 110 * s), (240, 205, 150), -1)
    cv2.circle(img, (50 * s, 48 * s), 10 * s, (120, 235, 255), -1, cv2.LINE_AA)
    cv2.rectangle(img, (30 * s, 28 * s), (112 * s, 110 * s), (90, 120, 160), 5 * s)
    cv2.line(img, (71 * s, 28 * s), (71 * s, 110 * s), (90, 120, 160), 4 * s)
    cv2.line(img, (30 * s, 69 * s), (112 * s, 69 * s), (90, 120, 160), 4 * s)
    # Picture frame on the wall, upper right, tilted.
    box = cv2.boxPoints(((262 * s, 52 * s), (44 * s, 34 * s), -8)).astype(np.int32)
    cv2.fillConvexPoly(img, box, (150, 190, 120), cv2.LINE_AA)
    cv2.polylines(img, [box], True, (60, 80, 110), 3 * s, cv2.LINE_AA)
    fur, dark, pink = (70, 150, 235), (30, 90, 180), (170, 160, 245)
    # Tail curling out to the right.
    tail = np.array([[190, 200], [222, 196], [242, 178], [246, 150], [236, 132]], np.int32) * s
    cv2.polylines(img, [tail], False, dark, 13 * s, cv2.LINE_AA)
    cv2.polylines(img, [tail], False, fur, 9 * s, cv2.LINE_AA)
    # Body and front paws.
    cv2.ellipse(img, (150 * s, 168 * s), (52 * s, 50 * s), 0, 0, 360, fur, -1, cv2.LINE_AA)
    cv2.ellipse(img, (150 * s, 178 * s), (30 * s, 34 * s), 0, 0, 360, (200, 225, 250), -1, cv2.LINE_AA)
    for x in (128, 170):
        cv2.ellipse(img, (x * s, 214 * s), (14 * s, 8 * s), 0, 0, 360, (215, 235, 252), -1, cv2.LINE_AA)
    # Head with ears.
    cx, cy = 150 * s, 100 * s
    for sign in (-1, 1):
        ear = np.array([[cx + sign * 44 * s, cy - 12 * s], [cx + sign * 40 * s, cy - 62 * s],
                        [cx + sign * 10 * s, cy - 34 * s]], np.int32)
        inner = np.array([[cx + sign * 36 * s, cy - 20 * s], [cx + sign * 37 * s, cy - 50 * s],
                          [cx + sign * 18 * s, cy - 33 * s]], np.int32)
        cv2.fillConvexPoly(img, ear, fur, cv2.LINE_AA)
        cv2.fillConvexPoly(img, inner, pink, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy), (48 * s, 40 * s), 0, 0, 360, fur, -1, cv2.LINE_AA)
    for dx in (-12, 0, 12):                          # forehead stripes
        cv2.line(img, (cx + dx * s, cy - 38 * s), (cx + dx * s // 2, cy - 24 * s), dark, 4 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 16 * s), (22 * s, 15 * s), 0, 0, 360, (215, 235, 252), -1, cv2.LINE_AA)
    for sign in (-1, 1):                             # green eyes with slit pupils
        ex = cx + sign * 19 * s
        cv2.ellipse(img, (ex, cy - 4 * s), (10 * s, 8 * s), 0, 0, 360, (60, 190, 90), -1, cv2.LINE_AA)
        cv2.ellipse(img, (ex, cy - 4 * s), (3 * s, 7 * s), 0, 0, 360, (20, 20, 20), -1, cv2.LINE_AA)
        cv2.circle(img, (ex - 3 * s, cy - 7 * s), 2 * s, (255, 255, 255), -1, cv2.LINE_AA)
    nose = np.array([[cx - 6 * s, cy + 8 * s], [cx + 6 * s, cy + 8 * s], [cx, cy + 15 * s]], np.int32)
    cv2.fillConvexPoly(img, nose, (140, 110, 230), cv2.LINE_AA)
    cv2.ellipse(img, (cx - 6 * s, cy + 18 * s), (6 * s, 5 * s), 0, 0, 180, (40, 40, 40), 2 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 6 * s, cy + 18 * s), (6 * s, 5 * s), 0, 0, 180, (40, 40, 40), 2 * s, cv2.LINE_AA)
    for sign in (-1, 1):                             # whiskers
        for dy, slope in ((10, -8), (16, 0), (22, 8)):
            start = (cx + sign * 16 * s, cy + dy * s)
            end = (cx + sign * 62 * s, cy + (dy + slope) * s)
            cv2.line(img, start, end, (50, 50, 50), 2 * s, cv2.LINE_AA)
    # Ball of wool on the floor, lower right.
    cv2.circle(img, (268 * s, 206 * s), 20 * s, (70, 60, 200), -1, cv2.LINE_AA)
    for angle in (20, 70, 120):
        cv2.ellipse(img, (268 * s, 206 * s), (20 * s, 8 * s), angle, 0, 360, (40, 30, 150), 2 * s, cv2.LINE_AA)
    cv2.line(img, (250 * s, 216 * s), (212 * s, 228 * s), (70, 60, 200), 2 * s, cv2.LINE_AA)
    return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)


def draw_dog(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """A cartoon dog on a lawn (sun top right, bone bottom left), floppy ears and tongue out.

    The drawing is deliberately not left-right symmetric, so a mirrored crop looks different.

    Args:
        size: (width, height) of the picture.

    Returns:
        BGR uint8 image of that size.
    """
    width, height = _check_size(size, "picture size")
    s = 4
    w, h = 320 * s, 240 * s
    img = np.empty((h, w, 3), np.uint8)
    img[:] = (245, 222, 190)                        # pale blue sky
    lawn = np.array([[0, 118], [320, 158], [320, 240], [0, 240]], np.int32) * s   # sloping lawn
    cv2.fillConvexPoly(img, lawn, (140, 212, 150), cv2.LINE_AA)
    cv2.ellipse(img, (40 * s, 124 * s), (90 * s, 34 * s), 0, 180, 360, (120, 190, 130), -1, cv2.LINE_AA)
    cv2.fillConvexPoly(img, np.array([[0, 124], [130, 124], [130, 150], [0, 150]], np.int32) * s,
                       (120, 190, 130))
    cv2.fillConvexPoly(img, lawn, (140, 212, 150), cv2.LINE_AA)
    cv2.circle(img, (272 * s, 40 * s), 22 * s, (90, 215, 255), -1, cv2.LINE_AA)          # sun
    for k in range(8):
        a = k * math.pi / 4
        p1 = (int(272 * s + 28 * s * math.cos(a)), int(40 * s + 28 * s * math.sin(a)))
        p2 = (int(272 * s + 38 * s * math.cos(a)), int(40 * s + 38 * s * math.sin(a)))
        cv2.line(img, p1, p2, (90, 215, 255), 3 * s, cv2.LINE_AA)
    for x, y in ((50, 40), (90, 30)):                                                       # cloud
        cv2.ellipse(img, (x * s, y * s), (26 * s, 12 * s), 0, 0, 360, (252, 250, 248), -1, cv2.LINE_AA)
    for x in range(12, 320, 22):                                                            # grass blades
        cv2.line(img, (x * s, 236 * s), ((x + 4) * s, 226 * s), (90, 170, 100), 2 * s, cv2.LINE_AA)
    # Bone, lower left.
    cv2.line(img, (34 * s, 206 * s), (84 * s, 194 * s), (235, 245, 250), 9 * s, cv2.LINE_AA)
    for x, y in ((34, 206), (84, 194)):
        for d in (-5, 5):
            cv2.circle(img, ((x - 2) * s, (y + d) * s), 6 * s, (235, 245, 250), -1, cv2.LINE_AA)
    brown, dark, light = (60, 110, 170), (30, 55, 95), (150, 195, 230)
    # Body sitting, a little right of centre, and a red collar.
    cv2.ellipse(img, (190 * s, 184 * s), (50 * s, 44 * s), 0, 0, 360, brown, -1, cv2.LINE_AA)
    cv2.ellipse(img, (242 * s, 214 * s), (22 * s, 10 * s), -20, 0, 360, brown, -1, cv2.LINE_AA)  # back leg
    cv2.ellipse(img, (170 * s, 222 * s), (14 * s, 8 * s), 0, 0, 360, light, -1, cv2.LINE_AA)
    cv2.ellipse(img, (206 * s, 222 * s), (14 * s, 8 * s), 0, 0, 360, light, -1, cv2.LINE_AA)
    cx, cy = 184 * s, 98 * s
    cv2.ellipse(img, (cx, cy + 42 * s), (34 * s, 8 * s), 0, 0, 360, (40, 40, 200), -1, cv2.LINE_AA)
    cv2.circle(img, (cx + 8 * s, cy + 52 * s), 6 * s, (40, 200, 240), -1, cv2.LINE_AA)     # tag
    # Head.
    cv2.ellipse(img, (cx, cy), (44 * s, 42 * s), 0, 0, 360, brown, -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 16 * s, cy - 14 * s), (14 * s, 12 * s), 0, 0, 360, light, -1, cv2.LINE_AA)  # eye patch
    # Floppy ears hanging down beside the head.
    cv2.ellipse(img, (cx - 44 * s, cy + 8 * s), (14 * s, 36 * s), 18, 0, 360, dark, -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 44 * s, cy + 8 * s), (14 * s, 36 * s), -18, 0, 360, dark, -1, cv2.LINE_AA)
    for ex in (cx - 16 * s, cx + 16 * s):
        cv2.circle(img, (ex, cy - 12 * s), 7 * s, (255, 255, 255), -1, cv2.LINE_AA)
        cv2.circle(img, (ex + 2 * s, cy - 11 * s), 4 * s, (20, 20, 20), -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 16 * s), (24 * s, 17 * s), 0, 0, 360, light, -1, cv2.LINE_AA)   # snout
    cv2.ellipse(img, (cx, cy + 6 * s), (9 * s, 6 * s), 0, 0, 360, (25, 25, 25), -1, cv2.LINE_AA)  # nose
    cv2.line(img, (cx, cy + 12 * s), (cx, cy + 20 * s), (25, 25, 25), 2 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 20 * s), (12 * s, 6 * s), 0, 0, 180, (25, 25, 25), 2 * s, cv2.LINE_AA)
    # Tongue hanging out to the dog's left (our right).
    cv2.ellipse(img, (cx + 6 * s, cy + 32 * s), (8 * s, 12 * s), -10, 0, 360, (130, 110, 240), -1, cv2.LINE_AA)
    cv2.line(img, (cx + 6 * s, cy + 26 * s), (cx + 7 * s, cy + 38 * s), (100, 80, 200), 2 * s, cv2.LINE_AA)
    return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)
