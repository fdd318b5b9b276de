"""Repository hygiene: notebooks are committed clean, build products are never committed."""

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
