"""The printed board: the cat and dog pictures side by side, each framed by its four markers.

Lengths are in board units; the marker layout follows :mod:`course_lib.imaging.marker_board`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

import cv2
import numpy as np

from course_lib.imaging import drawn_cache
from course_lib.imaging.marker_board import PICTURES, dictionary
from course_lib.imaging.pictures import draw_cat, draw_dog


class TextureLevels(Sequence):
    """A texture at several resolutions, finest first: (pixels per unit, image) pairs, as a list
    of them reads. An image is made when first asked for (`make(index)`; a scene warps one level),
    and kept.

    Args:
        scales: pixels per unit of each level.
        shapes: the shape of each level's image.
        make: index -> that level's image, or None when `images` holds every level.
        images: the images of the levels, when they are made already.
    """

    def __init__(self, scales: Sequence[float], shapes: Sequence[tuple[int, ...]],
                 make: Callable[[int], np.ndarray] | None = None, images: Sequence[np.ndarray] = ()):
        self.scales, self.shapes = tuple(scales), tuple(shapes)
        self._make = make
        self._images = dict(enumerate(images))
        self._lock = threading.RLock()  # the checks of one submission render in threads

    @classmethod
    def of(cls, levels: Sequence[tuple[float, np.ndarray]]) -> TextureLevels:
        """Levels whose images are made already."""
        return cls([s for s, _ in levels], [image.shape for _, image in levels], images=[image for _, image in levels])

    @classmethod
    def pyramid(cls, scale: float, image: np.ndarray, smallest: int = 64) -> TextureLevels:
        """`image` at `scale`, then halved (cv2.pyrDown) until at most `smallest` pixels wide; a
        halving is made when first asked for."""
        shapes = [image.shape]
        while shapes[-1][1] > smallest:
            height, width = shapes[-1][:2]
            shapes.append(((height + 1) // 2, (width + 1) // 2, *shapes[-1][2:]))
        levels = cls([scale / 2 ** index for index in range(len(shapes))], shapes,
                     make=lambda index: cv2.pyrDown(levels[index - 1][1]), images=[image])
        return levels

    def __len__(self) -> int:
        return len(self.scales)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(len(self))[index]]
        index = range(len(self))[index]  # negative indices, and IndexError past the end
        if index not in self._images:
            with self._lock:
                if index not in self._images:
                    self._images[index] = self._make(index)
        return self.scales[index], self._images[index]


class Board:
    """The flat board: the cat and dog pictures side by side, each framed by its four markers.

    Lengths are in board units: a picture slot is 320x240 units, a marker 96 units (16 per cell)
    with at least 24 units (1.5 cells) of white paper around it.

    Args:
        cat, dog: BGR (or grey) images to show instead of the drawn cat and dog; any size, they
            are stretched to the 4:3 slot. Picture pixels in Scene homographies are pixels of
            these images.

    Raises:
        ValueError: an image is not 2-D/3-D uint8 with at least one pixel.
    """

    PICTURE_SIZE = (320, 240)
    MARKER = 96
    QUIET = 24
    GAP = 48
    PAPER = (236, 240, 242)
    #: Textures kept: the whole board (its levels take ~46 MB) and the five boards with markers
    #: missing that the catdog_warp checks show in every grading (their patches, and the levels
    #: that scenes warped).
    KEPT_TEXTURES = 6
    #: Texture pixels per board unit of the finest level.
    SCALE = 4

    def __init__(self, cat: np.ndarray | None = None, dog: np.ndarray | None = None):
        self.pictures: dict[str, np.ndarray] = {
            "cat": draw_cat() if cat is None else _as_bgr(cat, "cat"),
            "dog": draw_dog() if dog is None else _as_bgr(dog, "dog"),
        }
        m, q, (pw, ph) = self.MARKER, self.QUIET, self.PICTURE_SIZE
        left = q + m
        self._slots = {"cat": (left, q + m, left + pw, q + m + ph)}
        left = left + pw + m + self.GAP + m
        self._slots["dog"] = (left, q + m, left + pw, q + m + ph)
        self.size = (left + pw + m + q, q + m + ph + m + q)  # (width, height) in units
        self._textures: dict[frozenset, list[tuple[float, np.ndarray]]] = {}
        self._textures_lock = threading.Lock()  # the checks of one submission render in threads

    def picture_slot(self, picture: str) -> np.ndarray:
        """The picture's corners in board units (top-left, top-right, bottom-right, bottom-left)."""
        x0, y0, x1, y1 = self._slots[picture]
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)

    def marker_square(self, marker_id: int) -> np.ndarray:
        """A board marker's corners in board units, in OpenCV order (0 top-left ... 3 bottom-left)."""
        for name, ids in PICTURES.items():
            if marker_id in ids:
                index = ids.index(marker_id)
                corner = self.picture_slot(name)[index]
                # The marker lies diagonally outside the picture corner it touches.
                dx, dy = ((-1, -1), (1, -1), (1, 1), (-1, 1))[index]
                x0 = corner[0] if dx > 0 else corner[0] - self.MARKER
                y0 = corner[1] if dy > 0 else corner[1] - self.MARKER
                return _square(x0, y0, self.MARKER)
        raise KeyError(f"Marker {marker_id} is not on the board: board markers are "
                       f"{sorted(i for ids in PICTURES.values() for i in ids)}")

    def picture_homography(self, picture: str) -> np.ndarray:
        """Picture pixels (OpenCV centres) -> board units."""
        image_h, image_w = self.pictures[picture].shape[:2]
        x0, y0, x1, y1 = self._slots[picture]
        sx, sy = (x1 - x0) / image_w, (y1 - y0) / image_h
        return np.array([[sx, 0, x0 + 0.5 * sx], [0, sy, y0 + 0.5 * sy], [0, 0, 1]])

    def texture(self, missing: Sequence[int] = ()) -> TextureLevels:
        """The printed board as images at several resolutions (pixels per unit, image), finest first."""
        key = frozenset(i for i in missing if any(i in ids for ids in PICTURES.values()))
        with self._textures_lock:
            return self._levels(key)

    def _levels(self, key: frozenset) -> TextureLevels:
        if key not in self._textures:
            # With markers missing: the whole board with paper over them, the same pixels made faster.
            levels = self._with_paper(self._levels(frozenset()), key) if key else self._whole()
            if len(self._textures) >= self.KEPT_TEXTURES:  # the oldest board with markers missing goes
                self._textures.pop(next((k for k in self._textures if k), next(iter(self._textures))))
            self._textures[key] = levels
        return self._textures[key]

    def _whole(self) -> TextureLevels:
        """The levels of the whole board: drawn at SCALE, then halved (cv2.pyrDown) down to 64 pixels wide."""
        scale = self.SCALE
        width, height = self.size
        image = np.empty((height * scale, width * scale, 4), np.uint8)
        self._paper(image)  # BGRA: the alpha channel gives the board anti-aliased edges
        for name, picture in self.pictures.items():
            x0, y0, x1, y1 = (v * scale for v in self._slots[name])
            resized = cv2.resize(picture, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA
                                 if picture.shape[1] > x1 - x0 else cv2.INTER_CUBIC)
            cv2.cvtColor(resized, cv2.COLOR_BGR2BGRA, dst=image[y0:y1, x0:x1])  # opaque, written in place
        for marker_id in sorted(i for ids in PICTURES.values() for i in ids):
            x0, y0 = (int(v) * scale for v in self.marker_square(marker_id)[0])
            _paste_marker(image, marker_id, x0, y0, self.MARKER * scale)
        levels = [(float(scale), image)]
        while levels[-1][1].shape[1] > 64:
            levels.append((levels[-1][0] / 2, cv2.pyrDown(levels[-1][1])))
        return TextureLevels.of(levels)

    def _paper(self, area: np.ndarray) -> None:
        """Fill a BGRA area (rows of contiguous pixels) with opaque paper, one 32-bit value per
        pixel: numpy fills with a 4-tuple eight times slower."""
        area.view(np.uint32)[:] = np.array([(*self.PAPER, 255)], np.uint8).view(np.uint32)

    def _with_paper(self, whole: TextureLevels, key: frozenset) -> TextureLevels:
        """The levels of the whole board with paper over the markers of `key`: level 0 patched,
        and each coarser level recomputed (cv2.pyrDown) only around the patches, so the pixels
        are those of a full pyramid of the patched image at a fraction of its cost. Only the
        patches are made here; a level's image is the whole board's with its patches, made when
        a scene first warps that level (a copy of every level took 60 ms and 46 MB a board)."""
        scale = self.SCALE
        side = self.MARKER * scale
        paper = np.empty((side, side, 4), np.uint8)
        self._paper(paper)
        patches = [[]]  # per level: (y0, y1, x0, x1, pixels) written over the whole board's image
        for marker_id in sorted(key):
            x0, y0 = (int(v) * scale for v in self.marker_square(marker_id)[0])
            patches[0].append((y0, y0 + side, x0, x0 + side, paper))
        for index in range(1, len(whole)):
            finer = whole[index - 1][1]
            patches.append([_pyr_down_patch(finer, patches[-1], patch[:4], whole.shapes[index])
                            for patch in patches[-1]])
        return TextureLevels(whole.scales, whole.shapes, lambda index: _patched(whole[index][1], patches[index]))


def _patched(image: np.ndarray, patches, origin: tuple[int, int] = (0, 0)) -> np.ndarray:
    """A copy of `image` (whose pixel (0, 0) is pixel `origin` of its level) with the parts of
    `patches` that fall inside it written over it, in order."""
    image = image.copy()
    oy, ox = origin
    height, width = image.shape[:2]
    for y0, y1, x0, x1, pixels in patches:
        iy0, iy1 = max(y0, oy), min(y1, oy + height)
        ix0, ix1 = max(x0, ox), min(x1, ox + width)
        if iy0 < iy1 and ix0 < ix1:
            image[iy0 - oy:iy1 - oy, ix0 - ox:ix1 - ox] = pixels[iy0 - y0:iy1 - y0, ix0 - x0:ix1 - x0]
    return image


def _pyr_down_patch(finer: np.ndarray, finer_patches, region, coarser_shape) -> tuple:
    """The patch of the coarser level (cv2.pyrDown of `finer` with `finer_patches` written over
    it) that a change of `region` of the finer level reaches: (y0, y1, x0, x1, pixels), computed
    from a window of the patched finer level around the region. pyrDown's 5x5 kernel makes coarse
    pixel i from fine pixels 2i-2..2i+2, so a window with an even start and 8 pixels more on each
    side gives those pixels exactly (its own border handling touches only pixels 2 from its edge,
    which are the image's own edge or not used)."""
    y0, y1, x0, x1 = region
    height, width = finer.shape[:2]
    wy0, wx0 = max(0, (y0 - 8) & ~1), max(0, (x0 - 8) & ~1)
    wy1, wx1 = min(height, y1 + 8), min(width, x1 + 8)
    small = cv2.pyrDown(_patched(finer[wy0:wy1, wx0:wx1], finer_patches, (wy0, wx0)))
    cy0, cx0 = max(0, (y0 - 2) // 2), max(0, (x0 - 2) // 2)  # coarse pixels the change reaches
    cy1, cx1 = min(coarser_shape[0], (y1 + 2) // 2 + 1), min(coarser_shape[1], (x1 + 2) // 2 + 1)
    return cy0, cy1, cx0, cx1, small[cy0 - wy0 // 2:cy1 - wy0 // 2, cx0 - wx0 // 2:cx1 - wx0 // 2]


def _square(x0: float, y0: float, side: float) -> np.ndarray:
    return np.array([[x0, y0], [x0 + side, y0], [x0 + side, y0 + side], [x0, y0 + side]], dtype=np.float64)


def _paste_marker(image: np.ndarray, marker_id: int, x0: int, y0: int, side: int) -> None:
    marker = cv2.aruco.generateImageMarker(dictionary(), marker_id, side)
    image[y0:y0 + side, x0:x0 + side, :3] = marker[:, :, None]


def _as_bgr(image, name: str) -> np.ndarray:
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim not in (2, 3) or 0 in image.shape[:2]:
        raise ValueError(f"The {name} picture must be a uint8 image (height, width[, 3]), not "
                         f"{image.dtype} {image.shape}; load one with cv2.imread")
    if image.ndim == 2 or image.shape[2] == 1:
        return cv2.cvtColor(image.reshape(image.shape[:2]), cv2.COLOR_GRAY2BGR)
    if image.shape[2] == 4:
        return cv2.cvtColor(image, cv2.COLOR_BGRA2BGR)
    return image.copy()


_DEFAULT_BOARD: Board | None = None
_DEFAULT_BOARD_LOCK = threading.Lock()


def default_board() -> Board:
    """The board with the drawn cat and dog (made once, then shared, also by threads that ask at once:
    the checks of a submission render in threads, and each board draws its own textures)."""
    global _DEFAULT_BOARD
    if _DEFAULT_BOARD is None:
        with _DEFAULT_BOARD_LOCK:
            if _DEFAULT_BOARD is None:
                _DEFAULT_BOARD = _kept_default_board()
    return _DEFAULT_BOARD


def _kept_default_board() -> Board:
    """Board() with its pictures and its whole texture mapped from the copy kept on disk
    (drawn_cache), else drawn, and then kept when this process may."""
    key = drawn_cache.key("boards.py", "pictures.py", "marker_board.py")
    kept = drawn_cache.load("default_board", key)
    if kept is not None and len(kept) > 2:
        board = Board(cat=kept[0], dog=kept[1])
        width, height = board.size
        if kept[2].shape == (height * board.SCALE, width * board.SCALE, 4):
            board._textures[frozenset()] = TextureLevels.of([(board.SCALE / 2 ** index, image)
                                                             for index, image in enumerate(kept[2:])])
            return board
    board = Board()
    levels = board.texture()
    drawn_cache.store("default_board", key, [board.pictures["cat"], board.pictures["dog"],
                                             *(image for _, image in levels)])
    return board
