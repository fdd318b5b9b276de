"""nbgrader's student side in JupyterLab, driven as a student drives it: the notebook's Validate
button (``validate``: press it, read the dialog) and the Nbgrader > Assignment List panel
(``open_assignment_list``, ``assignment_lists``, ``chosen_course``, ``wait_for_assignment``), and the kernels a
server runs (``kernel_processes``, ``kernels_left``: what a Validate leaves behind). The server and the
browser are browser_support's, the notebook UI is browser_notebook's.
"""

from __future__ import annotations

import contextlib
import dataclasses
import time
from pathlib import Path

import psutil

from .browser import JupyterLab
from .browser_notebook import NOTEBOOK, click_menu, click_toolbar_button

# nbgrader's lab extension answers every press of Validate with a dialog of one of these classes,
# titled "Validation Results" when validation ran (success, failed or changed cells, or the error
# it raised), "Validation failed" or "Version Mismatch" when it never got that far.
_VALIDATE_DIALOG = ".jp-Dialog.nbgrader-SuccessDialog, .jp-Dialog.nbgrader-ErrorDialog"

_VALIDATE_DIALOG_JS = """(selector) => {
  const dialog = document.querySelector(selector);
  if (!dialog) return null;
  const message = dialog.querySelector('#validation-message');
  const outcome = message ? [...message.classList].find(c => c.startsWith('validation-')) : null;
  return {
    title: (dialog.querySelector('.jp-Dialog-header') || {}).innerText || '',
    text: (dialog.querySelector('.jp-Dialog-body') || {}).innerText || '',
    outcome: outcome ? outcome.slice('validation-'.length) : '',
    error: dialog.classList.contains('nbgrader-ErrorDialog'),
  };
}"""


@dataclasses.dataclass
class Validation:
    """What nbgrader's Validate dialog told the student.

    Attributes:
        title: the dialog's title; "Validation Results" when validation ran.
        text: the dialog's text as shown (failed cells' sources and their errors included).
        outcome: nbgrader's verdict: "success", "failed", "changed" or "type-changed"; "" when
            validation did not run or raised (the text says why).
        error: nbgrader showed it as an error dialog (anything but success).
        seconds: time from the click until the dialog appeared.
        labels: what the Validate button said from the click to the dialog, each change once
            ("Saving...", "Validating...", "Validating: cell 3 of 20", ...).
    """

    title: str
    text: str
    outcome: str
    error: bool
    seconds: float
    labels: list[str] = dataclasses.field(default_factory=list)


# Records each label the Validate button shows (nbgrader and the course's progress both set the
# label's innerText) in window.validateLabels, until the next call.
_WATCH_LABELS_JS = """(buttonSelector) => {
  const button = document.querySelector(buttonSelector);
  const label = () => button.querySelector('.jp-ToolbarButtonComponent-label').innerText.trim();
  window.validateLabels = [label()];
  if (window.validateLabelsObserver) window.validateLabelsObserver.disconnect();
  window.validateLabelsObserver = new MutationObserver(() => {
    const now = label();
    if (now !== window.validateLabels[window.validateLabels.length - 1]) window.validateLabels.push(now);
  });
  window.validateLabelsObserver.observe(button, {childList: true, characterData: true, subtree: true});
}"""


def validate(page, timeout: float, screenshot: Path | None = None) -> Validation:
    """Press the open notebook's Validate button, read nbgrader's dialog, close it; return what it said.

    Args:
        page: a page from open_notebook.
        timeout: seconds to allow for saving and validating (nbgrader runs the whole notebook).
        screenshot: where to save a screenshot of the page with the dialog open, or None.

    Raises:
        TimeoutError: when no dialog appeared within timeout, with the button's label at that time.
    """
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    page.evaluate(_WATCH_LABELS_JS, f"{NOTEBOOK} .validate-button")
    started = time.monotonic()
    click_toolbar_button(page, "Validate")
    try:
        page.locator(_VALIDATE_DIALOG).first.wait_for(state="visible", timeout=timeout * 1000)
    except PlaywrightTimeout:
        label = page.locator(f"{NOTEBOOK} .validate-button").inner_text(timeout=5_000).strip()
        raise TimeoutError(f"no nbgrader dialog {timeout:.0f} s after pressing Validate; the button says "
                           f"{label!r} (\"Validating...\": the server is still running the notebook)") from None
    seconds = time.monotonic() - started
    labels = page.evaluate("() => window.validateLabels")
    page.wait_for_timeout(300)  # the dialog fades in; let the screenshot show it settled
    said = page.evaluate(_VALIDATE_DIALOG_JS, _VALIDATE_DIALOG)
    if screenshot is not None:
        screenshot.parent.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(screenshot))
    page.locator(_VALIDATE_DIALOG).locator(".jp-mod-accept").first.click()
    page.locator(_VALIDATE_DIALOG).first.wait_for(state="detached", timeout=60_000)
    return Validation(title=said["title"].strip(), text=said["text"].strip(), outcome=said["outcome"],
                      error=said["error"], seconds=seconds, labels=labels)


ASSIGNMENT_LISTS = ("released", "fetched", "submitted")

# Each list of the Assignments panel: rows, a placeholder when empty, an error when nbgrader failed.
_ASSIGNMENT_LISTS_JS = """(names) => Object.fromEntries(names.map(name => {
  const shown = id => { const el = document.getElementById(id); return !!el && el.offsetParent !== null; };
  const list = document.getElementById(name + '_assignments_list');
  const rows = list ? [...list.querySelectorAll(':scope > .list_item')] : [];
  const text = id => document.getElementById(id).innerText.trim();
  let said = rows.map(row => row.innerText.split('\\n').map(s => s.trim()).filter(Boolean).join(' | '));
  if (!list) said = ['(no such list: is the Assignments panel open?)'];
  else if (shown(name + '_assignments_list_loading')) said = ['(loading)'];
  else if (shown(name + '_assignments_list_error')) said = ['(error) ' + text(name + '_assignments_list_error')];
  return [name, said];
}))"""


def open_assignment_list(context, lab: JupyterLab, timeout: float = 60):
    """Open JupyterLab without a notebook and its Nbgrader > Assignment List panel; return the page."""
    page = context.new_page()
    try:
        page.set_default_timeout(timeout * 1000)
        page.goto(f"{lab.url}/lab/workspaces/test-assignments?token={lab.token}", wait_until="domcontentloaded")
        page.locator("#jp-MainMenu .lm-MenuBar-item").first.wait_for()
        click_menu(page, "Nbgrader", "Assignment List")
        page.locator("#released_assignments_list").wait_for()
    except BaseException:
        page.close()
        raise
    return page


def assignment_lists(page) -> dict[str, list[str]]:
    """What the open Assignments panel shows now, by list ("released", "fetched", "submitted").

    Returns:
        each list's rows as e.g. "brightness | <course id> | Fetch"; [] for an empty list, and
        ["(loading)"] or ["(error) <nbgrader's message>"] while it loads or when it failed.
    """
    return page.evaluate(_ASSIGNMENT_LISTS_JS, list(ASSIGNMENT_LISTS))


def chosen_course(page) -> str:
    """What the Assignments panel's course button says: the course shown, "Error fetching courses!"
    when nbgrader could not list them, "No courses found." when the exchange has none."""
    return page.locator("#course_list_default").inner_text().strip()


def wait_for_assignment(page, listed: str, assignment: str, timeout: float) -> str:
    """Wait until the Assignments panel's list `listed` ("released", ...) has a row for assignment; return it.

    Raises:
        TimeoutError: naming what each list showed instead.
    """
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    try:
        page.wait_for_function(
            """([listed, assignment]) => [...document.querySelectorAll(`#${listed}_assignments_list > .list_item`)]
                 .some(row => (row.querySelector('.item_name') || {}).innerText?.trim() === assignment)""",
            arg=[listed, assignment], timeout=timeout * 1000, polling=250)
    except PlaywrightTimeout:
        raise TimeoutError(f"no {assignment!r} among the {listed} assignments after {timeout:.0f} s; "
                           f"the panel shows {assignment_lists(page)}") from None
    return next(row for row in assignment_lists(page)[listed] if row.split(" | ")[0] == assignment)


def kernel_processes(lab: JupyterLab) -> list[psutil.Process]:
    """The kernels the server runs now: its descendant processes that run ipykernel."""
    found = []
    for process in lab.descendants():
        with contextlib.suppress(psutil.Error):
            if any("ipykernel" in part for part in process.cmdline()):
                found.append(process)
    return found


def kernels_left(lab: JupyterLab, before: list[psutil.Process], grace: float = 60) -> list[str]:
    """Kernels of the server that were not among `before` and have not ended within grace seconds
    (a wall-clock backstop: a kernel that is being shut down ends long before), by pid and command."""
    known = {process.pid for process in before}
    new = [process for process in kernel_processes(lab) if process.pid not in known]
    _, alive = psutil.wait_procs(new, timeout=grace)
    left = []
    for process in alive:
        with contextlib.suppress(psutil.Error):
            left.append(f"pid {process.pid}: {' '.join(process.cmdline())}")
    return left
