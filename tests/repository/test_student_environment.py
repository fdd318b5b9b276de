"""What a student gets holds no answer: no reference solution, no answer key, no hidden test; and
an untouched release earns nothing.

A student's environment is what the course installs for students, the course-lib wheel built
from pyproject.toml (course_lib with course_lib.checks), plus the released assignments (nbgrader's
release/ folder). The instructor's side (autograder/, assignments/source/, the reference
packages in assignments/reference_ws/) must never reach it.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import nbformat
import pytest
from support import course as course_support

from autograder.builds import reference
from course_lib import contract
from course_lib.checks import assignments, registry, runner

REPO = contract.ROOT
ASSIGNMENTS = list(assignments.ASSIGNMENTS)

pytestmark = pytest.mark.timeout(600)


# --- what counts as a reference solution -------------------------------------------------------

def significant_lines(text: str) -> list[str]:
    """The lines of code that make a solution what it is: stripped, without blank lines,
    comments, docstrings, solution markers and short generic lines (``pass``, ``return crops``)."""
    lines = []
    for line in text.splitlines():
        line = line.strip()
        if (len(line) < 16 or line.startswith(("#", '"""', "'''", "%%")) or "SOLUTION" in line
                or "HIDDEN TESTS" in line):
            continue
        lines.append(line)
    return lines


def _between(text: str, begin: str, end: str) -> list[str]:
    blocks, current = [], None
    for line in text.splitlines():
        if begin in line:
            current = []
        elif end in line and current is not None:
            blocks.append("\n".join(current))
            current = None
        elif current is not None:
            current.append(line)
    return blocks


def reference_blocks() -> dict[str, list[str]]:
    """Every piece of reference code of the instructor's side, by where it comes from: the solution
    and hidden-test blocks of the source notebooks, the answer keys' functions, and the reference
    packages' modules."""
    blocks = {}
    for assignment in ASSIGNMENTS:
        nb = reference.source_notebook(assignment)
        for index, cell in enumerate(c for c in nb.cells if c.cell_type == "code"):
            for kind, begin, end in (("solution", "### BEGIN SOLUTION", "### END SOLUTION"),
                                     ("hidden test", "### BEGIN HIDDEN TESTS", "### END HIDDEN TESTS")):
                for number, block in enumerate(_between(cell.source, begin, end)):
                    blocks[f"{assignment}: {kind} {index}.{number}"] = significant_lines(block)
    for path in sorted((REPO / "autograder" / "answers").glob("*.py")):
        for number, block in enumerate(path.read_text().split("\ndef ")[1:]):
            blocks[f"answer key {path.stem}: function {number}"] = significant_lines(block.split("\n", 1)[1])
    # The reference packages: their solution regions (the rest of their files is given to students).
    packages = REPO / "assignments" / "reference_ws" / "src"
    for path in sorted(p for package in packages.iterdir() for p in (package / package.name).glob("*.py")):
        for number, block in enumerate(_between(path.read_text(), "### BEGIN SOLUTION", "### END SOLUTION")):
            blocks[f"reference package {path.relative_to(REPO)} solution {number}"] = significant_lines(block)
    return {name: lines for name, lines in blocks.items() if lines}


def leaks(files: dict[str, str], blocks: dict[str, list[str]]) -> list[str]:
    """Which reference blocks a set of files holds: at least half of a block's significant lines
    (and at least one) in one file."""
    found = []
    for path, text in files.items():
        present = set(significant_lines(text))
        for name, lines in blocks.items():
            hits = sum(line in present for line in lines)
            if hits >= max(1, math.ceil(len(lines) / 2)):
                found.append(f"{path} holds {hits} of {len(lines)} lines of {name}")
    return found


# --- what a student's environment holds --------------------------------------------------------

def _text(data: bytes) -> str | None:
    try:
        return data.decode()
    except UnicodeDecodeError:
        return None


@pytest.fixture(scope="module")
def release(tmp_path_factory) -> Path:
    course = course_support.released_course(tmp_path_factory, tmp_path_factory.mktemp("course"), ASSIGNMENTS)
    return course / "release"


@pytest.fixture(scope="module")
def wheel_files(tmp_path_factory) -> dict[str, str]:
    """The text files of the course-lib wheel, built from a copy of the project (pip, no network)."""
    work = tmp_path_factory.mktemp("wheel")
    source = work / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, source / name)
    shutil.copytree(REPO / "course_lib", source / "course_lib", ignore=shutil.ignore_patterns("__pycache__"))
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                           "--disable-pip-version-check", "-q", "-w", str(work / "dist"), str(source)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    (wheel,) = (work / "dist").glob("course_lib-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        return {name: text for name in archive.namelist() if (text := _text(archive.read(name))) is not None}


def test_the_wheel_holds_the_student_package_only(wheel_files):
    """The wheel installs course_lib (with its checks and recorded self-check answers), nothing of
    the instructor's side."""
    tops = {name.split("/", 1)[0] for name in wheel_files if not name.split("/", 1)[0].endswith(".dist-info")}
    assert tops == {"course_lib"}
    assert "course_lib/checks/assignments/brightness.py" in wheel_files
    assert "course_lib/checks/recorded/brightness.json" in wheel_files
    # The student lab's Validate progress: its configuration and lab extension.
    lab = "course_lib/notebook/student_lab/"
    assert {lab + "jupyter_server_config.py", lab + "labextensions/@course-lib/validate-progress/package.json",
            lab + "labextensions/@course-lib/validate-progress/static/remoteEntry.js"} <= set(wheel_files)


@pytest.mark.slow
def test_no_reference_solution_in_the_wheel_or_the_release(wheel_files, release):
    """No reference solution, answer key or hidden test in anything a student can import or read."""
    files = dict(wheel_files)
    for path in sorted(release.rglob("*")):
        if path.is_file() and (text := _text(path.read_bytes())) is not None:
            files[str(path.relative_to(release.parent))] = text
    blocks = reference_blocks()
    assert any(name.startswith("answer key brightness") for name in blocks)
    assert any("reference package" in name for name in blocks)
    assert leaks(files, blocks) == []


def test_the_scan_finds_a_planted_solution(wheel_files):
    """The scan is not blind: a module of the wheel that carried a solution block is reported."""
    blocks = reference_blocks()
    name, lines = next((n, ls) for n, ls in blocks.items() if n.startswith("catdog_warp: solution"))
    planted = dict(wheel_files)
    planted["course_lib/imaging/scenes.py"] += "\n" + "\n".join(lines)
    assert any(name in leak for leak in leaks(planted, blocks))
    key = next(n for n in blocks if n.startswith("answer key brightness"))
    planted = {"course_lib/helpers.py": "def f(image):\n    " + "\n    ".join(blocks[key])}
    assert any(key in leak for leak in leaks(planted, blocks))


# --- an untouched release earns nothing --------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("assignment", ASSIGNMENTS)
def test_untouched_release_earns_nothing(release, tmp_path, monkeypatch, assignment):
    """The released stubs, handed in as they are (and built as the grader builds them), score 0 in
    every graded check, and a check that calls a stub says to replace NotImplementedError (the
    quiz's: that no question is answered yet)."""
    from autograder.builds import workspace_build

    nb = nbformat.read(release / assignment / f"{assignment}.ipynb", as_version=4)
    has_packages = bool(assignments.spec(assignment).packages)
    if has_packages:
        reference.write_files(nb, tmp_path)
        workspace_build.build_here(assignment, tmp_path)
        monkeypatch.setenv(contract.BUILD_REPORT_ENV, str(workspace_build.report_path(tmp_path)))
    verdicts = []
    for name in registry.checks_of(assignment):
        result = runner.execute(assignment, name, 7, workdir=tmp_path, mode="graded")
        verdicts.append("\n".join(result.verdict_lines()))
        assert result.points == 0, verdicts[-1]
    assert ("NotImplementedError" if has_packages else "not answered yet") in "\n".join(verdicts)
    if assignment == "brightness":
        assert "replace `raise NotImplementedError()`" in verdicts[0]
