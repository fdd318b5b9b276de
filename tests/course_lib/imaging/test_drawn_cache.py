"""Tests for course_lib.imaging.drawn_cache: the default board is drawn once and then mapped from disk,
from a copy no one but root or the code's owner can have written."""

import os

import numpy as np
import pytest

from course_lib.imaging import boards, drawn_cache, scenes


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """The cache in a folder of its own (the package's stand-in: the tests' tmp_path)."""
    tmp_path.chmod(0o755)
    monkeypatch.setattr(drawn_cache, "PACKAGE", tmp_path)
    monkeypatch.setattr(drawn_cache, "FOLDER", tmp_path / "__pycache__")
    return tmp_path / "__pycache__"


def test_kept_images_come_back_the_same_and_read_only(folder):
    images = [np.arange(24, dtype=np.uint8).reshape(2, 3, 4), np.full((5, 7, 3), 9, np.uint8)]
    drawn_cache.store("thing", "k1", images)
    kept = drawn_cache.load("thing", "k1")
    assert [k.shape for k in kept] == [i.shape for i in images]
    assert all(np.array_equal(k, i) for k, i in zip(kept, images, strict=True))
    assert not kept[0].flags.writeable
    assert drawn_cache.load("thing", "k2") is None  # drawn by other code: not the same images
    drawn_cache.store("thing", "k2", images[:1])
    assert sorted(p.name for p in folder.glob("thing-*")) == ["thing-k2.bin"]  # the old key's copy went


@pytest.mark.parametrize("loosen", ["file", "folder"])
def test_a_copy_that_others_may_write_is_not_read(folder, loosen):
    """A copy, or its folder, writable by group or others could be a student's: it is not trusted."""
    drawn_cache.store("thing", "k", [np.zeros((2, 2), np.uint8)])
    (folder / "thing-k.bin" if loosen == "file" else folder).chmod(0o666 if loosen == "file" else 0o777)
    assert drawn_cache.load("thing", "k") is None


def test_a_copy_of_another_owner_is_neither_read_nor_written(folder, monkeypatch):
    drawn_cache.store("thing", "k", [np.zeros((2, 2), np.uint8)])
    monkeypatch.setattr(drawn_cache, "_owners", lambda: {os.geteuid() + 12345})
    assert drawn_cache.load("thing", "k") is None
    drawn_cache.store("thing", "other", [np.zeros((2, 2), np.uint8)])
    assert not (folder / "thing-other.bin").exists()


def test_the_default_board_from_a_kept_copy_draws_the_same_frames(folder, monkeypatch):
    """The first default board is drawn and kept; the next is mapped from the copy, and scenes
    (with and without markers missing) are the same bytes."""
    monkeypatch.setattr(drawn_cache, "key", lambda *modules: "test")
    drawn = boards._kept_default_board()
    assert (folder / "default_board-test.bin").exists()
    mapped = boards._kept_default_board()
    assert not mapped.texture()[0][1].flags.writeable  # mapped, not drawn
    for name in ("cat", "dog"):
        assert np.array_equal(drawn.pictures[name], mapped.pictures[name])
    for seed, missing in ((3, ()), (4, (2, 7))):
        a = scenes.render_scene(seed, board=drawn, missing_markers=missing)
        b = scenes.render_scene(seed, board=mapped, missing_markers=missing)
        assert np.array_equal(a.frame, b.frame)


def test_kept_arrays_of_any_number_type_are_drawn_once_then_mapped(folder):
    """kept(): the first call draws and keeps, the next maps the copy (read-only), the same numbers."""
    drawn = []

    def draw():
        drawn.append(1)
        return np.random.default_rng(1).standard_normal((4, 5, 3), dtype=np.float32)

    first = drawn_cache.kept("field", "k", draw, np.float32)
    second = drawn_cache.kept("field", "k", draw, np.float32)
    assert len(drawn) == 1 and second.dtype == np.float32 and not second.flags.writeable
    assert np.array_equal(first, second)


def test_the_wood_grain_and_the_noise_field_from_kept_copies_are_the_numbers_drawn(folder, monkeypatch):
    from course_lib.imaging import camera_views, table

    monkeypatch.setattr(drawn_cache, "key", lambda *modules: "test")
    monkeypatch.setattr(table, "_GRAIN", {})
    grain = table._wood_grain((40, 30))
    monkeypatch.setattr(table, "_GRAIN", {})
    mapped = table._wood_grain((40, 30))
    assert not mapped.flags.writeable and np.array_equal(grain, table._draw_wood_grain((40, 30)))
    assert np.array_equal(mapped, grain)
    camera_views._noise_tile.cache_clear()
    noise = camera_views._noise_tile((640, 480))
    camera_views._noise_tile.cache_clear()
    assert (folder / "noise_tile-test.bin").exists() and noise.shape == (480 + 64, 640 + 64, 3)
    assert np.array_equal(camera_views._noise_tile((640, 480)), noise)
    assert not camera_views._noise_tile((640, 480)).flags.writeable  # mapped
    assert camera_views._noise_tile((32, 24)).shape == (88, 96, 3)  # drawn: only the default size is kept
    assert sorted(p.name for p in folder.glob("noise_tile*")) == ["noise_tile-test.bin"]
