"""Right answers to the lessons' exercises, as files, and the files the lessons' %%writefile cells
write: for the tests of the self-checks and of the lessons' commands.

These answers exist here only: a lesson hands out the exercise's stub, and course_lib, which students
have, holds no solution. What the lessons write themselves is read from the notebooks, not copied."""

import json
from pathlib import Path

from course_lib import contract

HERE = Path(__file__).parent
NOTEBOOKS = contract.ROOT / "notebooks"


def lesson_files(notebook: str) -> dict[str, str]:
    """{path: text} of the lesson's %%writefile cells."""
    files = {}
    for cell in json.loads((NOTEBOOKS / notebook).read_text())["cells"]:
        first, _, body = "".join(cell["source"]).partition("\n")
        if cell["cell_type"] == "code" and first.startswith("%%writefile"):
            files[first.split(maxsplit=1)[1]] = body
    return files


def lesson_file(notebook: str, relative: str) -> str:
    """The text a lesson's %%writefile cell writes to a path ending in `relative`."""
    found = [text for path, text in lesson_files(notebook).items() if path.endswith(relative)]
    if not found:
        raise LookupError(f"{notebook} writes no {relative}")
    return found[0]

#: The line of lesson 02's setup.py stub that the student replaces with the executable's entry.
BRIGHTNESS_SETUP_TODO = ("            # TODO: the executable brightness_node, which runs main() of "
                         "brightness/brightness_node.py\n")


def brightness_node() -> str:
    """Lesson 02's node file, done (brightness/brightness_node.py)."""
    return (HERE / "brightness_node.py").read_text()


def brightness_setup(stub: str, entry: str = "brightness_node = brightness.brightness_node:main") -> str:
    """Lesson 02's setup.py stub with `entry` in place of its TODO."""
    if BRIGHTNESS_SETUP_TODO not in stub:
        raise ValueError("lesson 02's setup.py no longer has the TODO line lesson_answers expects: update "
                         "BRIGHTNESS_SETUP_TODO")
    return stub.replace(BRIGHTNESS_SETUP_TODO, f"            {entry!r},\n")
