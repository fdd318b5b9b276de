"""Repository hygiene: notebooks are committed clean, build products are never committed, and the
course's packages import each other without cycles."""

import ast
import json
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def tracked(*patterns):
    out = subprocess.run(["git", "ls-files", *patterns], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        pytest.skip("not a git checkout: " + out.stderr.strip())
    return [ROOT / line for line in out.stdout.splitlines()]


def test_committed_notebooks_have_no_outputs():
    dirty = []
    for path in tracked("*.ipynb"):
        if {"submitted", "autograded", "feedback"} & set(path.relative_to(ROOT).parts):
            continue
        cells = json.loads(path.read_text())["cells"]
        if any(c.get("outputs") or c.get("execution_count") for c in cells if c["cell_type"] == "code"):
            dirty.append(str(path.relative_to(ROOT)))
    assert not dirty, f"clear outputs before committing (jupyter nbconvert --clear-output --inplace): {dirty}"


def test_no_environment_or_colcon_output_is_committed():
    bad = [p for p in tracked() if {".venv", "build", "install", "log"} & set(p.relative_to(ROOT).parts[:-1])]
    assert not bad, bad


def test_ci_runs_the_readme_test_command():
    assert "make test" in (ROOT / ".ci" / "run").read_text()
    assert "make test" in (ROOT / "README.md").read_text()


# --- the course's packages depend on each other in one direction --------------------------------

PACKAGES = ("course_lib", "autograder", "coursehub")


def module_imports() -> dict[str, set[str]]:
    """{module: the course modules it imports}, at the top or inside a function alike; ``from
    course_lib import X`` is an import of course_lib.X when that is a module."""
    files = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            parts = path.relative_to(ROOT).with_suffix("").parts
            files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = {}
    for name, path in files.items():
        here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found |= {alias.name for alias in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(here[:len(here) - node.level + 1] + ([node.module] if node.module else []))
                found |= {f"{base}.{alias.name}" if f"{base}.{alias.name}" in files else base for alias in node.names}
        graph[name] = {module for module in found if module in files and module != name}
    return graph


def import_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the graph (its modules in order, the first again at the end), or None."""
    state, path = {}, []

    def visit(module):
        state[module] = "open"
        path.append(module)
        for imported in sorted(graph[module]):
            if state.get(imported) == "open":
                return path[path.index(imported):] + [imported]
            if imported not in state and (cycle := visit(imported)):
                return cycle
        state[module] = "done"
        path.pop()
        return None

    return next((cycle for module in sorted(graph) if module not in state and (cycle := visit(module))), None)


def test_the_finder_finds_a_cycle():
    assert import_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert import_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycles():
    """No module of course_lib, autograder or coursehub imports, through others, itself: each
    part can be read, tested and moved on its own (a parser registers with the actions instead)."""
    graph = module_imports()
    assert "course_lib.contract" in graph["course_lib.checks.answers"]
    assert import_cycle(graph) is None, " -> ".join(import_cycle(graph))
