"""autograder/builds/workspace_build.py: how the grader builds a submission's workspace, and when it builds
an interface package again. colcon is replaced by a recording runner here (the real build runs in
tests/assignments/test_autograder.py and tests/assignments/test_reference_packages.py): these tests are about the cache,
the order and the reasons."""

from __future__ import annotations

from pathlib import Path

from autograder.builds import caches, workspace_build

MSG = "builtin_interfaces/Time stamp\nint32 data\n"


def write_interface(ws: Path, name: str = "tutorial_interfaces", msg: str = MSG) -> Path:
    folder = ws / "src" / name
    (folder / "msg").mkdir(parents=True)
    (folder / "msg" / "MsgTutorial.msg").write_text(msg)
    (folder / "CMakeLists.txt").write_text(
        "project(x)\nrosidl_generate_interfaces(${PROJECT_NAME} \"msg/MsgTutorial.msg\")\n")
    (folder / "package.xml").write_text(f"<package format=\"3\"><name>{name}</name>"
                                        "<depend>builtin_interfaces</depend></package>")
    return folder


def write_python_package(ws: Path, name: str = "pubsub", depends=("tutorial_interfaces",)) -> Path:
    folder = ws / "src" / name
    folder.mkdir(parents=True)
    tags = "".join(f"<depend>{d}</depend>" for d in depends)
    (folder / "package.xml").write_text(f"<package format=\"3\"><name>{name}</name>{tags}</package>")
    (folder / "setup.py").write_text("from setuptools import setup\nsetup()\n")
    return folder


class FakeColcon:
    """Records each colcon call; "builds" an install prefix with an empty setup.bash, or fails
    with the given output for the workspaces named in `fail`."""

    def __init__(self, fail: dict[str, str] | None = None):
        self.calls: list[tuple[Path, list[str]]] = []
        self.fail = fail or {}

    def __call__(self, command, cwd, env, wall_seconds):
        self.calls.append((Path(cwd), command[2:]))
        for marker, output in self.fail.items():
            if marker in str(cwd):
                return 1, output
        (Path(cwd) / "install").mkdir(exist_ok=True)
        (Path(cwd) / "install" / "setup.bash").write_text("")
        return 0, "Starting >>> x\nFinished <<< x [1s]\n"


def test_identical_interface_packages_are_built_once(tmp_path):
    """Two workspaces with byte-identical .msg packages: one interface build; each workspace's other
    packages are built with the interface package skipped (an underlay)."""
    cache = caches.InterfaceCache(tmp_path / "cache")
    colcon = FakeColcon()
    reports = []
    for student in ("alice", "bob"):
        ws = tmp_path / student / "ros2_ws"
        write_interface(ws)
        write_python_package(ws)
        scratch = tmp_path / student / "scratch"
        scratch.mkdir()
        reports.append(workspace_build.build_workspace(ws, cache, scratch, colcon))
    assert [r.ok for r in reports] == [True, True]
    assert reports[0].built_interfaces == ["tutorial_interfaces"] and reports[1].cached == ["tutorial_interfaces"]
    interface_builds = [cwd for cwd, _ in colcon.calls if "interfaces" in cwd.parts]
    assert len(interface_builds) == 1
    workspace_builds = [args for cwd, args in colcon.calls if cwd.name == "ros2_ws"]
    assert workspace_builds == [["--symlink-install", "--packages-ignore", "tutorial_interfaces"]] * 2


def test_a_build_that_is_not_kept_leaves_the_cache_alone(tmp_path):
    """store=False (a kernel of the same uid ran beside the build): the new interface package
    serves this workspace, from its scratch folder, and the cache stays empty."""
    cache = caches.InterfaceCache(tmp_path / "cache")
    ws = tmp_path / "ros2_ws"
    write_interface(ws)
    write_python_package(ws)
    report = workspace_build.build_workspace(ws, cache, tmp_path, FakeColcon(), store=False)
    assert report.ok and report.built_interfaces == ["tutorial_interfaces"]
    assert not cache.root.exists()


def test_a_changed_message_is_built_again(tmp_path):
    """One byte more in a .msg file is another cache key."""
    a, b = write_interface(tmp_path / "a"), write_interface(tmp_path / "b", msg=MSG + "int32 extra\n")
    same = write_interface(tmp_path / "c")
    assert caches.content_key(a) == caches.content_key(same) != caches.content_key(b)


def test_a_failed_interface_build_gives_its_first_error_lines_and_is_not_cached(tmp_path):
    """A CMake error: the reason quotes it from its first line, the workspace's other packages are
    not built, and an identical package later is built again (a failure may be the machine's)."""
    cache = caches.InterfaceCache(tmp_path / "cache")
    output = ("Starting >>> tutorial_interfaces\n-- Found ament_cmake\n"
              "CMake Error at CMakeLists.txt:2 (rosidl_generate_interfaces):\n  Unknown type 'float96'\n"
              "Failed   <<< tutorial_interfaces [2s, exited with code 1]\n")
    colcon = FakeColcon(fail={"interfaces": output})
    for student in ("alice", "bob"):
        ws = tmp_path / student / "ros2_ws"
        write_interface(ws)
        write_python_package(ws)
        (tmp_path / student / "scratch").mkdir()
        report = workspace_build.build_workspace(ws, cache, tmp_path / student / "scratch", colcon)
        assert not report.ok
        assert report.reason.startswith("colcon build failed in package 'tutorial_interfaces':\nCMake Error at")
        assert "Unknown type 'float96'" in report.reason
    assert len(colcon.calls) == 2 and not cache.root.exists()


def test_a_failed_python_package_names_the_package_and_the_error(tmp_path):
    """setup.py that does not run: the reason names the package and quotes the SyntaxError."""
    ws = tmp_path / "ros2_ws"
    write_python_package(ws, depends=())
    output = ("Starting >>> pubsub\n--- stderr: pubsub\n  File \"setup.py\", line 3\n"
              "SyntaxError: '(' was never closed\n---\nFailed   <<< pubsub [0.5s, exited with code 1]\n")
    colcon = FakeColcon(fail={"ros2_ws": output})
    report = workspace_build.build_workspace(ws, caches.InterfaceCache(tmp_path / "cache"), tmp_path, colcon)
    assert not report.ok
    assert "in package 'pubsub'" in report.reason and "SyntaxError: '(' was never closed" in report.reason


def test_no_workspace_says_which_cells_write_it(tmp_path):
    report = workspace_build.build_workspace(tmp_path / "ros2_ws", caches.InterfaceCache(tmp_path / "c"), tmp_path,
                                      FakeColcon())
    assert not report.ok and "%%writefile ros2_ws/src/" in report.reason


def test_interface_packages_are_ordered_by_their_dependencies(tmp_path):
    ws = tmp_path / "ws"
    write_interface(ws, "b_msgs")
    a = write_interface(ws, "a_msgs")
    (a / "package.xml").write_text("<package format=\"3\"><name>a_msgs</name><depend>b_msgs</depend></package>")
    found = workspace_build.source_packages(ws)
    assert workspace_build._in_dependency_order({n: found[n] for n in ("a_msgs", "b_msgs")}) == ["b_msgs", "a_msgs"]


def test_a_setup_py_that_does_not_run_is_quoted_from_its_exception_not_from_colcons_frames():
    """colcon reads setup.py in its own process: the traceback starts in colcon, the student's error ends it."""
    output = ("Starting >>> pubsub\n--- stderr: pubsub\nTraceback (most recent call last):\n"
              "  File \"/venv/colcon_core/executor/__init__.py\", line 91, in __call__\n    rc = await self.task()\n"
              "  File \"/venv/colcon_ros/task/ament_python/build.py\", line 51, in build\n    setup_py_data = get()\n"
              "  File \"/ws/src/pubsub/setup.py\", line 3\n    package_name = 'pubsub'(\n"
              "SyntaxError: '(' was never closed\n---\nFailed   <<< pubsub [0.5s, exited with code 1]\n")
    quoted = workspace_build.first_error_lines(output)
    assert quoted.endswith("SyntaxError: '(' was never closed") and "setup.py\", line 3" in quoted
    assert "executor" not in quoted
