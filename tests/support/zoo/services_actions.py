"""Zoo submissions of the services_actions assignment: the reference, the release as it is, and
the typical mistakes of a service and an action server.

As in tests/support/zoo/pubsub.py, one submission carries several mistakes (each submission costs a
grading run): each entry has edits of the reference packages (see tests/support/zoo/__init__.py), the
expected points per check (a number or a (low, high) range) and phrases the feedback page must
show.
"""

from __future__ import annotations

from pathlib import Path

import nbformat


def _untouched(course_dir: str):
    """An edit that puts the released stubs back into every solution cell: the release as a
    student fetches it, handed in without a change."""
    def edit(nb):
        release = nbformat.read(Path(course_dir) / "release" / "services_actions" / "services_actions.ipynb",
                                as_version=4)
        stubs = {c.metadata["nbgrader"]["grade_id"]: c.source for c in release.cells
                 if c.metadata.get("nbgrader", {}).get("solution")}
        for cell in nb.cells:
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id")
            if grade_id in stubs:
                cell.source = stubs[grade_id]
    return edit


def entries(course_dir: str) -> dict[str, dict]:
    return {
        "services_actions_full": dict(edits=[], scores={"service": 4, "action": 5, "cancel": 2}, reasons=[]),
        # Nothing written: the node's __init__ raises NotImplementedError, no check earns a point,
        # and none says the node runs (it appears in the graph for a moment before it raises).
        "services_actions_stub": dict(edits=[_untouched(course_dir)],
                                      scores={"service": 0, "action": 0, "cancel": 0},
                                      reasons=["NotImplementedError"], absent=["node pan_camera runs"]),
        # The two typical mistakes: the service answers success=False, and the action turns
        # without publishing feedback (so it cannot be canceled after its first feedback either).
        "services_actions_mistakes": dict(
            edits=[("        response.success = True\n", "        response.success = False\n"),
                   ("            goal_handle.publish_feedback(", "            (")],
            scores={"service": 3, "action": 2, "cancel": 0},
            reasons=["answered success=False", "set response.success = True", "no feedback arrived",
                     "goal_handle.publish_feedback(FindPictures.Feedback(pan=..., ids=...))"]),
    }
