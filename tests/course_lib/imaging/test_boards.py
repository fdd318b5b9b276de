"""Tests for course_lib.imaging.boards: the printed board follows the marker convention."""

from itertools import pairwise

import numpy as np
import pytest

from course_lib.imaging import boards, marker_board


def test_markers_touch_their_picture_corner_and_hide_none_of_it():
    board = boards.Board()
    for name, ids in marker_board.PICTURES.items():
        slot = board.picture_slot(name)
        x0, y0 = slot.min(axis=0)
        x1, y1 = slot.max(axis=0)
        for index, (marker_id, corner) in enumerate(zip(ids, marker_board.CORNER_OF_MARKER, strict=True)):
            square = board.marker_square(marker_id)
            np.testing.assert_allclose(square[corner], slot[index])
            mx0, my0 = square.min(axis=0)
            mx1, my1 = square.max(axis=0)
            overlap = max(0, min(x1, mx1) - max(x0, mx0)) * max(0, min(y1, my1) - max(y0, my0))
            assert overlap == 0, f"marker {marker_id} covers part of the {name}"


@pytest.mark.parametrize("gone", [(1, 5), (4, 8), tuple(range(1, 9))])
def test_a_board_with_markers_missing_is_the_whole_board_with_paper_over_them(gone):
    """Only the missing markers' squares differ from the whole board, they are paper, and every
    coarser level is the finer one halved (cv2.pyrDown), as for the whole board (the coarser
    levels are recomputed only around the squares)."""
    import cv2

    board = boards.Board()
    whole, missing = board.texture()[0][1], board.texture(gone)
    scale, side = int(missing[0][0]), board.MARKER * int(missing[0][0])
    squares = np.zeros(whole.shape[:2], bool)
    for marker_id in gone:
        x0, y0 = (int(v) * scale for v in board.marker_square(marker_id)[0])
        squares[y0:y0 + side, x0:x0 + side] = True
        assert (missing[0][1][y0:y0 + side, x0:x0 + side] == (*board.PAPER, 255)).all()
    changed = np.any(whole != missing[0][1], axis=2)
    assert changed.any() and not changed[~squares].any()
    for (_, finer), (_, coarser) in pairwise(missing):
        assert np.array_equal(coarser, cv2.pyrDown(finer))


def test_threads_that_render_at_once_share_one_texture():
    """The checks of a submission render scenes in threads: one texture per set of missing markers."""
    import threading

    board = boards.Board()
    got = []
    threads = [threading.Thread(target=lambda: got.append(board.texture([2, 6]))) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(got) == 4 and all(levels is got[0] for levels in got)


def test_a_board_with_markers_missing_makes_only_the_levels_a_scene_warps():
    """A scene warps one level of the board: the others of a board with markers missing are not
    made (a copy of every level cost 60 ms and 46 MB for each of the five such boards of a grading)."""
    board = boards.Board()
    missing = board.texture([3, 7])
    assert missing.shapes == tuple(image.shape for _, image in board.texture())
    assert missing._images == {}
    scale, image = missing[2]
    assert scale == board.texture()[2][0] and image.shape == missing.shapes[2]
    assert sorted(missing._images) == [2]


def test_threads_that_ask_at_once_share_one_default_board(monkeypatch):
    """The checks of a submission render in threads: the default board is drawn once among them."""
    import threading

    monkeypatch.setattr(boards, "_DEFAULT_BOARD", None)
    got = []
    threads = [threading.Thread(target=lambda: got.append(boards.default_board())) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(got) == 4 and all(board is got[0] for board in got)
