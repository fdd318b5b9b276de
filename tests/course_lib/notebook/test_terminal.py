"""Tests for course_lib.notebook.student_lab.terminal: the shell of JupyterLab's terminal in the course."""

from __future__ import annotations

import json
import subprocess
import sys

from course_lib import contract
from course_lib.notebook.student_lab import terminal

ROOT = contract.ROOT


def test_a_bashrc_that_puts_another_python_first_does_not_hide_the_course_python(tmp_path):
    """~/.bashrc puts pyenv's (here: a stand-in's) bin/ first, as `eval "$(pyenv init -)"` does: the
    course's terminal still runs the commands the lessons quote with the course's python."""
    other = tmp_path / ".pyenv" / "shims"
    other.mkdir(parents=True)
    (other / "python").write_text("#!/bin/sh\necho 'No module named course_lib' >&2\nexit 1\n")
    (other / "python").chmod(0o755)
    (tmp_path / ".bashrc").write_text(f'export PATH="{other}:$PATH"\nexport FROM_BASHRC=read\n')
    lab = subprocess.run(["sh", "-c", f'. "{sys.prefix}/local_setup.sh" && env'], env={"PATH": "/usr/bin:/bin"},
                         capture_output=True, text=True, timeout=30).stdout  # make lab's environment
    env = dict(line.split("=", 1) for line in lab.splitlines() if "=" in line)
    env["HOME"] = str(tmp_path)
    # terminado runs the command in a terminal, where bash is interactive; -i makes it so in a pipe
    done = subprocess.run(terminal.shell_command("/bin/bash") + ["-i"], env=env, capture_output=True, text=True,
                          input='echo "$FROM_BASHRC"; command -v python; python -m course_lib build --help\nexit\n',
                          timeout=60)
    lines = done.stdout.splitlines()
    assert lines[:2] == ["read", f"{sys.prefix}/bin/python"], done.stdout + done.stderr
    assert "usage: python -m course_lib build WS_DIR" in done.stdout, done.stdout + done.stderr


def test_bash_gets_the_course_rc_file_and_other_shells_start_as_they_are():
    assert terminal.shell_command("/bin/bash") == ["/bin/bash", "--rcfile", str(terminal.BASHRC)]
    assert terminal.shell_command("/usr/bin/zsh") == ["/usr/bin/zsh"]
    printed = subprocess.run([sys.executable, "-m", "course_lib.notebook.student_lab.terminal"], capture_output=True,
                             text=True, timeout=60, env={"SHELL": "/bin/bash", "PATH": "/usr/bin:/bin"})
    assert json.loads(printed.stdout) == {"shell_command": terminal.shell_command("/bin/bash")}


def test_make_lab_and_the_hub_give_terminals_the_course_shell_and_environment():
    commands = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True, timeout=60).stdout
    assert "-m course_lib.notebook.student_lab.terminal" in commands and f'. "{ROOT}/.venv/local_setup.sh"' in commands
    assert "terminal.shell_command(" in (ROOT / "coursehub" / "jupyterhub_config.py").read_text()
