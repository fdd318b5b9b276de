"""The shell of JupyterLab's terminal in the course (``make lab`` and the course's hub start it).

A terminal runs the user's shell, which reads the user's start-up file. When that file puts
pyenv's or conda's ``bin/`` first on PATH (``eval "$(pyenv init -)"``, ``conda activate``), their
``python`` hides the course's: ``python -m course_lib build`` then says "No module named
course_lib". So bash starts with the course's rc file (:data:`BASHRC`), which reads the usual
start-up files and then the environment's ``local_setup.bash`` (course_lib.ros.underlay): the course's
``bin/`` first again, and the variables colcon needs. Other shells start as they are.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

#: bash's rc file in the course's terminal (bash --rcfile).
BASHRC = Path(__file__).resolve().parent / "bashrc"


def shell_command(shell: str | None = None) -> list[str]:
    """The command line of a terminal's shell: `shell` (default $SHELL, else /bin/bash), for bash
    with the course's rc file."""
    shell = shell or os.environ.get("SHELL") or "/bin/bash"
    return [shell, "--rcfile", str(BASHRC)] if Path(shell).name == "bash" else [shell]


def main(argv: list[str] | None = None) -> int:
    """``python -m course_lib.notebook.student_lab.terminal``: print the server's terminado settings (JSON)."""
    if argv if argv is not None else sys.argv[1:]:
        print("python -m course_lib.notebook.student_lab.terminal takes no arguments", file=sys.stderr)
        return 2
    print(json.dumps({"shell_command": shell_command()}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
