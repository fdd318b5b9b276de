"""The page of the hub's grading service (``/services/grading/``): where each of the student's
submissions is, "queued (n ahead)", "grading", then the score. Behind the hub's login (JupyterHub's
HubOAuth for services): a student sees only their own submissions.
"""

from __future__ import annotations

import html

from jupyterhub.services.auth import HubOAuthCallbackHandler, HubOAuthenticated
from jupyterhub.utils import url_path_join
from tornado import web

from course_lib.checks.result import points_text
from coursehub.submit_queue import Row, SubmitQueue

#: Seconds between two reloads of the page while a submission is still on its way.
REFRESH_SECONDS = 2


def describe(queue: SubmitQueue, row: Row) -> str:
    """Where a submission is, in the student's words."""
    if row.state == "queued":
        return f"queued ({queue.ahead_of(row)} ahead)"
    if row.state == "grading":
        return "grading"
    if row.state in ("graded", "released"):
        score = f"graded: {points_text(row.score or 0)} / {points_text(row.max_score or 0)}"
        reason = f" ({row.message})" if row.message else ""
        if row.state == "graded":
            return f"{score}{reason}; writing its feedback"
        return (f"{score}{reason}; press Fetch Feedback in the Assignments panel (Nbgrader > Assignment List) to "
                "read why")
    if row.state == "failed":
        score = f" ({points_text(row.score)} / {points_text(row.max_score)})" if row.max_score else ""
        return f"failed{score}: {row.message}"
    return f"{row.state} (not graded): {row.message}"


def page(queue: SubmitQueue, student: str) -> str:
    rows = queue.of_student(student)
    waiting = any(row.state in ("queued", "grading", "graded") for row in rows)
    refresh = f"<meta http-equiv='refresh' content='{REFRESH_SECONDS}'>" if waiting else ""
    lines = "".join(
        f"<tr class='submission {row.state}'><td>{html.escape(row.assignment)}</td><td>{row.attempt}</td>"
        f"<td>{html.escape(row.submitted[:19])} UTC</td><td>{html.escape(describe(queue, row))}</td></tr>"
        for row in rows)
    return ("<!doctype html><meta charset='utf-8'>" + refresh +
            f"<title>Grading of {html.escape(student)}'s submissions</title>"
            "<style>body{font-family:sans-serif}"
            "td,th{padding:4px 8px;border-top:1px solid #ccc;text-align:left}</style>"
            f"<h1>Your submissions, {html.escape(student)}</h1>"
            + (f"<table><tr><th>Assignment</th><th>Attempt</th><th>Submitted</th><th>Grading</th></tr>{lines}</table>"
               if rows else "<p id='none'>No submission yet: press Submit in the Assignments panel.</p>")
            + "<p>The newest first. Submissions are graded in the order they arrive.</p>")


class StatusPage(HubOAuthenticated, web.RequestHandler):
    def initialize(self, queue: SubmitQueue):
        self.queue = queue

    @web.authenticated
    def get(self):
        self.set_header("Cache-Control", "no-store")
        self.write(page(self.queue, self.current_user["name"]))


def application(queue: SubmitQueue, prefix: str) -> web.Application:
    """The service's web application under `prefix` (JUPYTERHUB_SERVICE_PREFIX)."""
    import secrets

    return web.Application([
        (prefix, StatusPage, {"queue": queue}),
        (url_path_join(prefix, "oauth_callback"), HubOAuthCallbackHandler),
    ], cookie_secret=secrets.token_bytes(32))
