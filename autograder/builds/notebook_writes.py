"""The files a notebook will write, read from the notebook without running it, and a digest of
a folder's files to tell afterwards whether the run wrote exactly those.

An assignment's notebook writes its ROS package with ``%%writefile`` cells and makes its folders
and empty files with ``!mkdir -p`` and ``!touch`` lines. :func:`predicted_writes` reads those
(and nothing else: a file written any other way is simply not predicted), so that the grader can
build and check the package while nbgrader runs the notebook (autograder.grading.early_checks).
:func:`folder_digest` of the folder the notebook really ran in then says whether the prediction
held: the grader uses the early build and verdicts only when the two digests are equal.
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
from pathlib import Path, PurePosixPath

from autograder.sandbox import untrusted
from course_lib.contract import WORKSPACE

#: Characters that make a shell line more than a list of plain paths (quotes are allowed: shlex).
_SHELL_SPECIAL = set("$`;&|<>*?[]{}~\\")

#: What a run leaves beside the files it was given, and the checks never read: colcon's output
#: folders, Python's byte code, Jupyter's checkpoints. The notebooks themselves (nbgrader writes
#: the graded copy) are left out too.
_NOT_COMPARED_DIRS = {"__pycache__", ".ipynb_checkpoints"}
_COLCON_OUTPUT = {"build", "install", "log"}


class Writes:
    """What a notebook's cells write, in order: {relative path: bytes} and the folders it makes."""

    def __init__(self):
        self.files: dict[str, bytes | None] = {}  # None: touched
        self.folders: set[str] = set()

    def apply(self, folder: Path) -> None:
        """Write them into `folder` (which holds the submitted files), as the notebook's run would."""
        for name in sorted(self.folders):
            (folder / name).mkdir(parents=True, exist_ok=True)
        for name, data in self.files.items():
            path = folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            if data is None:  # !touch: an existing file keeps its bytes
                path.touch()
            else:
                path.write_bytes(data)


def _relative(name: str) -> str | None:
    """`name` as a normalised path inside the notebook's folder, or None when it leaves it."""
    path = PurePosixPath(os.path.normpath(name))
    if path.is_absolute() or not path.parts or path.parts[0] == "..":
        return None
    return str(path)


def _shell_line(line: str, writes: Writes) -> None:
    """A top-level ``!mkdir -p PATH...`` or ``!touch PATH...`` line; any other is not predicted."""
    if _SHELL_SPECIAL & set(line):
        return
    try:
        words = shlex.split(line)
    except ValueError:
        return
    if words[:2] == ["mkdir", "-p"] and len(words) > 2:
        names = [_relative(word) for word in words[2:]]
        if None not in names:
            writes.folders.update(names)
    elif words[:1] == ["touch"] and len(words) > 1 and not any(word.startswith("-") for word in words[1:]):
        names = [_relative(word) for word in words[1:]]
        if None not in names:
            for name in names:
                writes.files.setdefault(name, None)  # None: empty, unless written before


def _writefile(first: str, body: str, writes: Writes) -> None:
    """A ``%%writefile [-a] PATH`` cell: IPython writes the cell's text after its first line, with
    a newline at its end (IPython ends every cell with one before it runs it)."""
    try:
        words = shlex.split(first)[1:]
    except ValueError:
        return
    append = bool(words) and words[0] in ("-a", "--append")
    words = words[1:] if append else words
    if len(words) != 1:
        return
    name = _relative(os.path.expanduser(words[0]))
    if name is None:
        return
    data = (body + "\n" if body and not body.endswith("\n") else body).encode()
    if append:
        before = writes.files.get(name)
        if before is None and name not in writes.files:
            return  # appending to a file the prediction does not know: not predicted
        data = (before or b"") + data
    writes.files[name] = data


def predicted_writes(notebook: Path) -> Writes:
    """The files and folders `notebook`'s code cells write with %%writefile, !mkdir -p and !touch."""
    try:
        cells = json.loads(Path(notebook).read_text(encoding="utf-8")).get("cells", [])
    except (OSError, ValueError, AttributeError):
        return Writes()
    sources = []
    for cell in cells:
        if isinstance(cell, dict) and cell.get("cell_type") == "code":
            source = cell.get("source", "")
            sources.append("".join(source) if isinstance(source, list) else str(source))
    return writes_of(sources)


def writes_of(sources) -> Writes:
    """What code cells with these sources write, in order (see predicted_writes)."""
    writes = Writes()
    for source in sources:
        first, _, body = source.partition("\n")
        if first.startswith("%%writefile"):
            _writefile(first, body, writes)
            continue
        if first.startswith("%%"):  # another cell magic: its lines are not Python or shell lines
            continue
        for line in source.splitlines():
            if line.startswith("!"):  # top level only: an indented one may not run
                _shell_line(line[1:].strip(), writes)
    return writes


def folder_digest(folder: Path) -> str:
    """A digest of the files under `folder` (names, bytes, link targets) that the checks may read:
    everything but colcon's build/install/log of ros2_ws, byte code, checkpoints and top-level
    notebooks."""
    folder = Path(folder)
    digest = hashlib.sha256()
    for directory, dirs, files in os.walk(folder):
        here = Path(directory)
        relative = here.relative_to(folder)
        dirs[:] = sorted(d for d in dirs if d not in _NOT_COMPARED_DIRS
                         and not (relative == Path(WORKSPACE) and d in _COLCON_OUTPUT))
        for name in sorted(files):
            path = here / name
            if relative == Path(".") and name.endswith(".ipynb"):
                continue
            entry = str(relative / name).encode()
            kind, content = untrusted.read_entry(path)  # never followed, never blocked on
            if kind == "link":
                digest.update(b"L" + entry + b"\0" + content + b"\0")
            elif kind == "other":
                digest.update(b"S" + entry + b"\0")
            else:
                digest.update(b"F" + entry + b"\0" + hashlib.sha256(content).digest())
    return digest.hexdigest()
