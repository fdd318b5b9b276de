"""Tests for course_lib.boards: the printed board follows the marker convention."""

import numpy as np

from course_lib import boards, marker_board


def test_markers_touch_their_picture_corner_and_hide_none_of_it():
    board = boards.Board()
    for name, ids in marker_board.PICTURES.items():
        slot = board.picture_slot(name)
        x0, y0 = slot.min(axis=0)
        x1, y1 = slot.max(axis=0)
        for index, (marker_id, corner) in enumerate(zip(ids, marker_board.CORNER_OF_MARKER)):
            square = board.marker_square(marker_id)
            np.testing.assert_allclose(square[corner], slot[index])
            mx0, my0 = square.min(axis=0)
            mx1, my1 = square.max(axis=0)
            overlap = max(0, min(x1, mx1) - max(x0, mx0)) * max(0, min(y1, my1) - max(y0, my0))
            assert overlap == 0, f"marker {marker_id} covers part of the {name}"
