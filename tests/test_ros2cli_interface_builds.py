"""A package of .msg, .srv and .action files built by the real colcon on the pip install, and
`ros2 interface show` of its service and action, held to ros2interface's test_cli.py (Jazzy): its
test package ros2cli_test_interfaces, written anew from the lines that test expects."""

import subprocess
import sys

import pytest
from ros2cli_support import ros2

from course_lib.ros import colcon, pkg_create, workspace

# Comments say at which nesting level they are, as in ros2cli_test_interfaces.
INTERFACES = {
    "ShortVaried": ("# A constant\n"
                    "bool BOOL_CONST=true # Comment - Nesting Level 1: 1 of 2\n\n"
                    "# Bool and array of bools\n"
                    "bool bool_value\n"
                    "bool[<=3] bool_values # Comment - Nesting Level 1: 2 of 2\n\n"
                    "# Trailing comment\n"),
    "ShortVariedNested": ("# A short, varied type\n"
                          "ShortVaried short_varied # Comment - Nesting Level 2: 1 of 1\n"
                          "# Trailing comment\n"),
    "ShortVariedMultiNested.srv": ("# Request\n"
                                   "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2\n"
                                   "---\n"
                                   "# Response\n"
                                   "bool bool_value # Comment - Nesting Level 3: 2 of 2\n"),
    "ShortVariedMultiNested.action": ("# Goal definition\n"
                                      "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2\n"
                                      "---\n"
                                      "# Result definition\n"
                                      "bool bool_value # Comment - Nesting Level 3: 2 of 2\n"
                                      "---\n"
                                      "# Feedback definition\n"
                                      "bool[3] bool_values\n"),
}
NESTED = ["ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2", "\tShortVaried short_varied",
          "\t\tbool BOOL_CONST=true", "\t\tbool bool_value", "\t\tbool[<=3] bool_values"]
NESTED_ALL_COMMENTS = [
    "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2", "\t# A short, varied type",
    "\tShortVaried short_varied # Comment - Nesting Level 2: 1 of 1", "\t\t# A constant",
    "\t\tbool BOOL_CONST=true # Comment - Nesting Level 1: 1 of 2", "", "\t\t# Bool and array of bools",
    "\t\tbool bool_value", "\t\tbool[<=3] bool_values # Comment - Nesting Level 1: 2 of 2", "",
    "\t\t# Trailing comment", "\t# Trailing comment"]
NESTED_NO_COMMENTS = ["ShortVariedNested short_varied_nested", *NESTED[1:]]
RESPONSE = "bool bool_value # Comment - Nesting Level 3: 2 of 2"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """ros2cli_test_interfaces built with colcon; the environment of its sourced install/setup.bash."""
    ws = tmp_path_factory.mktemp("interfaces_ws")
    pkg_create.create_interface_package(ws, "ros2cli_test_interfaces", INTERFACES, dependencies=())
    colcon.build(ws, timeout=600)
    return workspace.workspace_environment(ws)


@pytest.mark.slow
def test_services_and_actions_build_into_python_types(built):
    """rosidl generates Request/Response for a .srv and Goal/Result/Feedback for an .action."""
    code = ("from ros2cli_test_interfaces.srv import ShortVariedMultiNested as S\n"
            "from ros2cli_test_interfaces.action import ShortVariedMultiNested as A\n"
            "print(S.Request().short_varied_nested.short_varied.BOOL_CONST, S.Response().bool_value,"
            " list(A.Feedback().bool_values))\n")
    done = subprocess.run([sys.executable, "-c", code], env=built, capture_output=True, text=True, timeout=60)
    assert (done.returncode, done.stdout) == (0, "True False [False, False, False]\n"), done.stderr


@pytest.mark.slow
@pytest.mark.parametrize("options, lines", [
    # test_show_service, test_show_service_with_all_comments, test_show_service_with_no_comments
    ([], ["# Request", *NESTED, "---", "# Response", RESPONSE]),
    (["--all-comments"], ["# Request", *NESTED_ALL_COMMENTS, "---", "# Response", RESPONSE]),
    (["--no-comments"], [*NESTED_NO_COMMENTS, "---", "bool bool_value"]),
])
def test_show_service(built, options, lines):
    text = ros2("interface", "show", "ros2cli_test_interfaces/srv/ShortVariedMultiNested", *options, env=built).stdout
    assert text.splitlines() == lines


@pytest.mark.slow
@pytest.mark.parametrize("options, lines", [
    # test_show_action, test_show_action_with_all_comments, test_show_action_with_no_comments
    ([], ["# Goal definition", *NESTED, "---", "# Result definition", RESPONSE, "---", "# Feedback definition",
          "bool[3] bool_values"]),
    (["--all-comments"], ["# Goal definition", *NESTED_ALL_COMMENTS, "---", "# Result definition", RESPONSE, "---",
                          "# Feedback definition", "bool[3] bool_values"]),
    (["--no-comments"], [*NESTED_NO_COMMENTS, "---", "bool bool_value", "---", "bool[3] bool_values"]),
])
def test_show_action(built, options, lines):
    text = ros2("interface", "show", "ros2cli_test_interfaces/action/ShortVariedMultiNested", *options,
                env=built).stdout
    assert text.splitlines() == lines
