"""Pictures for the vision lessons: detected markers drawn over a frame, image grids, time plots.

These helpers explain; they do not detect or crop anything themselves. A lesson detects
markers (with ``marker_board.detector()`` or step by step) and passes the result here to look at it::

    corners, ids, _ = marker_board.detector().detectMarkers(frame)
    annotated = vision.draw_markers(frame, corners, ids)       # outlines, ids, corner numbers
    vision.show_images([frame, annotated], ["camera", "markers"])
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import cv2
import numpy as np

#: Colours (BGR) of the four corner numbers 0-3, so that corner order can be seen at a glance.
CORNER_COLOURS = ((0, 0, 255), (0, 200, 0), (255, 0, 0), (0, 200, 255))


def _as_marker_list(corners, ids) -> list[tuple[int | None, np.ndarray]]:
    """(id or None, (4, 2) float array) pairs from detectMarkers output or an id -> corners mapping."""
    if isinstance(corners, Mapping):
        items = list(corners.items())
    else:
        corners = [] if corners is None else list(corners)
        if ids is None:
            id_list = [None] * len(corners)
        else:
            id_list = [int(i) for i in np.asarray(ids).reshape(-1)]
            if len(id_list) != len(corners):
                raise ValueError(f"Got {len(corners)} marker corner arrays but {len(id_list)} ids: pass "
                                 "corners and ids exactly as detectMarkers returned them")
        items = list(zip(id_list, corners, strict=True))
    markers = []
    for marker_id, quad in items:
        quad = np.asarray(quad, dtype=np.float64)
        if quad.size != 8:
            raise ValueError(f"Each marker needs 4 corners (x, y), shape (4, 2) or (1, 4, 2); got shape "
                             f"{quad.shape} for marker {marker_id}")
        markers.append((marker_id, quad.reshape(4, 2)))
    return markers


def draw_markers(image: np.ndarray, corners, ids=None, *, corner_numbers: bool = True,
                 colour: tuple[int, int, int] = (0, 255, 0), thickness: int | None = None) -> np.ndarray:
    """A copy of an image with markers drawn on it: outline, id and the numbers of the corners.

    Args:
        image: BGR (height, width, 3) or grey (height, width) uint8 image; it is not changed.
        corners: marker corners as ``detectMarkers`` returns them (a sequence of (1, 4, 2)
            arrays), a sequence of (4, 2) arrays, or a mapping id -> corners.
        ids: the ids for a sequence of corners (the (N, 1) array of detectMarkers), or None.
            Ignored when ``corners`` is a mapping.
        corner_numbers: write 0, 1, 2, 3 next to each marker's corners (colours in
            CORNER_COLOURS) to show the corner order.
        colour: BGR colour of the outlines and ids.
        thickness: line thickness; None picks one from the image size.

    Returns:
        A BGR uint8 copy with the drawing.

    Raises:
        ValueError: an image that is not (h, w) or (h, w, 3), or corners that are not 4 points each.
    """
    image = np.asarray(image)
    if image.ndim == 2:
        canvas = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    elif image.ndim == 3 and image.shape[2] == 3:
        canvas = image.copy()
    else:
        raise ValueError(f"draw_markers needs a BGR (h, w, 3) or grey (h, w) image, not shape {image.shape}")
    thickness = thickness or max(1, round(max(canvas.shape[:2]) / 320))
    scale = max(0.35, max(canvas.shape[:2]) / 1600)
    for marker_id, quad in _as_marker_list(corners, ids):
        points = np.round(quad).astype(np.int32)
        cv2.polylines(canvas, [points], True, colour, thickness, cv2.LINE_AA)
        centre = quad.mean(axis=0)
        if marker_id is not None:
            label = f"id {marker_id}"
            (w, h), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, scale, thickness)
            origin = (int(centre[0] - w / 2), int(centre[1] + h / 2))
            cv2.putText(canvas, label, origin, cv2.FONT_HERSHEY_SIMPLEX, scale, (0, 0, 0), thickness + 2, cv2.LINE_AA)
            cv2.putText(canvas, label, origin, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, thickness, cv2.LINE_AA)
        if corner_numbers:
            for number, corner in enumerate(quad):
                # Put the number a little outside the marker, along the line from its centre.
                away = corner - centre
                away = away / (np.linalg.norm(away) or 1.0)
                x, y = corner + away * 12 * scale / 0.5
                cv2.circle(canvas, (int(round(corner[0])), int(round(corner[1]))), thickness + 2,
                           CORNER_COLOURS[number], -1, cv2.LINE_AA)
                cv2.putText(canvas, str(number), (int(x - 5 * scale), int(y + 5 * scale)), cv2.FONT_HERSHEY_SIMPLEX,
                            scale, CORNER_COLOURS[number], thickness, cv2.LINE_AA)
    return canvas


def _to_rgb(image: np.ndarray) -> tuple[np.ndarray, str | None]:
    image = np.asarray(image)
    if image.dtype == bool:
        image = image.astype(np.uint8) * 255
    if image.ndim == 2 or (image.ndim == 3 and image.shape[2] == 1):
        return image.reshape(image.shape[:2]), "gray"
    if image.ndim == 3 and image.shape[2] == 3:
        return image[:, :, ::-1], None  # OpenCV stores BGR, matplotlib shows RGB
    raise ValueError(f"show_images shows grey (h, w) or BGR (h, w, 3) images, not shape {image.shape}")


def show_images(images: Sequence[np.ndarray], titles: Sequence[str] | None = None, *, columns: int = 3,
                width: float = 4.0):
    """A matplotlib Figure with images side by side (BGR shown in true colours, grey in grey).

    Args:
        images: BGR (h, w, 3), grey (h, w) or boolean (h, w) images.
        titles: one title per image, or None.
        columns: images per row.
        width: inches per image.

    Returns:
        matplotlib Figure (a notebook shows it when it is a cell's last value).

    Raises:
        ValueError: no images, titles that do not match the images, or an image of another shape.
    """
    from matplotlib.figure import Figure

    images = list(images)
    if not images:
        raise ValueError("show_images needs at least one image")
    if titles is not None and len(titles) != len(images):
        raise ValueError(f"Got {len(images)} images but {len(titles)} titles: give one title per image")
    columns = max(1, min(columns, len(images)))
    rows = -(-len(images) // columns)
    first = np.asarray(images[0])
    aspect = first.shape[0] / first.shape[1] if first.ndim >= 2 and first.shape[1] else 0.75
    # A Figure made without pyplot: a notebook shows it once, as the cell's value.
    figure = Figure(figsize=(width * columns, width * aspect * rows + 0.4 * rows), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False)
    for index, ax in enumerate(axes.flat):
        ax.axis("off")
        if index >= len(images):
            continue
        shown, cmap = _to_rgb(images[index])
        ax.imshow(shown, cmap=cmap, vmin=0 if cmap else None, vmax=255 if cmap and shown.dtype == np.uint8 else None,
                  interpolation="nearest")
        if titles is not None:
            ax.set_title(titles[index], fontsize=10)
    return figure


def plot_over_time(times: Sequence[float], values: Sequence[float], *, ylabel: str = "value",
                   title: str | None = None, ylim: tuple[float, float] | None = None):
    """A matplotlib Figure of values against time, with the time axis starting at 0.

    Args:
        times: time stamps in seconds (any origin, e.g. message stamps or time.monotonic()).
        values: one value per time stamp.
        ylabel: what the values are.
        title: figure title.
        ylim: y-axis range, e.g. (0, 255) for brightness; None fits the data.

    Returns:
        matplotlib Figure.

    Raises:
        ValueError: times and values differ in length.
    """
    from matplotlib.figure import Figure

    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    if times.shape != values.shape:
        raise ValueError(f"Got {times.size} times but {values.size} values: give one time per value")
    figure = Figure(figsize=(7, 3), layout="constrained")
    ax = figure.subplots()
    ax.plot(times - (times[0] if times.size else 0.0), values, marker=".", linewidth=1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    if ylim is not None:
        ax.set_ylim(*ylim)
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    return figure
