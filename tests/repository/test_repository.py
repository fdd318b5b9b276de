"""Repository hygiene: notebooks are committed clean, build products are never committed, the
documents' links lead somewhere, and the course's packages import each other without cycles."""

import ast
import functools
import json
import re
import subprocess
from pathlib import Path

import pytest

from course_lib import contract

ROOT = contract.ROOT


@functools.cache
def syntax(path: Path) -> ast.Module:
    """The parsed file (parsed once for all the tests here)."""
    return ast.parse(path.read_text())


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


def test_what_make_lab_and_the_lessons_write_into_the_clone_is_ignored():
    """Under `make lab` the lab's root is the clone: Fetch puts each assignment in <assignment>/ there
    (a student's solutions, which a `git add -A` must not take), and the lessons write their
    workspaces, snapshots and lesson 05's bag beside the notebooks (the walkthrough found
    notebooks/camera_bag/, left by cells run again after the clean-up, and the fetched folders
    untracked but not ignored)."""
    from course_lib.checks import assignments

    written = [f"{name}/{name}.ipynb" for name in assignments.discover()]
    written += ["notebooks/camera_bag/metadata.yaml", "notebooks/camera_ws/src/x", "notebooks/snapshots/x.png"]
    out = subprocess.run(["git", "check-ignore", "--no-index", "--verbose", "--non-matching", *written], cwd=ROOT,
                         capture_output=True, text=True)
    if out.returncode not in (0, 1):
        pytest.skip("not a git checkout: " + out.stderr.strip())
    not_ignored = [line.split("\t")[-1] for line in out.stdout.splitlines() if line.startswith("::")]
    assert not not_ignored, f"add these to .gitignore: {not_ignored}"


def test_ci_runs_the_readme_test_command():
    assert "make test" in (ROOT / ".ci" / "run").read_text()
    assert "make test" in (ROOT / "README.md").read_text()


def heading_anchors(markdown: str) -> set[str]:
    """The anchors GitHub gives a document's headings: lower case, punctuation dropped, spaces as -."""
    text = re.sub(r"```.*?```", "", markdown, flags=re.S)
    return {re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
            for heading in re.findall(r"^#{1,6} (.+)$", text, re.M)}


def test_links_of_the_readme_and_the_guides_lead_to_a_file_and_heading():
    """Every relative link of README.md, docs/ and the folders' READMEs names a file that exists and,
    with #anchor, a heading of it (the README was split into the guides by reader)."""
    documents = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "assignments" / "README.md",
                 ROOT / "deploy" / "README.md"]
    broken = []
    for document in documents:
        for target in re.findall(r"\]\(([^)\s]+)\)", document.read_text()):
            if re.match(r"[a-z]+:", target):
                continue  # https:, mailto:
            path, _, anchor = target.partition("#")
            linked = (document.parent / path).resolve() if path else document
            if not linked.exists() or (anchor and linked.is_file()
                                       and anchor not in heading_anchors(linked.read_text())):
                broken.append(f"{document.relative_to(ROOT)}: {target}")
    assert not broken, broken


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
        for node in ast.walk(syntax(path)):
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
    assert {"course_lib.ros.graph_info", "course_lib.ros.node_names"} <= graph["course_lib.ros.graph"]
    assert "course_lib.supervision.bounded_log" in graph["course_lib.supervision.supervisor"]
    assert import_cycle(graph) is None, " -> ".join(import_cycle(graph))


def package_imports(graph: dict[str, set[str]], package: str = "course_lib") -> dict[str, set[str]]:
    """The module graph folded to `package`'s parts: each subpackage one node (course_lib.ros), each
    module at its top one node (course_lib.contract)."""
    def part(module):
        return ".".join(module.split(".")[:2])
    folded = {}
    for module, imported in graph.items():
        if module.startswith(f"{package}."):
            folded.setdefault(part(module), set()).update(
                part(other) for other in imported if other.startswith(f"{package}.") and part(other) != part(module))
    return folded


def test_course_lib_packages_depend_on_each_other_in_one_direction():
    """Its parts by job (ros, supervision, imaging, notebook, checks, ...) import each other without
    a cycle: supervision needs no ROS, ros shows no notebook UI; what every part uses (contract,
    waiting, progress) sits at the top and imports none of them."""
    folded = package_imports(module_imports())
    assert {"course_lib.ros", "course_lib.supervision", "course_lib.notebook"} <= set(folded)
    assert "course_lib.supervision" in folded["course_lib.ros"]
    assert import_cycle(folded) is None, " -> ".join(import_cycle(folded))
    for shared in ("course_lib.contract", "course_lib.waiting", "course_lib.progress"):
        assert folded[shared] <= {"course_lib.contract"}, (shared, folded[shared])


def autograder_index() -> list[str]:
    """The files autograder/__init__.py's index names (``- ``term/grade.py``: ...``), in its order."""
    import autograder

    return re.findall(r"^- ``([\w/<>]+\.py)``:", autograder.__doc__, re.M)


def test_the_autograder_index_names_each_module_once():
    """autograder/__init__.py's index has one line for every module of the grader and none for a module
    that does not exist; ``answers/<assignment>.py`` stands for the answer keys."""
    named = autograder_index()
    assert "term/grade.py" in named and "config.py" in named
    assert len(named) == len(set(named)), [name for name in named if named.count(name) > 1]
    files = set()
    for path in (ROOT / "autograder").rglob("*.py"):
        name = path.relative_to(ROOT / "autograder").as_posix()
        if path.name != "__init__.py":
            files.add("answers/<assignment>.py" if name.startswith("answers/") else name)
    assert sorted(files - set(named)) == [], "name these modules in autograder/__init__.py's index"
    assert sorted(set(named) - files) == [], "autograder/__init__.py's index names modules that do not exist"


def test_autograder_groups_import_only_what_the_index_lists_above_them():
    """The grader's groups by job (sandbox/, results/, builds/, grading/, term/, ...) and its top modules
    import each other in one direction, the order of autograder/__init__.py's index: the sandbox needs
    no result, a submission's grading runs no term command."""
    def part(name):
        return "autograder." + name.split("/")[0].removesuffix(".py")
    order = list(dict.fromkeys(part(name) for name in autograder_index()))
    assert order.index("autograder.sandbox") < order.index("autograder.grading") < order.index("autograder.term")
    folded = package_imports(module_imports(), "autograder")
    assert "autograder.sandbox" in folded["autograder.grading"]
    assert set(folded) <= set(order), f"name these in autograder/__init__.py's index: {set(folded) - set(order)}"
    upward = {group: above for group, imported in folded.items()
              if (above := sorted(other for other in imported if order.index(other) > order.index(group)))}
    assert not upward, f"these import what the index lists below them: {upward}"


# --- each file does one job ----------------------------------------------------------------------

def course_sources():
    roots = (*PACKAGES, "tests", "benchmarks")
    return [path for path in tracked("*.py") if path.relative_to(ROOT).parts[0] in roots and path.exists()]


def opens_with_a_docstring(text: str) -> bool:
    """Whether the first statement is a string (after blank and comment lines), without parsing."""
    lines = (line.strip() for line in text.splitlines())
    first = next((line for line in lines if line and not line.startswith("#")), "")
    return first.lstrip("rRuU").startswith(('"""', "'''", '"', "'"))


def test_each_source_file_opens_with_a_docstring():
    """A file's first lines say its job, so that a reader finds the file of a job."""
    assert not opens_with_a_docstring("import os\n") and opens_with_a_docstring('#!/bin/python\n"""Job."""\n')
    silent = [str(path.relative_to(ROOT)) for path in course_sources()
              if not opens_with_a_docstring(path.read_text())]
    assert not silent, f"say in a docstring at the top what each of these files does: {silent}"


def test_no_source_file_is_over_500_lines():
    """Past 500 lines a file does several jobs: split it by job (not in halves)."""
    long = {str(path.relative_to(ROOT)): lines for path in course_sources()
            if (lines := len(path.read_text().splitlines())) > 500}
    assert not long, f"split these files by job: {long}"


# --- short names are for notebooks ----------------------------------------------------------------

def test_the_course_imports_modules_by_their_place_not_their_short_name():
    """``from course_lib import session`` is the notebooks' and students' way (course_lib.SHORT_NAMES);
    the course's own code names the module's place (``from course_lib.ros import session``), so
    that the import graph above is the real one."""
    import course_lib

    moved = {name for name, place in course_lib.SHORT_NAMES.items() if place != name}
    candidate = re.compile(rf"from course_lib import ([^\n]*\b({'|'.join(moved)})\b|\()")
    found = []
    # The reference solutions (assignments/reference_ws) are what a student writes: short names.
    for path in course_sources() + [p for p in tracked("assignments/*.py") if "reference_ws" not in p.parts]:
        if not candidate.search(path.read_text()):
            continue  # parsing every file would cost a second
        for node in ast.walk(syntax(path)):
            if isinstance(node, ast.ImportFrom) and node.module == "course_lib" and not node.level:
                found += [f"{path.relative_to(ROOT)}:{node.lineno} {alias.name}" for alias in node.names
                          if alias.name in moved]
    assert not found, f"import these from their subpackage (course_lib.SHORT_NAMES says which): {found}"


def test_every_short_name_is_a_module_of_course_lib():
    """Each short name leads to a module (found, not imported: importing them all costs seconds);
    ``vision`` is the drawing module, not a package of that name."""
    import importlib.util

    import course_lib

    missing = [name for name, place in course_lib.SHORT_NAMES.items()
               if importlib.util.find_spec(f"course_lib.{place}") is None]
    assert not missing, missing
    from course_lib.imaging import drawing  # course_lib.imaging is imported first, as in a lesson

    assert course_lib.vision is drawing


def test_every_course_lib_module_the_lessons_and_guides_name_exists():
    """A dotted name that a lesson, an assignment notebook or a guide runs (``python -m
    course_lib.x``, ``"course_lib.x:main"`` for processes.python_node) is a module of course_lib:
    the move into subpackages left lesson 05's camera at a name that no longer imported."""
    import importlib.util

    pattern = re.compile(r"(?:python -m |[\"'])(course_lib(?:\.\w+)+)(?::\w+)?")
    texts = [*ROOT.glob("notebooks/*.ipynb"), *ROOT.glob("assignments/source/*/*.ipynb"), *ROOT.glob("docs/*.md"),
             ROOT / "README.md"]
    named = {(path.name, name) for path in texts for name in pattern.findall(path.read_text())}
    assert ("05_recording_and_replaying.ipynb", "course_lib.imaging.camera") in named
    missing = sorted((file, name) for file, name in named if importlib.util.find_spec(name) is None)
    assert not missing, f"no such module: {missing}"


# --- every fact once --------------------------------------------------------------------------------

#: The modules whose ``Path(__file__).resolve().parent.parent`` (``.parents[2]`` one folder deeper) is the folder
#: that holds *their* copy of autograder (under grading, the grader's private staged copy:
#: autograder.grading.staging), not the repository.
STAGED_ROOTS = {"autograder/config.py", "autograder/nbgrader_cli.py", "autograder/grading/outputs.py",
                "autograder/sandbox/namespaces.py"}


def test_every_fact_is_spelled_out_once():
    """An environment name of course_lib.contract, the hub directory and its variable, the workspace's
    folder, the source notebooks' folder and the repository's root are written in the one module that
    owns them (contract.py, coursehub/course.py) and imported everywhere else."""
    from course_lib import contract

    facts = {f'"{value}"': "course_lib/contract.py" for name, value in vars(contract).items() if name.endswith("_ENV")}
    facts.update({'"ros2_ws"': "course_lib/contract.py", '"assignments" / "source"': "course_lib/contract.py",
                  '"/srv/ros2cv-hub"': "coursehub/course.py", '"COURSEHUB_HUB_DIR"': "coursehub/course.py"})
    # autograder/sandbox/sandbox_entry.py runs with ``python -I -S`` and imports nothing of the course (contract.py
    # says so).
    allowed = {"autograder/sandbox/sandbox_entry.py": {f'"{contract.EXPOSE_ENV}"', f'"{contract.BLOCKED_ENV}"',
                                                       f'"{contract.STAGE_ENV}"'}}
    root = re.compile(r"Path\(__file__\)\.resolve\(\)\.(parent\.parent|parents\[[12]\])")
    again = []
    for path in course_sources() + [ROOT / "assignments" / "build.py"]:
        name = str(path.relative_to(ROOT))
        if name.startswith(("tests/", "benchmarks/")) or not path.exists():
            continue
        text = path.read_text().replace("'", '"')
        again += [f"{name}: {fact} (defined in {owner})" for fact, owner in facts.items()
                  if fact in text and owner != name and fact not in allowed.get(name, ())]
        if root.search(text) and name != "course_lib/contract.py" and name not in STAGED_ROOTS:
            again.append(f"{name}: the repository's root (contract.ROOT)")
    makefile = (ROOT / "Makefile").read_text()
    again += [f"Makefile: {fact}" for fact in ('/srv/ros2cv-hub', 'COURSEHUB_HUB_DIR') if fact in makefile]
    assert not again, f"import these from the module that defines them: {again}"
