"""Tests for course_lib.ros.pkg_create: the package layouts ros2 pkg create writes."""

import ast
import re
import xml.etree.ElementTree as ElementTree

import pytest

from course_lib.ros import pkg_create

#: The classic tutorial message (as in tests/course_lib/ros/test_workspace.py, which builds it).
MSG_TUTORIAL = "builtin_interfaces/Time stamp\nint32 data\n"


def test_create_package_lays_out_an_ament_python_package(tmp_path):
    package = pkg_create.create_package(tmp_path, "my_nodes", dependencies=["rclpy", "std_msgs"],
                                       node_name="talker")
    assert package == tmp_path / "src" / "my_nodes"
    for relative in ["package.xml", "setup.py", "setup.cfg", "resource/my_nodes", "my_nodes/__init__.py",
                     "my_nodes/talker.py", "test/test_copyright.py", "test/test_flake8.py",
                     "test/test_pep257.py"]:
        assert (package / relative).is_file(), relative
    assert (package / "resource/my_nodes").read_text() == ""

    root = ElementTree.parse(package / "package.xml").getroot()
    assert root.tag == "package" and root.get("format") == "3"
    assert root.findtext("name") == "my_nodes"
    assert [d.text for d in root.findall("depend")] == ["rclpy", "std_msgs"]
    assert [d.text for d in root.findall("test_depend")] == ["ament_copyright", "ament_flake8", "ament_pep257",
                                                             "python3-pytest"]
    assert root.findtext("export/build_type") == "ament_python"

    setup = ast.parse((package / "setup.py").read_text())
    call = next(node for node in ast.walk(setup) if isinstance(node, ast.Call)
                and getattr(node.func, "id", None) == "setup")
    keywords = {k.arg: k.value for k in call.keywords}
    entry_points = ast.literal_eval(keywords["entry_points"])
    assert entry_points == {"console_scripts": ["talker = my_nodes.talker:main"]}
    assert "resource/" in ast.unparse(keywords["data_files"]) and "package.xml" in ast.unparse(keywords["data_files"])

    cfg = (package / "setup.cfg").read_text()
    assert "[develop]\nscript_dir=$base/lib/my_nodes" in cfg and "[install]\ninstall_scripts=$base/lib/my_nodes" in cfg
    node = (package / "my_nodes/talker.py").read_text()
    compile(node, "talker.py", "exec")
    assert "Node started!" in node and "rclpy.try_shutdown()" in node and "with rclpy.init" not in node


def test_create_package_refuses_to_overwrite_but_can_rerun(tmp_path):
    package = pkg_create.create_package(tmp_path, "my_nodes", dependencies=["rclpy"], node_name="talker")
    (package / "my_nodes/talker.py").write_text("# my own work\n")
    with pytest.raises(FileExistsError, match="exist_ok=True"):
        pkg_create.create_package(tmp_path, "my_nodes")
    pkg_create.create_package(tmp_path, "my_nodes", dependencies=["rclpy", "std_msgs"], node_name="talker",
                             exist_ok=True)
    assert (package / "my_nodes/talker.py").read_text() == "# my own work\n"
    assert "<depend>std_msgs</depend>" in (package / "package.xml").read_text()


def test_write_python_package_puts_the_package_where_asked_with_ros2_pkg_creates_node(tmp_path):
    """Any folder, what is made listed in ros2pkg's order (its api/create.py), and the plain main
    of `ros2 pkg create`."""
    here = tmp_path / "here"
    written = pkg_create.write_python_package(here, "demo", dependencies=["rclpy"],
                                             node_name="hello", rclpy_node=False)
    assert [path.relative_to(here).as_posix() for path in written] == [
        ".", "package.xml", "demo", "setup.py", "setup.cfg", "resource", "resource/demo", "demo/__init__.py",
        "test", "test/test_copyright.py", "test/test_flake8.py", "test/test_pep257.py", "demo/hello.py"]
    written = written[1:]
    assert "print('Hi from demo.')" in written[-1].read_text()
    assert "<depend>rclpy</depend>" in written[0].read_text()


@pytest.mark.parametrize("name", ["MyNodes", "2nodes", "my-nodes", ""])
def test_invalid_package_names_are_refused_with_the_rule(tmp_path, name):
    with pytest.raises(ValueError, match="lower case"):
        pkg_create.create_package(tmp_path, name)


def test_only_ament_python_packages_are_created_by_create_package(tmp_path):
    with pytest.raises(ValueError, match="create_interface_package"):
        pkg_create.create_package(tmp_path, "my_nodes", build_type="ament_cmake")


def test_create_interface_package_declares_the_generators(tmp_path):
    package = pkg_create.create_interface_package(tmp_path, "tutorial_interfaces", {"MsgTutorial": MSG_TUTORIAL})
    assert (package / "msg/MsgTutorial.msg").read_text() == MSG_TUTORIAL
    cmake = (package / "CMakeLists.txt").read_text()
    assert "find_package(rosidl_default_generators REQUIRED)" in cmake
    assert "find_package(builtin_interfaces REQUIRED)" in cmake
    assert re.search(r'rosidl_generate_interfaces\(\$\{PROJECT_NAME\}\s+"msg/MsgTutorial.msg"\s+'
                     r"DEPENDENCIES builtin_interfaces\s*\)", cmake), cmake
    assert "ament_export_dependencies(rosidl_default_runtime)" in cmake
    root = ElementTree.parse(package / "package.xml").getroot()
    assert root.get("format") == "3"
    assert [d.text for d in root.findall("buildtool_depend")] == ["ament_cmake", "rosidl_default_generators"]
    assert [d.text for d in root.findall("exec_depend")] == ["rosidl_default_runtime"]
    assert [d.text for d in root.findall("depend")] == ["builtin_interfaces"]
    assert root.findtext("member_of_group") == "rosidl_interface_packages"
    assert root.findtext("export/build_type") == "ament_cmake"


def test_message_names_must_be_camel_case(tmp_path):
    with pytest.raises(ValueError, match="CamelCase"):
        pkg_create.create_interface_package(tmp_path, "my_interfaces", {"msg_tutorial": "int32 data"})


def test_create_interface_package_lists_services_and_actions_in_their_folders(tmp_path):
    """ROS 2's "Creating custom msg and srv files" and "Creating an action" tutorials: srv/X.srv and
    action/X.action in rosidl_generate_interfaces, and action_msgs as a dependency for actions."""
    package = pkg_create.create_interface_package(
        tmp_path, "tutorial_interfaces",
        {"Num": "int64 num", "AddThreeInts.srv": "int64 a\n---\nint64 sum",
         "Fibonacci.action": "int32 order\n---\nint32[] sequence\n---\nint32[] partial"})
    cmake = (package / "CMakeLists.txt").read_text()
    assert re.search(r'"msg/Num.msg"\s+"srv/AddThreeInts.srv"\s+"action/Fibonacci.action"\s+'
                     r"DEPENDENCIES builtin_interfaces action_msgs\s*\)", cmake), cmake
    assert (package / "srv" / "AddThreeInts.srv").read_text() == "int64 a\n---\nint64 sum\n"
    assert (package / "action" / "Fibonacci.action").is_file()
    assert "<depend>action_msgs</depend>" in (package / "package.xml").read_text()
