"""Per-student HTML feedback: ``python -m autograder feedback COURSE_DIR [--assignment A] [--student S]``.

nbgrader's ``generate_feedback`` renders each autograded notebook (every check's verdict lines,
its seed, and for catdog_warp the student's crops beside the expected ones, which the checks
display as images) to COURSE_DIR/feedback/<student>/<assignment>/<notebook>.html; long verdict
lines wrap there (:data:`WRAP_STYLE`) instead of running off the page. This module adds
COURSE_DIR/feedback/<student>/index.html: for every assignment graded so far (also those not
named in this run), the score per check, the due date, the submission time and the late
penalty, and the reason when a notebook could not be graded at all. Every number on it comes
from the course gradebook (autograder.results.gradebook.submission_scores), the record grades.csv is
made from too, so a manual score given in the formgrader shows on the page as it counts there;
the grader's own record (autograder.json) gives only which assignments were graded and the
reason of a failed one. Students read only what is meant for them: the instructor's notes
(nbgrader's log, the fix) stay in the grading report.
"""

from __future__ import annotations

import html
from pathlib import Path

from autograder import nbgrader_cli
from autograder.results import store
from course_lib.checks.result import points_text

#: Added to nbgrader's feedback pages: output lines (the verdicts) wrap at the page's width.
WRAP_STYLE = ("<style id='autograder-wrap'>div.output_area pre, div.output_subarea pre "
              "{white-space: pre-wrap; overflow-wrap: anywhere;}</style>")


def write_feedback(course_dir, assignment: str | None = None, student: str | None = None) -> list[Path]:
    """Write the feedback of one assignment's, one student's or every graded submission; return the
    index pages written."""
    course = Path(course_dir).resolve()
    chosen = store.recorded_results(course, assignment, student)
    for name in sorted({r.assignment for r in chosen if r.status != "failed"}):
        nbgrader_cli.generate_feedback(course, name, student)
    return _finish(course, chosen)


def _finish(course: Path, chosen: list) -> list[Path]:
    """Wrap the long lines of the results' pages and write each student's index; return the indexes."""
    for r in chosen:
        for page in (course / "feedback" / r.student / r.assignment).glob("*.html"):
            _wrap_lines(page)
    pages = []
    for name in sorted({r.student for r in chosen}):
        # Every assignment of the student, not only this run's: the index lists them all.
        pages.append(_write_index(course, name, store.recorded_results(course, student=name)))
    return pages


def write_in_process(course_dir, assignment: str, students: list[str], scores_only: bool = False) -> list[Path]:
    """The feedback of some students' submissions of one assignment, with nbgrader's
    generate_feedback run in this process (a long-lived caller pays its import once, and one run
    serves every student named). `scores_only`: the checks' verdicts left out
    (autograder.term.scores_only). Return the index pages written."""
    import shutil

    from nbconvert.preprocessors import CSSHTMLHeaderPreprocessor
    from nbgrader.converters import GenerateFeedback
    from nbgrader.preprocessors import GetGrades

    from autograder import config
    from autograder.term import scores_only as hide

    course = Path(course_dir).resolve()
    for student in students:  # generate_feedback without --force makes only what is missing
        shutil.rmtree(course / "feedback" / student / assignment, ignore_errors=True)
    settings = config.load(course)
    settings.GenerateFeedback.preprocessors = [GetGrades, CSSHTMLHeaderPreprocessor,
                                               *([hide.ScoresOnly] if scores_only else [])]
    converter = nbgrader_cli.converter_for(GenerateFeedback, course, assignment, settings=settings)
    converter.force = False
    converter.start()
    chosen = [r for student in students for r in store.recorded_results(course, assignment, student)]
    return _finish(course, chosen)


def _wrap_lines(page: Path) -> None:
    text = page.read_text()
    if "id='autograder-wrap'" not in text and "</head>" in text:
        page.write_text(text.replace("</head>", WRAP_STYLE + "</head>", 1))


def _write_index(course: Path, student: str, results: list) -> Path:
    from autograder.results import gradebook

    folder = course / "feedback" / student
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for r in results:
        links = " ".join(f"<a href='{html.escape(p.relative_to(folder).as_posix())}'>{html.escape(p.stem)}</a>"
                         for p in sorted((folder / r.assignment).glob("*.html")))
        scores = gradebook.submission_scores(course, student, r.assignment)
        checks = "" if scores is None or r.status == "failed" else "".join(
            f"<li>{html.escape(c['cell'])}: {points_text(c['score'] or 0)} / {points_text(c['max_score'])}</li>"
            for c in scores["cells"])
        reason = f"<pre>{html.escape(r.reason.strip())}</pre>" if r.reason.strip() else ""
        rows.append(f"<tr><td>{html.escape(r.assignment)}</td><td>{_score(scores)}</td>"
                    f"<td><ul>{checks}</ul>{reason}</td><td>{links or '(no notebook feedback)'}</td></tr>")
    page = folder / "index.html"
    page.write_text(
        "<!doctype html><meta charset='utf-8'><title>Feedback for " + html.escape(student) + "</title>"
        "<style>body{font-family:sans-serif}td{vertical-align:top;padding:4px 8px;border-top:1px solid #ccc}"
        "pre{white-space:pre-wrap;overflow-wrap:anywhere;max-width:60em}</style>"
        f"<h1>Feedback for {html.escape(student)}</h1><table><tr><th>Assignment</th><th>Score</th>"
        "<th>Checks</th><th>Notebooks</th></tr>" + "".join(rows) + "</table>"
        "<p>Each check in the notebook pages shows its seed: grading again with AUTOGRADER_SEED=&lt;seed&gt; "
        "reproduces the frames it used.</p>")
    return page


def _score(scores: dict | None) -> str:
    """The score cell: the final score, and when there is a due date, the submission time and the penalty."""
    if scores is None:
        return "no score recorded"
    text = f"{points_text(scores['score'])} / {points_text(scores['max_score'])}"
    if scores["duedate"] is not None:
        text += f"<br><small>due {scores['duedate']:%Y-%m-%d %H:%M} UTC"
        if scores["timestamp"] is not None:
            text += f", submitted {scores['timestamp']:%Y-%m-%d %H:%M} UTC"
        if scores["seconds_late"] > 0:
            text += (f"<br>late by {_duration(scores['seconds_late'])}: {points_text(scores['raw_score'])} points "
                     f"− late penalty {points_text(scores['penalty'])}")
        text += "</small>"
    return text


def _duration(seconds: float) -> str:
    days, rest = divmod(int(seconds), 86400)
    hours, rest = divmod(rest, 3600)
    return f"{days} d {hours} h {rest // 60} min" if days else f"{hours} h {rest // 60} min"
