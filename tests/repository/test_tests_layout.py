"""The tests mirror the packages they test: each test file in the folder of its package (none directly
in tests/), no two of one name, the helpers in one support package that pyproject's pythonpath finds,
and no test that edits the import path."""

import ast
import collections
import pathlib
import re

from course_lib import contract

ROOT = contract.ROOT
TESTS = ROOT / "tests"
#: tests/<folder>/ for what the packages' own folders do not hold: what spans them.
ACROSS_PACKAGES = {"assignments", "lessons", "browser", "repository"}
PACKAGES = {"course_lib", "autograder", "coursehub"}
#: The tests of course_lib's modules at its top (progress.py, waiting.py): tests/course_lib holds folders.
TOP_LEVEL = pathlib.PurePath("course_lib", "top_level")


def python_files():
    return sorted(path for path in TESTS.rglob("*.py") if "__pycache__" not in path.parts)


def test_files():
    return [path for path in python_files() if path.name.startswith("test_")]


def test_no_test_file_sits_directly_in_tests():
    assert test_files() and not sorted(path.name for path in TESTS.glob("test_*.py"))


def test_each_test_file_is_in_the_folder_of_the_package_it_tests():
    """tests/course_lib/ros/test_graph.py tests a module of course_lib/ros/: the folders under tests/
    are the packages' own folders, or one of the folders of what spans packages."""
    misplaced = []
    for path in test_files():
        folder = path.parent.relative_to(TESTS)
        top = folder.parts[0] if folder.parts else ""
        if top in PACKAGES:
            if not (ROOT / folder / "__init__.py").is_file() and folder != TOP_LEVEL:
                misplaced.append(str(path.relative_to(ROOT)))
        elif top not in ACROSS_PACKAGES or len(folder.parts) != 1:
            misplaced.append(str(path.relative_to(ROOT)))
    assert not misplaced, f"put these where the package they test is (or in {sorted(ACROSS_PACKAGES)}): {misplaced}"


def test_a_folder_of_test_files_holds_no_folder_that_would_import_as_a_package():
    """pytest puts a test file's folder on sys.path: a subfolder there imports as a package of its name
    (tests/course_lib/ros2cli would make ``import ros2cli`` succeed where ros2cli is not installed).
    Only a folder of data files (rviz_files/) may sit beside test files."""
    found = []
    for folder in sorted({path.parent for path in test_files()}):
        found += [str(sub.relative_to(ROOT)) for sub in folder.iterdir() if sub.is_dir()
                  and sub.name != "__pycache__" and not (sub.name.endswith("_files") and not any(sub.rglob("*.py")))]
    assert not found, f"a folder beside test files: {found}"


def test_no_two_test_files_share_a_name():
    """pytest imports each test file by its name (the default import mode): two of one name would clash."""
    names = collections.Counter(path.name for path in test_files())
    assert not [name for name, count in names.items() if count > 1]


def test_every_helper_lives_in_the_support_package():
    """Besides test files and conftest.py, every module under tests/ is in tests/support, the one
    package of tests/ (a package elsewhere under tests/ would shadow course_lib, autograder or coursehub)."""
    support = TESTS / "support"
    strays = [str(path.relative_to(ROOT)) for path in python_files()
              if not path.name.startswith("test_") and path.name != "conftest.py" and support not in path.parents]
    assert (support / "__init__.py").is_file() and not strays, f"move these into tests/support: {strays}"
    packages = [str(path.parent.relative_to(ROOT)) for path in TESTS.rglob("__init__.py")
                if path.parent != support and support not in path.parents]
    assert not packages, packages


def test_the_support_package_is_found_through_pyproject(pytestconfig):
    """pyproject.toml's pytest pythonpath puts tests/ on the path, so ``import support`` is tests/support."""
    import support

    assert TESTS in pytestconfig.getini("pythonpath")
    assert support.__file__ == str(TESTS / "support" / "__init__.py")


def test_no_test_edits_the_import_path():
    """Helpers come from the support package, not from folders added to sys.path by hand (which
    needed ``# noqa: E402`` on the imports after them)."""
    edit = re.compile(r"\bsys\.path(\.(insert|append|extend|remove)\(|\[[^\]]*\]\s*=(?!=)|\s*\+?=(?!=))")
    late_import = "noqa: " + "E402"
    found = [f"{path.relative_to(ROOT)}:{number}" for path in python_files() if path.name != "test_tests_layout.py"
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if edit.search(line) or late_import in line]
    assert not found, found
    assert edit.search("sys.path.insert(0, x)") and edit.search("sys.path[:0] = [x]")
    assert not edit.search("sys.path == before") and not edit.search("sys.path[0] == os.getcwd()")


def test_the_longest_files_named_in_conftest_exist():
    """The root conftest.py starts the longest test files first, named by their paths (a folder's
    files by the folder's path and "/")."""
    tree = ast.parse((ROOT / "conftest.py").read_text())
    longest = next(ast.literal_eval(node.value) for node in tree.body if isinstance(node, ast.Assign)
                   and any(getattr(target, "id", None) == "LONGEST_FIRST" for target in node.targets))
    assert longest and not [name for name in longest
                            if not ((ROOT / name).is_dir() if name.endswith("/") else (ROOT / name).is_file())]
