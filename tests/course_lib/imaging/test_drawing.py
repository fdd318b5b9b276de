"""Tests for course_lib.imaging.drawing: drawings over frames and figures for the vision lessons."""

import numpy as np
import pytest

from course_lib.imaging import drawing, marker_board, scenes

SQUARE = np.array([[20, 20], [60, 20], [60, 60], [20, 60]], dtype=np.float32)


def test_draw_markers_draws_on_a_copy_and_leaves_the_input_alone():
    frame = np.zeros((100, 120, 3), np.uint8)
    annotated = drawing.draw_markers(frame, [SQUARE.reshape(1, 4, 2)], np.array([[7]]))
    assert not frame.any(), "the input frame must stay unchanged"
    assert annotated.shape == frame.shape and annotated.dtype == np.uint8
    assert annotated[20, 40].any(), "the outline passes through the middle of the top edge"


def test_draw_markers_colours_each_corner_number_differently():
    annotated = drawing.draw_markers(np.zeros((100, 120), np.uint8), {3: SQUARE})
    assert annotated.ndim == 3, "a grey frame comes back as BGR so the colours show"
    for corner, colour in zip(SQUARE.astype(int), drawing.CORNER_COLOURS, strict=True):
        assert tuple(annotated[corner[1], corner[0]]) == colour


def test_draw_markers_accepts_detector_output_of_a_real_scene():
    scene = scenes.render_scene(1)
    corners, ids, _ = marker_board.detector().detectMarkers(scene.frame)
    annotated = drawing.draw_markers(scene.frame, corners, ids)
    assert (annotated != scene.frame).any()


def test_draw_markers_names_mismatched_ids_and_bad_corners():
    with pytest.raises(ValueError, match="2 marker corner arrays but 1 ids"):
        drawing.draw_markers(np.zeros((50, 50, 3), np.uint8), [SQUARE, SQUARE], np.array([[1]]))
    with pytest.raises(ValueError, match="4 corners"):
        drawing.draw_markers(np.zeros((50, 50, 3), np.uint8), [SQUARE[:3]])


def test_show_images_shows_bgr_in_true_colours_and_grey_in_grey():
    blue = np.zeros((10, 20, 3), np.uint8)
    blue[:, :, 0] = 255  # BGR blue
    figure = drawing.show_images([blue, np.full((10, 20), 128, np.uint8), np.eye(10, dtype=bool)],
                                ["blue", "grey", "mask"], columns=2)
    shown = [ax.images[0] for ax in figure.axes if ax.images]
    assert len(shown) == 3
    assert tuple(shown[0].get_array()[0, 0]) == (0, 0, 255), "RGB order for matplotlib"
    assert shown[1].get_cmap().name == "gray"
    assert [ax.get_title() for ax in figure.axes if ax.images] == ["blue", "grey", "mask"]


def test_show_images_needs_one_title_per_image():
    with pytest.raises(ValueError, match="one title per image"):
        drawing.show_images([np.zeros((5, 5), np.uint8)], ["a", "b"])


def test_plot_over_time_starts_the_time_axis_at_zero():
    figure = drawing.plot_over_time([10.0, 10.5, 11.0], [100, 110, 120], ylabel="brightness", ylim=(0, 255))
    x, y = figure.axes[0].lines[0].get_data()
    assert list(x) == [0.0, 0.5, 1.0] and list(y) == [100, 110, 120]
    assert figure.axes[0].get_ylim() == (0, 255)
    with pytest.raises(ValueError, match="one time per value"):
        drawing.plot_over_time([1, 2], [1])
