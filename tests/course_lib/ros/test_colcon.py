"""Tests for course_lib.ros.colcon: the real colcon build, its errors and its command line.

The builds of a working workspace are tested in tests/course_lib/ros/test_workspace.py, which builds one once
per test run for all its tests.
"""

import subprocess
import sys

import pytest

from course_lib.ros import colcon, pkg_create, rosenv


def test_build_without_src_names_the_fix(tmp_path):
    with pytest.raises(FileNotFoundError, match="create_package"):
        colcon.build(tmp_path)


@pytest.mark.slow
def test_a_cmake_error_is_the_last_thing_a_build_error_says(tmp_path):
    package = pkg_create.create_interface_package(tmp_path, "broken_interfaces", {"Broken": "int32 data"})
    cmake = package / "CMakeLists.txt"
    # Early in the file, so that CMake fails within seconds instead of after generating code.
    cmake.write_text(cmake.read_text().replace("find_package(ament_cmake REQUIRED)",
                                               "find_package(ament_cmake REQUIRED)\nthis_command_does_not_exist()"))
    with pytest.raises(colcon.BuildError) as caught:
        colcon.build(tmp_path, timeout=300)
    message = str(caught.value)
    log = caught.value.result.log_path("broken_interfaces")
    assert message.splitlines()[0].endswith(f"failed in package 'broken_interfaces' (exit code 1); its full log: {log}")
    # CMake's first error, from the package's log, ends the message (not colcon's summary after it).
    cause = message[message.index("The first error in it:\n"):].splitlines()[1:]
    assert cause[0].startswith("CMake Error at CMakeLists.txt:") and "this_command_does_not_exist" in cause[0], message
    assert not any(line.startswith(("Failed", "Summary")) for line in cause), message
    assert caught.value.result.failed == ["broken_interfaces"] and caught.value.result.returncode != 0


@pytest.mark.slow
def test_command_line_build_failure_ends_with_python_s_error_line(tmp_path):
    """A notebook's build cell (`!course-lib build ...`) shows colcon's package lines, then the cause
    last: Python's error in setup.py with its file and line, not colcon's traceback or the ten-line
    `python -c` command colcon ran."""
    package = pkg_create.create_package(tmp_path, "bad_python_pkg")
    setup = package / "setup.py"
    setup.write_text(setup.read_text() + "this is not python(\n")
    done = subprocess.run([sys.executable, "-m", "course_lib", "build", str(tmp_path)], stderr=subprocess.STDOUT,
                          stdout=subprocess.PIPE, text=True, timeout=300, env=rosenv.ros_environment())
    assert done.returncode == 1
    shown = done.stdout.rstrip().splitlines()
    assert shown[0] == "Starting >>> bad_python_pkg" and shown[-1] == "SyntaxError: '(' was never closed", done.stdout
    log = colcon.package_log_path(tmp_path, "bad_python_pkg")
    assert f'File "{setup}", line' in done.stdout and str(log) in done.stdout
    assert "Traceback" not in done.stdout and "python -c" not in done.stdout and "'-c'" not in done.stdout, done.stdout
    assert "--- stderr" not in done.stdout, done.stdout


def test_quiet_echo_keeps_a_traceback_of_the_student_s_own_code():
    shown = []
    echo = colcon.QuietEcho(shown.append)
    for line in ["--- stderr: pkg", "Traceback (most recent call last):", '  File "/ws/src/pkg/pkg/node.py", line 3',
                 "    import nothing", "ModuleNotFoundError: No module named 'nothing'", "---",
                 "--- stderr: other", "Traceback (most recent call last):",
                 '  File "/venv/lib/colcon_core/executor/__init__.py", line 91, in __call__',
                 "subprocess.CalledProcessError: Command '['python', '-c', 'x']' returned non-zero exit status 1.",
                 "---", "Command '['python', '-c', 'x']' returned non-zero exit status 1."]:
        echo(line)
    assert shown == ["--- stderr: pkg", "Traceback (most recent call last):",
                     '  File "/ws/src/pkg/pkg/node.py", line 3', "    import nothing",
                     "ModuleNotFoundError: No module named 'nothing'", "---"]


@pytest.mark.slow
def test_a_setup_py_syntax_error_is_shown_with_its_file_and_line_and_kept_in_the_log_named(tmp_path):
    """colcon reads setup.py in a process of its own, whose error goes to the console only (with the
    file shown as "<string>"); its package log holds colcon's CalledProcessError. The build error
    shows what Python says about the file, as plain colcon in a shell shows it, and the log it
    names ends with the same."""
    package = pkg_create.create_package(tmp_path, "comma_pkg")
    setup = package / "setup.py"
    lines = setup.read_text().splitlines()
    number = next(i for i, line in enumerate(lines, start=1) if "version=" in line)
    lines[number - 1] = lines[number - 1].rstrip(",")
    setup.write_text("\n".join(lines) + "\n")
    with pytest.raises(colcon.BuildError) as caught:
        colcon.build(tmp_path, timeout=300)
    message = str(caught.value)
    said = f'File "{setup}", line {number}'
    assert said in message and "SyntaxError: invalid syntax. Perhaps you forgot a comma?" in message, message
    assert "CalledProcessError" not in message, message
    log = caught.value.result.log_path("comma_pkg")
    assert str(log) in message
    assert said in log.read_text() and "Perhaps you forgot a comma?" in log.read_text()


def test_package_dir_finds_a_package_by_its_name_as_colcon_does(tmp_path):
    pkg_create.create_package(tmp_path, "wanted")
    ignored = pkg_create.create_package(tmp_path, "ignored")
    (ignored / "COLCON_IGNORE").touch()
    assert colcon.package_dir(tmp_path, "wanted") == tmp_path / "src" / "wanted"
    assert colcon.package_dir(tmp_path, "ignored") is None and colcon.package_dir(tmp_path, "nowhere") is None


def test_build_errors_name_a_missing_cmake_package_and_its_wheel():
    log = ('Could not find a package configuration file provided by "rosidl_core_generators" with any')
    assert "pip install ros-jazzy-rosidl-core-generators==0.2.0" in colcon._hint(log)
