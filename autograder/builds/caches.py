"""The grader's two caches of colcon builds, so that identical work is built once per course.

- :class:`InterfaceCache`: built interface packages (``.msg`` files: a CMake build of 10-40 s), one
  entry per :func:`content_key` (the package's files, the interface packages it builds on, this
  environment); a workspace's other packages are built on top of the entry's install.
- :class:`WorkspaceBuilds`: successful ``colcon build --symlink-install`` of a workspace, one entry
  per :func:`workspace_key` (every file name of ``src/``, the bytes of all but its modules), copied
  into an identical workspace with its paths moved there.

Entries appear atomically (a staging folder renamed); only the grader writes them.
:mod:`autograder.builds.workspace_build` builds and fills them.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import shutil
import sys
import time
from pathlib import Path

from autograder.sandbox import untrusted

#: Bumped when the way interface packages are built changes: older cache entries are then unused.
CACHE_VERSION = "1"

def content_key(folder: Path, underlay_keys=()) -> str:
    """The cache key of an interface package: its files (names and bytes), the keys of the
    workspace's interface packages it builds on, this interpreter and CACHE_VERSION."""
    digest = hashlib.sha256(f"{CACHE_VERSION}\0{sys.version}\0{sys.prefix}\0".encode())
    for key in underlay_keys:
        digest.update(key.encode() + b"\0")
    for path in sorted(p for p in folder.rglob("*") if p.is_file() or p.is_symlink()):
        kind, content = untrusted.read_entry(path)  # a student's link is named, never followed
        digest.update(str(path.relative_to(folder)).encode() + b"\0" + (b"link " if kind == "link" else b"")
                      + content + b"\0")
    return digest.hexdigest()[:32]



class InterfaceCache:
    """Built interface packages, one folder per content key: ``<root>/<key>/install/`` (a colcon
    install prefix). Written by the grader (root) only; entries appear atomically. Failed builds
    are not kept (see _build_interface); store(key, None, reason) records one all the same."""

    def __init__(self, root: Path):
        self.root = Path(root)

    def entry(self, key: str) -> Path:
        return self.root / key

    def lookup(self, key: str) -> tuple[Path | None, str | None]:
        """(install prefix, None) when built, (None, reason) when it failed, (None, None) when new."""
        entry = self.entry(key)
        if (entry / "install" / "setup.bash").is_file():
            return entry / "install", None
        if (entry / "failed.txt").is_file():
            return None, (entry / "failed.txt").read_text()
        return None, None

    def store(self, key: str, install: Path | None, reason: str = "") -> None:
        def fill(staging: Path) -> None:
            if install is not None:
                shutil.copytree(install, staging / "install", symlinks=True)
            else:
                (staging / "failed.txt").write_text(reason)
        _store_atomically(self.entry(key), fill)


def _store_atomically(entry: Path, fill) -> None:
    """Make the folder `entry` appear whole: `fill(folder)` fills a staging folder beside it,
    which is then renamed; when another worker stored the same entry meanwhile, theirs stays."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    staging = entry.parent / f".{entry.name}.{os.getpid()}.{time.monotonic_ns()}"
    staging.mkdir()
    try:
        fill(staging)
        os.rename(staging, entry)
    except OSError:
        shutil.rmtree(staging, ignore_errors=True)


#: Set to 0 to build every workspace with colcon even when an identical one was built before.
#: What colcon and setuptools make of a workspace depends on their versions too.
_BUILD_TOOLS = ("colcon-core", "colcon-ros", "colcon-python-setup-py", "setuptools")


def workspace_key(src: Path, interface_keys=()) -> str:
    """The key of a workspace's ``colcon build --symlink-install``: the names of every file of
    `src` and the bytes of all but the Python modules (setup.py's count), the keys of the
    interface packages it builds on, this interpreter, the build tools' versions and
    CACHE_VERSION."""
    digest = hashlib.sha256(f"{CACHE_VERSION}\0{sys.version}\0{sys.prefix}\0{_build_tool_versions()}\0".encode())
    for key in interface_keys:
        digest.update(key.encode() + b"\0")
    for path in sorted(p for p in Path(src).rglob("*") if p.is_file() or p.is_symlink()):
        relative = path.relative_to(src)
        if any(part in ("__pycache__", ".ipynb_checkpoints") for part in relative.parts):
            continue
        digest.update(str(relative).encode() + b"\0")
        if path.is_symlink() or path.suffix != ".py" or path.name == "setup.py":
            kind, content = untrusted.read_entry(path)
            digest.update((b"link " if kind == "link" else b"") + content + b"\0")
    return digest.hexdigest()[:32]


@functools.cache
def _build_tool_versions() -> str:
    """"colcon-core=0.x ..." of _BUILD_TOOLS (looked up once: it reads the venv's metadata)."""
    from importlib import metadata

    versions = []
    for tool in _BUILD_TOOLS:
        try:
            versions.append(f"{tool}={metadata.version(tool)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{tool}=none")
    return " ".join(versions)


class WorkspaceBuilds:
    """Successful workspace builds (``build/`` and ``install/``), one folder per workspace_key,
    with the folders they were built in (``paths.json``): a copy of one, those paths replaced by
    another workspace's in every file and link, is what colcon would have built there. Written
    by the grader only, from builds no other code of the student's uid ran beside (see
    build_for_checks)."""

    def __init__(self, root: Path):
        self.root = Path(root)

    def entry(self, key: str) -> Path:
        return self.root / key

    def restore(self, key: str, ws: Path, scratch: Path) -> bool:
        """Copy the build of `key` into `ws` (which has neither build/ nor install/) for a build
        whose scratch folder is `scratch`; False when there is none."""
        entry = self.entry(key)
        try:
            paths = json.loads((entry / "paths.json").read_text())
        except (OSError, ValueError):
            return False
        moves = sorted({paths["workspace"]: str(ws), paths["scratch"]: str(scratch)}.items(),
                       key=lambda move: -len(move[0]))
        for folder in ("build", "install"):
            shutil.copytree(entry / folder, Path(ws) / folder, symlinks=True)
            _relocate(Path(ws) / folder, moves)
        return True

    def store(self, key: str, ws: Path, scratch: Path) -> None:
        def fill(staging: Path) -> None:
            for folder in ("build", "install"):
                shutil.copytree(Path(ws) / folder, staging / folder, symlinks=True)
            (staging / "paths.json").write_text(json.dumps({"workspace": str(ws), "scratch": str(scratch)}))
        _store_atomically(self.entry(key), fill)


def _relocate(tree: Path, moves: list[tuple[str, str]]) -> None:
    """Replace the old paths of `moves` by the new ones in every link target and file of `tree`."""
    encoded = [(old.encode(), new.encode()) for old, new in moves]

    def moved(data: bytes) -> bytes:
        for old, new in encoded:
            data = data.replace(old, new)
        return data

    for directory, dirs, files in os.walk(os.fsencode(tree)):
        for name in [*files, *dirs]:
            path = os.path.join(directory, name)
            if os.path.islink(path):
                target = os.readlink(path)
                new_target = moved(target)
                if new_target != target:
                    os.unlink(path)
                    os.symlink(new_target, path)
            elif name in files:
                with open(path, "rb") as handle:
                    data = handle.read()
                new_data = moved(data)
                if new_data != data:
                    with open(path, "wb") as handle:
                        handle.write(new_data)


# ---- where they are ----------------------------------------------------------------------------

def cache_of(course: Path) -> InterfaceCache:
    """The course's cache of built interface packages: COURSE_DIR/autograder/.interface-cache."""
    return InterfaceCache(Path(course) / "autograder" / ".interface-cache")


def builds_of(course: Path) -> WorkspaceBuilds:
    """The course's kept workspace builds: COURSE_DIR/autograder/.workspace-builds."""
    return WorkspaceBuilds(Path(course) / "autograder" / ".workspace-builds")


def local_cache() -> InterfaceCache:
    """A cache of interface builds for runs outside a course (tests, benchmarks, record-answers)."""
    import tempfile

    return InterfaceCache(Path(tempfile.gettempdir()) / f"ros2cv-interface-cache-{os.getuid()}")
