"""Right answers to the lessons' exercises, as files: for the tests of the self-checks and of the lessons' commands."""

from pathlib import Path

HERE = Path(__file__).parent

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
