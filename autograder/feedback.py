"""Per-student HTML feedback: ``python -m autograder feedback COURSE_DIR``.

nbgrader's ``generate_feedback`` renders each autograded notebook (every check's verdict lines,
its seed, and for catdog_warp the student's crops beside the expected ones, which the checks
display as images) to COURSE_DIR/feedback/<student>/<assignment>/<notebook>.html. This module
adds COURSE_DIR/feedback/<student>/index.html: the scores per assignment and check, and the
reason when a notebook could not be graded at all (those have no nbgrader feedback page).
"""

from __future__ import annotations

import html
import json
from pathlib import Path

from autograder import grading


def write_feedback(course_dir, assignment: str | None = None) -> list[Path]:
    course = Path(course_dir).resolve()
    states = sorted((course / "autograder").glob(f"*/{assignment or '*'}/{grading.STATE_FILE}"))
    results = [json.loads(p.read_text()) for p in states]
    for name in sorted({r["assignment"] for r in results if r["status"] != "failed"}):
        grading.run_nbgrader(["generate_feedback", name, "--force"], course)
    pages = []
    by_student: dict[str, list[dict]] = {}
    for result in results:
        by_student.setdefault(result["student"], []).append(result)
    for student, items in sorted(by_student.items()):
        folder = course / "feedback" / student
        folder.mkdir(parents=True, exist_ok=True)
        rows = []
        for r in sorted(items, key=lambda r: r["assignment"]):
            links = " ".join(f"<a href='{html.escape(p.relative_to(folder).as_posix())}'>{html.escape(p.stem)}</a>"
                             for p in sorted((folder / r["assignment"]).glob("*.html")))
            checks = "".join(f"<li>{html.escape(c['cell'])}: {c['auto_score'] or 0:g} / {c['max_score']:g}</li>"
                             for c in r["cells"])
            reason = f"<pre>{html.escape(r['reason'].strip())}</pre>" if r["reason"].strip() else ""
            rows.append(f"<tr><td>{html.escape(r['assignment'])}</td><td>{r['score']:g} / {r['max_score']:g}</td>"
                        f"<td><ul>{checks}</ul>{reason}</td><td>{links or '(no notebook feedback)'}</td></tr>")
        page = folder / "index.html"
        page.write_text(
            "<!doctype html><meta charset='utf-8'><title>Feedback for " + html.escape(student) + "</title>"
            "<style>body{font-family:sans-serif}td{vertical-align:top;padding:4px 8px;border-top:1px solid #ccc}"
            "pre{white-space:pre-wrap;max-width:60em}</style>"
            f"<h1>Feedback for {html.escape(student)}</h1><table><tr><th>Assignment</th><th>Score</th>"
            "<th>Checks</th><th>Notebooks</th></tr>" + "".join(rows) + "</table>"
            "<p>Each check in the notebook pages shows its seed: grading again with AUTOGRADER_SEED=&lt;seed&gt; "
            "reproduces the frames it used.</p>")
        pages.append(page)
    return pages
