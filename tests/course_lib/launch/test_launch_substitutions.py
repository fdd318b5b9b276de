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
    ("$(command ls)", r"\$\(command\) is not supported here \(a full ROS 2 install has it\); supported: \$\(var"),
    ("$(evn HOME)", r"\$\(evn\) is not a launch substitution \(did you mean 'env'\?\)"),
    # launch's words (the parse methods of LaunchConfiguration, ThisLaunchFileDir, NotSubstitution,
    # PythonExpression, IfElseSubstitution), then how to write it
    ("$(var)",
     r"3: var substitution expects 1 or 2 arguments \(got 0 in '\$\(var\)'\): write \$\(var NAME \[DEFAULT\]\)$"),
    ("$(dirname x)", r"3: dirname substitution doesn't expect arguments \(got 1 in"),
    ("$(not a b)", r"3: not substitution expects 1 argument \(got 2 in"),
    ("$(eval)", r"3: eval substitution expects 1 or 2 arguments \(got 0 in"),
    ("$(if a)", r"3: if substitution expects 2 or 3 arguments \(got 1 in"),
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


# --- boolean, comparison, conditional and Python substitutions -----------------------------------

TRUTHS = {"true": True, "false": False, "1": True, "0": False}


def performed(text: str, configurations: dict | None = None) -> str:
    class Context(FakeContext):
        pass

    Context.configurations = dict(FakeContext.configurations, **(configurations or {}))
    return substitutions.perform(substitutions.parse(text, "f.launch.xml", 3), Context())


def test_boolean_substitutions_hold_launch_s_truth_tables():
    """launch/test/launch/substitutions/test_boolean_substitution.py: not, and, or, any, all read
    'true', 'false', '1' and '0', and perform to 'true' or 'false'."""
    for left, right in [(left, right) for left in TRUTHS for right in TRUTHS]:
        expected_and = "true" if TRUTHS[left] and TRUTHS[right] else "false"
        expected_or = "true" if TRUTHS[left] or TRUTHS[right] else "false"
        assert performed(f"$(and {left} {right})") == expected_and, (left, right)
        assert performed(f"$(or {left} {right})") == expected_or, (left, right)
        assert performed(f"$(all {left} {right} true)") == expected_and
        assert performed(f"$(any {left} false {right})") == expected_or
    assert [performed(f"$(not {value})") for value in TRUTHS] == ["false", "true", "false", "true"]
    assert performed("$(any)") == "false" and performed("$(all)") == "true"


@pytest.mark.parametrize("text", ["$(not not-condition-expression)", "$(and not-condition-expression true)",
                                  "$(and true not-condition-expression)", "$(or true not-condition-expression)",
                                  "$(all true not-condition-expression)", "$(any true not-condition-expression)"])
def test_a_value_that_is_no_boolean_fails_in_launch_s_words(text):
    """test_boolean_substitution.py wants SubstitutionFailure for 'not-condition-expression', on
    either side and even when the other side already decides; its text is coerce_to_type's."""
    with pytest.raises(LaunchFileError) as error:
        performed(text)
    assert error.value.message == "Cannot convert value 'not-condition-expression' to '<class 'bool'>'"
    assert (error.value.file, error.value.line) == ("f.launch.xml", 3)


@pytest.mark.parametrize("form", ["xml", "yaml"])
def test_boolean_substitutions_in_let_as_launch_xml_and_launch_yaml_test_them(tmp_path, form):
    """launch_xml's and launch_yaml's test_boolean_substitution.py: the same <let> values."""
    from support.launch_demo import write

    from course_lib.launch.actions import run_launch_file

    names = [("not_true", "$(not $(var true_value))"), ("not_false", "$(not $(var false_value))")] + [
        (f"{kind}_{a}_{b}", f"$({kind} $(var {a}_value) $(var {b}_value))")
        for kind in ("and", "or") for a in ("true", "false") for b in ("true", "false")]
    xml = "<launch>\n<let name='true_value' value='true'/>\n<let name='false_value' value='false'/>\n" + "".join(
        f"<let name='{name}' value='{value}'/>\n" for name, value in names) + "</launch>"
    yaml_text = ("launch:\n- let: {name: true_value, value: 'true'}\n- let: {name: false_value, value: 'false'}\n"
                 + "".join(f"- let: {{name: {name}, value: '{value}'}}\n" for name, value in names))
    configurations = run_launch_file(write(tmp_path, form, xml, yaml_text)).configurations
    assert {name: configurations[name] for name, _ in names} == {
        "not_true": "false", "not_false": "true",
        "and_true_true": "true", "and_true_false": "false", "and_false_true": "false", "and_false_false": "false",
        "or_true_true": "true", "or_true_false": "true", "or_false_true": "true", "or_false_false": "false"}


@pytest.mark.parametrize("left, right, expected", [
    # launch/test/launch/substitutions/test_equals_substitution.py, the cases a front end can write
    # (text on both sides); each also holds with the sides swapped.
    ("", "", "true"), ("", "something", "false"),
    ("true", "True", "true"), ("false", "False", "true"), ("true", "False", "false"),
    ("true", "1", "true"), ("true", "0", "false"), ("false", "0", "true"), ("true", "10", "false"),
    ("true", "-1", "false"), ("false", "10", "false"),
    ("1", "1", "true"), ("1", "0", "false"), ("1", "-1", "false"), ("10", "10", "true"), ("10", "-10", "false"),
    ("10", "10.0", "true"), ("10", "10.0000000001", "true"), ("10", "10.1", "false"), ("10.0", "-10.0", "false"),
    ("nan", "nan", "false"), ("inf", "inf", "true"), ("inf", "-inf", "false"), ("-inf", "-inf", "true"),
    ("wow", "wow", "true"), ("wow", "true", "false"), ("wow", "1", "false"), ("wow", "0", "false"),
])
def test_equals_compares_as_launch_does(left, right, expected):
    opposite = "false" if expected == "true" else "true"
    for first, second in ((left, right), (right, left)):
        values = {"left": first, "right": second}
        assert performed("$(equals $(var left) $(var right))", values) == expected
        assert performed("$(not-equals $(var left) $(var right))", values) == opposite


@pytest.mark.parametrize("text, expected", [
    # launch/test/launch/frontend/test_substitutions.py (test_eval_subst, test_eval_subst_of_math_expr,
    # test_eval_subst_multiple_modules[_alt_syntax]) and substitutions/test_python_expression.py
    (r"""$(eval "\'asd\' + \'bsd\'")""", "asdbsd"),
    ('$(eval "ceil(1.3)")', "2"),
    ('$(eval "ceil(1.3)" "math")', "2"),
    ('$(eval "math.ceil(1.3)" "math")', "2"),
    (r"""$(eval "math.isfinite(sys.getrefcount(str(\'hello world!\')))" "math, sys")""", "True"),
    (r"""$(eval "math.isfinite(sys.getrefcount(str(\'hello world!\')))" " math,sys ")""", "True"),
    (r"$(eval '\'$(var robot)\' == \'r1\'')", "True"),  # the text is performed first
    ("$(eval '2 * pi > 6')", "True"),
    ("$(if $(equals $(var robot) r1) left right)", "left"),
    ("$(if false left right)_$(if 0 only)", "right_"),
])
def test_eval_and_if_perform_as_launch_s_tests_expect(text, expected):
    assert performed(text) == expected


@pytest.mark.parametrize("text, message", [
    # test_python_expression.py / test_substitutions.py want NameError here; launch prints its text
    ('$(eval "ceil(1.3)" "")', "name 'ceil' is not defined"),
    ('$(eval "math.ceil(1.3)" "")', "name 'math' is not defined"),
    ("$(eval 'sys.getrefcount(str(1))')", "name 'sys' is not defined"),
    ("$(eval '1 +')", "invalid syntax (<string>, line 1)"),
    ("$(eval 1 no_such_module)", "No module named 'no_such_module'"),
    ("$(if maybe a b)", "Cannot convert value 'maybe' to '<class 'bool'>'"),
])
def test_eval_and_if_errors_are_launch_s_words(text, message):
    with pytest.raises(LaunchFileError) as error:
        performed(text)
    assert error.value.message == message


def test_eval_describes_itself_like_python_expression():
    """test_python_expression.py: describe() is PythonExpr('expression', ['math'])."""
    assert substitutions.describe(substitutions.parse("$(eval 'math.ceil(1.6)')")) == \
        "PythonExpr('math.ceil(1.6)', ['math'])"
    assert substitutions.describe(substitutions.parse("$(eval 'a + 1' 'sys')")) == "PythonExpr('a + 1', ['sys'])"
