"""A package of .msg, .srv and .action files built by the real colcon on the pip install, and
`ros2 interface show` of its service and action, held to ros2interface's test_cli.py (Jazzy): its
test package's interfaces (ros2cli_test_interfaces), written anew from the lines that test
expects, are in tutorial_interfaces of the tutorial workspace (tests/support/tutorial_workspace.py),
built once per test run for this file and tests/course_lib/ros/test_workspace.py."""

import subprocess
import sys

import pytest
from support import tutorial_workspace
from support.ros2cli import ros2

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
    """The environment of the tutorial workspace's sourced install/setup.bash (built with colcon)."""
    return tutorial_workspace.built(tmp_path_factory)[1]


@pytest.mark.slow
def test_services_and_actions_build_into_python_types(built):
    """rosidl generates Request/Response for a .srv and Goal/Result/Feedback for an .action."""
    code = ("from tutorial_interfaces.srv import ShortVariedMultiNested as S\n"
            "from tutorial_interfaces.action import ShortVariedMultiNested as A\n"
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
    text = ros2("interface", "show", "tutorial_interfaces/srv/ShortVariedMultiNested", *options, env=built).stdout
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
    text = ros2("interface", "show", "tutorial_interfaces/action/ShortVariedMultiNested", *options,
                env=built).stdout
    assert text.splitlines() == lines
