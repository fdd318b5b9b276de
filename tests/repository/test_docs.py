"""Do the docs describe the code as it is? Every module, path and ``python -m`` command that README.md,
docs/*.md and assignments/README.md name exists; the tables and points the docs give are the specs'
(course_lib/checks/assignments/); and an assignment is its file alone."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from support.from_source import assignments_build

from course_lib import contract
from course_lib.checks import assignments, registry

ROOT = contract.ROOT
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "assignments" / "README.md"]


def _top_folders() -> list[str]:
    """The repository's top-level folders, without what git ignores: a student's lab puts fetched
    assignments (brightness/) there and the tests artifacts/, whose names the docs use otherwise."""
    folders = sorted(p.name for p in ROOT.iterdir() if p.is_dir() and not p.name.startswith("."))
    ignored = subprocess.run(["git", "check-ignore", *folders], cwd=ROOT, capture_output=True, text=True)
    return [name for name in folders if name not in ignored.stdout.split()]


#: The repository's top-level folders: a path in backticks that starts with one of them is a path of the repository.
TOP = _top_folders()
PACKAGES = ("course_lib", "autograder", "coursehub", "benchmarks")


def _spans(path: Path) -> list[str]:
    return re.findall(r"`([^`\n]+)`", path.read_text())


def _defines(file: Path, name: str) -> bool:
    name = re.escape(name)
    pattern = rf"^\s*((def |class )?{name}\b|(from .* )?import .*\b{name}\b)"
    return re.search(pattern, file.read_text(), re.M) is not None


def _module_exists(dotted: str) -> bool:
    """A module of the repository, or a name defined in one (course_lib.checks.result.round_points),
    or a name a package gives on import (``course_lib.pan_camera``: course_lib's lazy names)."""
    return _module_file_exists(dotted) or _importable(dotted)


def _importable(dotted: str) -> bool:
    import importlib

    first, *rest = dotted.split(".")
    try:
        value = importlib.import_module(first)
        for name in rest:
            value = getattr(value, name)
    except (ImportError, AttributeError):
        return False
    return True


def _module_file_exists(dotted: str) -> bool:
    parts = dotted.split(".")
    folder, rest = ROOT, list(parts)
    while rest:
        name = rest[0]
        if (folder / name).is_dir():
            folder, rest = folder / name, rest[1:]
            continue
        file = folder / f"{name}.py"
        if file.is_file():
            return not rest[1:] or _defines(file, rest[1])
        return (folder / "__init__.py").is_file() and _defines(folder / "__init__.py", name)
    return True


def _named(kind: str) -> list[tuple[str, str]]:
    found = []
    for doc in DOCS:
        for span in _spans(doc):
            for command in re.findall(r"python -m ([\w.]+)", span):
                if kind == "command" and command.split(".")[0] in PACKAGES:
                    found.append((str(doc.relative_to(ROOT)), command))
            for token in span.split():
                token = token.strip("(),;:'\"").rstrip(".")
                if any(c in token for c in "<>*{}$[]=") or "..." in token:
                    continue
                if kind == "path" and "/" in token and token.split("/")[0] in TOP:
                    found.append((str(doc.relative_to(ROOT)), token))
                if kind == "module" and "/" not in token and re.fullmatch(r"[\w.]+", token) \
                        and token.split(".")[0] in PACKAGES and "." in token and not token.endswith((".py", ".md")):
                    found.append((str(doc.relative_to(ROOT)), token))
    return sorted(set(found))


def test_every_path_named_in_the_docs_exists():
    """Each repository path in backticks (course_lib/..., tests/..., docs/...) is a file or folder."""
    missing = [(doc, path) for doc, path in _named("path") if not (ROOT / path).exists()]
    assert not missing, missing


def test_every_module_named_in_the_docs_exists():
    """Each dotted name of the course's packages in backticks (course_lib.checks.runner) is a module or in one."""
    missing = [(doc, name) for doc, name in _named("module") if not _module_exists(name)]
    assert not missing, missing


def test_every_python_m_command_in_the_docs_runs_a_module_that_exists():
    """``python -m X`` in the docs names a module of the repository with something to run."""
    def runnable(dotted: str) -> bool:
        path = ROOT.joinpath(*dotted.split("."))
        return (path / "__main__.py").is_file() or path.with_suffix(".py").is_file()

    missing = [(doc, name) for doc, name in _named("command") if not runnable(name)]
    assert _named("command") and not missing, missing


def _total(name: str) -> float:
    return sum(check.points for check in registry.checks_of(name).values())


def test_assignments_readme_table_is_written_from_the_specs():
    """assignments/README.md's table of contracts is what ``python assignments/build.py`` writes from the specs."""
    build = assignments_build()
    text = build.README.read_text()
    assert build.readme_with_table(text, assignments.ASSIGNMENTS) == text


def test_points_in_the_docs_are_the_checks_points():
    """Each assignment's points and each check's points in assignments/README.md, and the counts in
    docs/instructors.md, are what the checks and specs say."""
    readme = (ROOT / "assignments" / "README.md").read_text()
    headings = dict(re.findall(r"^### (\w+) \((\d+) points\)", readme, re.M))
    assert {name: float(points) for name, points in headings.items()} == {a: _total(a) for a in assignments.ASSIGNMENTS}
    for section in re.split(r"^### ", readme.split("\n## Contracts\n", 1)[1], flags=re.M)[1:]:
        name = section.split()[0]
        checks = registry.checks_of(name)
        for noted in re.findall(r"\*\(checks? ([^)]*)\)\*", section):
            for check, points in re.findall(r"`(\w+)`,? (\d+)", noted):
                assert checks[check].points == float(points), (name, check, points)
    instructors = (ROOT / "docs" / "instructors.md").read_text()
    count = re.search(r"\*\*quiz\*\* is (\d+) multiple-choice questions", instructors)
    assert int(count.group(1)) == len(assignments.spec("quiz").questions)
    words = {"five": 5, "six": 6, "seven": 7, "eight": 8}
    number = re.search(r"the nbgrader source notebooks of (\w+) assignments", instructors).group(1)
    assert words[number] == len(assignments.ASSIGNMENTS)


SCRATCH = '''"""A scratch assignment: one file, nothing else."""
from course_lib.checks.context import Context
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

SPEC = Assignment("scratch", "99", {}, NotebookText(intro="# Scratch", checks={"sums": ("sums",)}))
selfcheck, grade = SPEC.selfcheck, SPEC.grade


@check(points=3, timeout=10)
def sums(ctx: Context) -> None:
    """One plus one is two."""
    ctx.item(1 + 1 == 2, "1 + 1 == 2")
'''


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """The scratch assignment, its file in a folder of its own that course_lib.checks.assignments searches too."""
    (tmp_path / "scratch.py").write_text(SCRATCH)
    monkeypatch.setattr(assignments, "__path__", [*assignments.__path__, str(tmp_path)])
    monkeypatch.setattr(assignments, "ASSIGNMENTS", assignments.discover())
    yield assignments.spec("scratch")
    sys.modules.pop("course_lib.checks.assignments.scratch", None)
    registry._REGISTRY.pop("scratch", None)


def test_an_assignment_is_its_file_alone(scratch, tmp_path):
    """A new assignment's file alone makes it an assignment: found last (its lesson), imported as a
    notebook imports it, its notebook built with its check's points, its row in the contracts'
    table, and its check run."""
    from course_lib.checks import check_process

    assert list(assignments.ASSIGNMENTS)[-1] == "scratch"
    from course_lib.checks import scratch as checks

    assert checks.SPEC is scratch and callable(checks.selfcheck)
    build = assignments_build()
    cells = build.assignment_notebook(scratch).cells
    graded = [cell for cell in cells if cell.metadata.get("nbgrader", {}).get("grade")]
    assert [cell.metadata["nbgrader"]["points"] for cell in graded] == [3.0]
    assert "from course_lib.checks import scratch as checks" in cells[1].source
    assert "| `scratch` | 99 | 3 | none | `sums` 3 |" in build.contract_table(assignments.ASSIGNMENTS)
    result = check_process.run_in_this_process("scratch", "sums", 1, tmp_path, tmp_path)
    assert (result.points, result.max_points) == (3.0, 3.0)
