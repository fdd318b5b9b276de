"""Images that the course always draws the same, kept on disk beside the code that draws them.

The default board (its pictures and its texture levels, about 46 MB) takes about 0.1 s of
processor time to draw, in every process that shows it: a notebook's kernel, the webcam node and
the grader's checks; the table's wood grain 16 ms and the webcam's noise field 10 ms. :func:`load`
maps a kept copy instead (read-only; only the pages a process reads are read), :func:`store`
keeps one, and :func:`kept` does both for one array of any number type.

A copy lives in this package's ``__pycache__`` folder, named by a key of what drew it (the
drawing modules' source and OpenCV's and numpy's versions: :func:`key`). It is trusted only when
the folder and the file belong to root or to the owner of this package's code and no one else
may write them, the same protection as the code's own: a student's process (another uid) can
neither write a copy nor make one be read. A process that cannot write there draws as before.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import mmap
import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

PACKAGE = Path(__file__).resolve().parent
FOLDER = PACKAGE / "__pycache__"
_MAGIC = b"course_lib drawn images 1\n"
_ALIGN = 64


def key(*modules: str) -> str:
    """A key of the images drawn by `modules` (file names in this package): their source, and the
    versions of OpenCV and numpy."""
    digest = hashlib.sha256(f"{cv2.__version__}\0{np.__version__}\0".encode())
    for module in modules:
        digest.update((PACKAGE / module).read_bytes() + b"\0")
    return digest.hexdigest()[:24]


def load(name: str, key: str) -> list[np.ndarray] | None:
    """The images kept as `name` with this `key` (read-only arrays), or None when there is no
    trusted copy."""
    path = FOLDER / f"{name}-{key}.bin"
    if not _trusted(FOLDER, os.stat) or not _trusted(PACKAGE, os.stat):
        return None
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return None
    try:
        if not _trusted(fd, os.fstat):
            return None
        mapped = mmap.mmap(fd, 0, prot=mmap.PROT_READ)
    except (OSError, ValueError):
        return None
    finally:
        os.close(fd)
    return _arrays(mapped)


def store(name: str, key: str, images: list[np.ndarray]) -> None:
    """Keep `images` (uint8) as `name` with this `key`, when this process may (see the module's
    docstring); a copy of another key is replaced. Never fails: a copy not kept is drawn again."""
    if os.geteuid() not in _owners() or not _trusted(PACKAGE, os.stat):
        return
    with contextlib.suppress(OSError):
        FOLDER.mkdir(mode=0o755, exist_ok=True)
        if not _trusted(FOLDER, os.stat):
            return
        header = json.dumps([list(image.shape) for image in images]).encode() + b"\n"
        handle, staging = tempfile.mkstemp(prefix=f".{name}-", dir=FOLDER)
        try:
            with os.fdopen(handle, "wb") as out:
                out.write(_MAGIC + header)
                for image in images:
                    out.write(b"\0" * (-out.tell() % _ALIGN))
                    out.write(np.ascontiguousarray(image, np.uint8).tobytes())
            os.chmod(staging, 0o644)
            for old in FOLDER.glob(f"{name}-*.bin"):
                old.unlink()
            os.replace(staging, FOLDER / f"{name}-{key}.bin")
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(staging)


def kept(name: str, key: str, draw: Callable[[], np.ndarray], dtype=np.uint8) -> np.ndarray:
    """The array kept as `name` with this `key` (read-only, of `dtype`), else draw()'s as `dtype`,
    then kept when this process may."""
    loaded = load(name, key)
    if loaded is not None and len(loaded) == 1:
        with contextlib.suppress(ValueError):  # bytes that make no array of `dtype`: drawn again
            return loaded[0].view(dtype)
    array = np.ascontiguousarray(draw(), dtype)
    store(name, key, [array.view(np.uint8)])
    return array


def _arrays(mapped: mmap.mmap) -> list[np.ndarray] | None:
    if mapped[:len(_MAGIC)] != _MAGIC:
        return None
    end = mapped.find(b"\n", len(_MAGIC))
    try:
        shapes = json.loads(mapped[len(_MAGIC):end])
    except ValueError:
        return None
    images, offset = [], end + 1
    for shape in shapes:
        offset += -offset % _ALIGN
        count = int(np.prod(shape))
        if offset + count > len(mapped):
            return None
        images.append(np.frombuffer(mapped, np.uint8, count, offset).reshape(shape))
        offset += count
    return images


def _owners() -> set[int]:
    """Who may have written a trusted copy: root and the owner of this package's code."""
    return {0, os.stat(PACKAGE).st_uid}


def _trusted(target, stat_of) -> bool:
    """True when `target` (a path or an open file) belongs to root or the code's owner and no
    one else may write it."""
    try:
        info = stat_of(target)
    except OSError:
        return False
    return info.st_uid in _owners() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)
