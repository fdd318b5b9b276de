"""A feedback page with the hidden checks' scores but not their reasons: nbgrader's
generate_feedback with this preprocessor after GetGrades (the hub's grading service uses it
before the due date for assignments whose ``reasons_before_due`` is False, autograder.config)."""

from __future__ import annotations

from nbgrader.preprocessors import NbGraderPreprocessor

NOTE = ("The score of this check is above. Why it scored so is shown after the due date, when your "
        "instructor releases the final feedback.\n")


class ScoresOnly(NbGraderPreprocessor):
    """Replace the outputs of the graded test cells (the checks' verdicts) by NOTE. An nbgrader
    preprocessor, so enabled: nbconvert's own are disabled unless configured, and a converter's
    exporter skips them without a word."""

    def preprocess_cell(self, cell, resources, index):
        settings = cell.metadata.get("nbgrader", {})
        if cell.cell_type == "code" and settings.get("grade") and not settings.get("solution"):
            import nbformat

            cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=NOTE)]
        return cell, resources
