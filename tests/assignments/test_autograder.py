"""The autograder's checks: declared right, stubs that fail with a hint, typical mistakes named
(the whole pipeline, nbgrader to the feedback page: tests/assignments/test_autograder_pipeline.py)."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
from support.from_source import assignments_build

from autograder.builds import reference, workspace_build
from autograder.sandbox import namespaces
from course_lib import contract
from course_lib.checks import (
    assignments,
    registry,
    runner,
    validate,
)

ASSIGNMENTS = list(assignments.ASSIGNMENTS)
REPO = contract.ROOT


@pytest.mark.parametrize("assignment", ASSIGNMENTS)
def test_every_check_has_points_timeout_and_description(assignment):
    """Each check declares positive points, a timeout and a one-line description."""
    checks = registry.checks_of(assignment)
    assert checks
    for spec in checks.values():
        assert spec.points > 0 and spec.timeout > 0 and spec.description and "\n" not in spec.description


@pytest.mark.parametrize("assignment", ASSIGNMENTS)
def test_test_cells_match_the_checks(assignment):
    """Each source notebook has one graded cell per check, with the check's points, a visible
    self-check and a hidden graded run; and it is committed without outputs."""
    nb = nbformat.read(REPO / "assignments" / "source" / assignment / f"{assignment}.ipynb", as_version=4)
    graded = {c.metadata["nbgrader"]["grade_id"]: c for c in nb.cells
              if c.metadata.get("nbgrader", {}).get("grade") and not c.metadata["nbgrader"].get("solution")}
    checks = registry.checks_of(assignment)
    assert set(graded) == {f"check_{name}" for name in checks}
    for name, spec in checks.items():
        cell = graded[f"check_{name}"]
        assert cell.metadata["nbgrader"]["points"] == spec.points
        assert f"checks.selfcheck({name!r})" in cell.source
        assert "### BEGIN HIDDEN TESTS" in cell.source and f"checks.grade({name!r})" in cell.source
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code")


def test_build_script_reproduces_the_committed_notebooks(tmp_path, monkeypatch):
    """assignments/build.py writes exactly the committed source notebooks (no drift)."""
    build = assignments_build()

    monkeypatch.setattr(build, "SOURCE", tmp_path)
    for path in build.build():
        committed = REPO / "assignments" / "source" / path.relative_to(tmp_path)
        assert path.read_text() == committed.read_text(), path.name


def test_cell_timeouts_give_graded_cells_longer_and_grow_with_the_load_factor(monkeypatch):
    """Graded cells get the long timeout, every other cell the short one; both, and the kernel's
    start-up timeout, times the grader's load factor (as the notebook's wall time): a busy machine
    must not cut a cell that runs right (a clean-clone run at load 70 failed a submission whose
    kernel took longer than nbclient's fixed 60 s to start, and at load 40-60 one whose interrupted
    cell's last output came later than nbclient's fixed 4 s after its reply)."""
    from traitlets.config import Config

    graded = nbformat.v4.new_code_cell("x", metadata={"nbgrader": {"grade": True, "solution": False}})
    for factor in (1.0, 2.5):
        monkeypatch.setenv(contract.LOAD_FACTOR_ENV, str(factor))
        assert validate.cell_timeout(graded) == round(factor * validate.TEST_CELL_TIMEOUT)
        assert validate.cell_timeout(nbformat.v4.new_code_cell("x")) == round(factor * validate.CELL_TIMEOUT)
        c = Config()
        validate.apply_student(c)
        assert c.Execute.startup_timeout == round(factor * validate.STARTUP_TIMEOUT)
        assert c.Execute.iopub_timeout == round(factor * validate.IOPUB_TIMEOUT)


def test_sandbox_hides_directories_and_keeps_the_command():
    """As root the command runs under unshare with a network and mount namespace."""
    command = namespaces.sandbox_command(["python", "-V"], [Path("/somewhere/course")])
    assert command[-3:] == ["--", "python", "-V"]
    if namespaces.isolation() == "root":
        assert command[:3] == ["unshare", "--net", "--mount"] and "/somewhere/course" in command


def _module_dir(tmp_path: Path, assignment: str, edits=(), monkeypatch=None) -> Path:
    """The reference packages (with `edits`) in tmp_path/ros2_ws; with `monkeypatch`, also built as
    the grader builds them (interface packages from a cache), and the checks told so."""
    reference.write_reference_workspace(assignment, tmp_path, edits)
    if monkeypatch is not None:
        workspace_build.build_here(assignment, tmp_path)
        monkeypatch.setenv(contract.BUILD_REPORT_ENV, str(workspace_build.report_path(tmp_path)))
    return tmp_path


def _brightness_mistakes():
    from support.zoo import brightness as brightness_zoo

    return {k: v for k, v in brightness_zoo.entries("").items() if v.get("level") == "check"}


@pytest.mark.slow  # graded check runs and colcon builds
@pytest.mark.parametrize("student", sorted(_brightness_mistakes()))
def test_brightness_typical_mistake_gets_its_score_and_reason(tmp_path, monkeypatch, student):
    """Typical brightness mistakes, run through the checks directly: expected points and reason."""
    entry = _brightness_mistakes()[student]
    workdir = _module_dir(tmp_path, "brightness", entry["edits"], monkeypatch if entry["node"] is not None else None)
    texts, first_failures = [], []
    for check in ("values", "node"):
        if entry[check] is None:
            continue  # the entry is about the other check
        result = runner.execute("brightness", check, 11, workdir=workdir, mode="graded")
        texts.extend(result.verdict_lines())
        first_failures.extend([line for line in result.verdict_lines() if line.startswith("  ✘ ")][:1])
        expected = entry[check]
        if isinstance(expected, tuple):
            assert expected[0] - 1e-6 <= result.points <= expected[1] + 1e-6, result.verdict_lines()
        else:
            assert result.points == pytest.approx(expected), result.verdict_lines()
    text = "\n".join(texts)
    assert entry["reason"] in text
    if "first_failure" in entry:  # the first ✘ of a check's verdict names the cause
        assert any(entry["first_failure"] in line for line in first_failures), texts
    for phrase in entry.get("absent", ()):
        assert phrase not in text, texts


WARP = "crop = cv2.warpPerspective(frame, homography, (width, height), flags=cv2.INTER_LINEAR)"
CATDOG_MISTAKES = {
    "bgr_swapped": ([(WARP, WARP + "\n        crop = cv2.cvtColor(crop, cv2.COLOR_BGR2RGB)")],
                    "red and blue are swapped"),
    "mirrored": ([("target = marker_board.crop_corners((width, height))",
                   "target = np.float32([[width - 1, 0], [0, 0], [0, height - 1], [width - 1, height - 1]])")],
                 "mirrored left-right"),
    # Each marker's corner 0 instead of the corner that touches the picture.
    "corner_order": ([("corners = marker_board.picture_corners(markers, name)",
                       "corners = (np.float32([markers[m][0] for m in marker_board.PICTURES[name]])\n"
                       "                   if all(m in markers for m in marker_board.PICTURES[name]) else None)")],
                     "similarity"),
    "size_swapped": ([("(width, height), flags=cv2.INTER_LINEAR)", "(height, width), flags=cv2.INTER_LINEAR)")],
                     "size is (width, height)"),
}


#: The typical mistake of each assignment that goes through the whole pipeline (nbgrader, grader,
#: feedback page) in tests/assignments/test_autograder_pipeline.py (FULL_RUN_MISTAKES), which asserts there what
#: the tests below assert (the check loses points, its verdict names the mistake): it is not run
#: through the checks here a second time. pubsub's mistakes all run through the checks here: a
#: pubsub mistake handed in as a notebook goes through the whole pipeline in tests/autograder/test_term.py
#: (bob's subscriber) and in the zoo (tests/support/zoo/pubsub.py).
FULL_RUN = {"catdog_warp": "mirrored"}
#: The check a catdog_warp mistake above costs points in.
CATDOG_CHECK = "easy"


@pytest.mark.slow  # graded check runs and colcon builds
@pytest.mark.parametrize("mistake", sorted(set(CATDOG_MISTAKES) - {FULL_RUN["catdog_warp"]}))
def test_catdog_typical_mistake_loses_points_with_its_reason(tmp_path, mistake):
    """Typical warp mistakes score below full on easy scenes, and the verdict names the mistake."""
    edits, reason = CATDOG_MISTAKES[mistake]
    result = runner.execute("catdog_warp", CATDOG_CHECK, 3, workdir=_module_dir(tmp_path, "catdog_warp", edits),
                            mode="graded")
    assert result.points < result.max_points
    assert reason in "\n".join(result.verdict_lines())


@pytest.mark.slow  # graded check runs and colcon builds
def test_catdog_picture_reported_from_its_first_marker_loses_points_in_every_grading(tmp_path):
    """Each of a picture's four markers is hidden in turn in every grading, not left to a random
    draw: a crop_pictures that reports a picture whenever its first marker is seen always loses."""
    edits = [("corners = marker_board.picture_corners(markers, name)",
              "first = marker_board.PICTURES[name][0]\n"
              "        corners = marker_board.picture_corners({m: markers.get(m, markers.get(first)) "
              "for m in marker_board.PICTURES[name]}\n"
              "                                         if first in markers else markers, name)"),
             ("if corners is None or not _is_picture_shape(corners):", "if corners is None:")]
    workdir = _module_dir(tmp_path, "catdog_warp", edits)
    for seed in (3, 4):
        result = runner.execute("catdog_warp", "missing_and_none", seed, workdir=workdir, mode="graded")
        assert result.points < result.max_points, result.verdict_lines()
        failed = [item["message"] for item in result.items if not item["ok"]]
        assert len(failed) == 6 and all("although markers" in m for m in failed), result.verdict_lines()


# That the reference crop_pictures gets every point (the checks can be passed), on easy scenes and
# all the others: tests/assignments/test_autograder_pipeline.py::test_reference_solutions_get_full_marks[catdog_warp].


PUBSUB_MISTAKES = {
    # mistake: (edits of the reference packages, the check it costs, a phrase of the verdict)
    "wrong_topic": ([("TOPIC = 'ros_tutorial_msg'", "TOPIC = 'ros_tutorial'")], "publisher",
                    "nothing arrived on /ros_tutorial_msg"),
    "queue_depth_10": ([("QUEUE_DEPTH = 100", "QUEUE_DEPTH = 10")], "publisher", "queue depth of 100"),
    "best_effort": ([("self.create_publisher(MsgTutorial, TOPIC, QUEUE_DEPTH)",
                      "self.create_publisher(MsgTutorial, TOPIC, rclpy.qos.qos_profile_sensor_data)")], "publisher",
                    "publisher queue depth 5"),
    # The rate is measured from the stamps of a 1 s timer: 0.99 or 1.01 on a busy machine.
    "one_hertz": ([("create_timer(0.1,", "create_timer(1.0,")], "publisher",
                  re.compile(r"rate (0\.9[5-9]|1\.0[0-5]) Hz from the stamps of 3")),
    "counter_stuck": ([("        self.count += 1\n", "")], "publisher", "add one per message"),
    # Package-level mistakes (a missing <depend>, a wrong entry point, a build error) go through the
    # whole pipeline in the zoo (tests/support/zoo/pubsub.py), with these phrases; a wrong message field is
    # judged from the .msg file in tests/course_lib/checks/test_check_packages.py.
}


@pytest.mark.slow  # graded check runs and colcon builds
@pytest.mark.parametrize("mistake", sorted(PUBSUB_MISTAKES))
def test_pubsub_typical_mistake_loses_points_with_its_reason(tmp_path, monkeypatch, mistake):
    """Typical publisher/subscriber mistakes score below full, and the verdict names the mistake."""
    edits, check, reason = PUBSUB_MISTAKES[mistake]
    result = runner.execute("pubsub", check, 5, workdir=_module_dir(tmp_path, "pubsub", edits, monkeypatch),
                             mode="graded")
    assert result.points < result.max_points, result.verdict_lines()
    verdict = "\n".join(result.verdict_lines())
    assert reason.search(verdict) if isinstance(reason, re.Pattern) else reason in verdict, verdict
