"""``ros2 launch PKG FILE [name:=value ...]`` and ``ros2 launch PATH ...``: run a launch file.

Launch files are course_lib.launch's job; this command hands it everything after ``launch``.
"""

from __future__ import annotations


def main(argv: list[str]) -> int:
    from course_lib import launch

    return launch.main(list(argv))
