"""course_lib.launch's substitutions without processes: the ``$(...)`` grammar, what each
substitution performs to, and the errors, against launch's own expectations."""

from pathlib import Path

import pytest

from course_lib.launch import substitutions
from course_lib.launch.entities import LaunchFileError


class FakeContext:
    configurations = {"robot": "r1"}
    environment = {"HOME": "/home/student"}
    current_file = Path("/ws/launch/demo.launch.xml")


@pytest.mark.parametrize("text, expected", [
    ("plain 'quotes' stay", "plain 'quotes' stay"),
    ("$0 $ (not substitutions)", "$0 $ (not substitutions)"),
    ("ns_$(var robot)_$(env HOME)", "ns_r1_/home/student"),
    ("$(var nothing 'a default')", "a default"),
    ("$(env NOTHING '')", ""),
    ("$(env NOTHING $(var robot))", "r1"),
    ("$(var robot $(var missing))", "r1"),  # a default is only performed when needed
    ('$(var "$(var robot)_missing" "x $(var robot)")', "x r1"),
    (r"\$(var robot) is text", "$(var robot) is text"),
    (r"$(var a\(b\) c\))", "c)"),
    ("$(dirname)/x.yaml $(filename)", "/ws/launch/x.yaml /ws/launch/demo.launch.xml"),
])
def test_substitutions_follow_the_launch_grammar(text, expected):
    assert substitutions.perform(substitutions.parse(text), FakeContext()) == expected


def test_find_pkg_share_and_prefix_use_the_ament_index(demo_prefix):
    parts = substitutions.parse("$(find-pkg-share demo) $(find-pkg-prefix demo)")
    assert substitutions.perform(parts, FakeContext()) == f"{demo_prefix}/share/demo {demo_prefix}"
    with pytest.raises(LaunchFileError, match="Package 'nope' not found"):
        substitutions.perform(substitutions.parse("$(find-pkg-share nope)"), FakeContext())


@pytest.mark.parametrize("text, message", [
    ("$(var missing)", "launch configuration 'missing' does not exist"),
    ("$(env COURSE_NOT_SET)",
     r"environment variable 'COURSE_NOT_SET' does not exist.*\$\(env COURSE_NOT_SET DEFAULT\)"),
])
def test_missing_values_are_errors_that_name_them(text, message):
    with pytest.raises(LaunchFileError, match=message):
        substitutions.perform(substitutions.parse(text), FakeContext())


@pytest.mark.parametrize("text, message", [
    ('$(eval "1 + 1")', r"\$\(eval\) is not supported here \(a full ROS 2 install has it\); supported: \$\(var"),
    ("$(command ls)", r"\$\(command\) is not supported here"),
    ("$(evn HOME)", r"\$\(evn\) is not a launch substitution \(did you mean 'env'\?\)"),
    ("$(var)", r"\$\(var\) takes 1 or 2 arguments, got 0"),
    ("$(dirname x)", r"\$\(dirname\) takes 0 arguments, got 1"),
    ("$(var a", r"is not closed with '\)'"),
    ("$(var  a)", "expected an argument"),
    ("$(var 'a)", "the quote ' is not closed"),
])
def test_malformed_or_unsupported_substitutions_are_refused(text, message):
    with pytest.raises(LaunchFileError, match=message):
        substitutions.parse(text, "f.launch.xml", 3)


def test_describe_prints_defaults_like_show_args():
    parts = substitutions.parse("$(find-pkg-share demo)/x_$(var robot)")
    assert substitutions.describe(parts) == "FindPackageShare(pkg='demo') + '/x_' + LaunchConfig('robot')"
