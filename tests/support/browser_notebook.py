"""The notebook in JupyterLab as a student uses it, in a page of browser_support's Chromium.

- ``open_notebook`` / ``close_notebook`` and ``click_toolbar_button``: open a notebook by path
  (in one JupyterLab page per server, as a student does), press a notebook toolbar button by its
  label (the way in for nbgrader's "Validate" button); ``click_menu``;
- ``run_notebook``: Run > Run All Cells, wait for the kernel, and report what the student sees;
- the course's lessons: copied, their text rendered (``text_problems``), and those that show a
  widget run clean with it drawn (``assert_lesson_runs_clean``).
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import shutil
import time
from pathlib import Path

from course_lib import contract

from .browser import VIEWPORT, JupyterLab

# A screenshot taller than this is cut: Chromium cannot capture arbitrarily tall pages.
MAX_SCREENSHOT_HEIGHT = 16000

ERROR_MIME = "application/vnd.jupyter.error"
IMAGE_MIMES = ("image/png", "image/jpeg", "image/gif", "image/svg+xml", "image/webp", "image/bmp")
#: The course's widgets, drawn by their JavaScript in the browser only (nbmake runs a lesson without
#: it): the module a lesson's code uses to show one, and what the page shows once it is drawn.
WIDGETS = {"course_lib.notebook.rviz": ".rviz-canvas", "course_lib.robot.teleop_widget": ".course-teleop"}


# --- the notebook UI -----------------------------------------------------------------------

def write_notebook(path: Path, sources: list[str], markdown: tuple[str, ...] = ()) -> None:
    """Write a notebook of code cells (no outputs), after the markdown cells given, with the python3
    kernel, for a test to open."""
    import nbformat

    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell(m) for m in markdown]
                                        + [nbformat.v4.new_code_cell(s) for s in sources])
    notebook.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3 (ipykernel)",
                                       "language": "python"}
    nbformat.write(notebook, path)


def code_cell_count(path: Path) -> int:
    return sum(cell["cell_type"] == "code" for cell in json.loads(path.read_text())["cells"])


NOTEBOOK = ".jp-NotebookPanel:not(.lm-mod-hidden)"


_KERNEL_READY_JS = """(notebookSelector) => {
  const indicator = document.querySelector(notebookSelector + ' .jp-Notebook-ExecutionIndicator');
  const widget = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  const kernel = widget && widget.sessionContext && widget.sessionContext.session
      && widget.sessionContext.session.kernel;
  return !!(indicator && indicator.dataset.status === 'idle' && kernel && kernel.status === 'idle');
}"""

_FIRST_CELL_STARTED_JS = """(notebookSelector) => {
  const prompt = document.querySelector(notebookSelector + ' .jp-CodeCell .jp-InputArea-prompt');
  return !prompt || prompt.innerText.trim() !== '[ ]:';
}"""

_KERNEL_READY_OR_DIALOG_JS = f"""(notebookSelector) =>
  !!document.querySelector('.jp-Dialog .jp-mod-accept') || ({_KERNEL_READY_JS})(notebookSelector)"""


#: One JupyterLab page per Chromium context and server, kept between notebooks: a notebook opens in
#: it as a student opens one from the file browser. (Loading JupyterLab costs Chromium about 7 s of
#: CPU; opening a notebook in a loaded JupyterLab, a fraction of that.)
_LAB_PAGES: dict[tuple[int, str], object] = {}

_OPEN_JS = "(path) => { window.jupyterapp.commands.execute('docmanager:open', {path}); }"

_CURRENT_IS_JS = """(path) => {
  const widget = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  return !!(widget && widget.context && widget.context.path === path);
}"""

# Disposing skips the "save your changes?" question that closing a run notebook asks.
_DISPOSE_JS = """(path) => {
  for (const widget of [...window.jupyterapp.shell.widgets('main')])
    if (widget.context && widget.context.path === path) widget.dispose();
}"""


def open_notebook(context, lab: JupyterLab, path: str, timeout: float = 120):
    """Open the notebook at path (relative to lab.root_dir) and wait until its kernel is idle: in
    the JupyterLab page this context already has on lab, else in a new page (a tab of its own).
    Close it with close_notebook.

    Returns:
        the Playwright page showing it.
    """
    key = (id(context), lab.url)
    page = _LAB_PAGES.pop(key, None)
    if page is not None and (page.is_closed() or page.context is not context
                             or page.locator(".jp-Dialog").count()):
        if not page.is_closed():
            page.close()
        page = None
    fresh = page is None
    if fresh:
        page = context.new_page()
    try:
        page.set_default_timeout(timeout * 1000)
        if fresh:
            page.goto(lab.lab_url(path), wait_until="domcontentloaded")
        else:
            page.evaluate(_OPEN_JS, path)
            page.wait_for_function(_CURRENT_IS_JS, arg=path, polling=100)
        page.locator(f"{NOTEBOOK} .jp-Notebook .jp-Cell").first.wait_for(state="attached")
        # A notebook without kernel metadata asks which kernel to use; take the suggested one.
        page.wait_for_function(_KERNEL_READY_OR_DIALOG_JS, arg=NOTEBOOK, polling=250)
        accept = page.locator(".jp-Dialog .jp-mod-accept")
        if accept.count():
            accept.click()
        # The toolbar indicator says "idle" for a moment before the kernel exists: ask the session.
        page.wait_for_function(_KERNEL_READY_JS, arg=NOTEBOOK, polling=250)
    except BaseException:
        page.close()
        raise
    _LAB_PAGES[key] = page
    return page


def close_notebook(page, lab: JupyterLab, path: str) -> None:
    """Close path's notebook in page and shut its kernel down. The page stays open for the next
    notebook, unless something is left on it (a dialog): then it is closed too."""
    try:
        if not page.is_closed():
            page.evaluate(_DISPOSE_JS, path)
    finally:
        lab.shut_down_kernels_of(path)
        if not page.is_closed() and page.locator(".jp-Dialog").count():
            page.close()


def toolbar_labels(page) -> list[str]:
    """Labels of the open notebook's toolbar buttons: their visible text, else their tooltip."""
    return page.locator(f"{NOTEBOOK} .jp-NotebookPanel-toolbar .jp-ToolbarButtonComponent").evaluate_all(
        "buttons => buttons.map(b => (b.innerText.trim() || b.getAttribute('title') || '').trim())")


def click_toolbar_button(page, label: str) -> None:
    """Click the open notebook's toolbar button whose text or tooltip starts with label.

    This is how a student presses e.g. nbgrader's "Validate" button.

    Raises:
        LookupError: naming the labels that are there, when no button or several match.
    """
    labels = toolbar_labels(page)
    matches = [i for i, text in enumerate(labels) if text.lower().startswith(label.lower())]
    if len(matches) != 1:
        raise LookupError(f"{len(matches)} toolbar buttons match {label!r}; the toolbar has {labels}")
    page.locator(f"{NOTEBOOK} .jp-NotebookPanel-toolbar .jp-ToolbarButtonComponent").nth(matches[0]).click()


def click_menu(page, menu: str, item: str) -> None:
    """Click item in menu of the main menu bar (e.g. "Run", "Run All Cells")."""
    page.locator("#jp-MainMenu .lm-MenuBar-item", has=page.get_by_text(menu, exact=True)).click()
    label = page.locator(".lm-Menu-itemLabel", has_text=re.compile(rf"^{re.escape(item)}$"))
    page.locator(".lm-Menu .lm-Menu-item", has=label).click()


@dataclasses.dataclass
class NotebookRun:
    """What a student sees after Run All Cells.

    Attributes:
        path: the notebook, relative to the server's root.
        code_cells: number of code cells in the .ipynb file.
        prompts: the execution prompt of every code cell on the page, e.g. "[3]:" or "[ ]:".
        errors: "cell N: EName: value" for every error output.
        images: number of <img> elements in output areas.
        broken_images: "cell N" for every image that did not decode (naturalWidth 0).
        image_outputs: number of outputs with an image MIME type in the notebook model.
        stderr_outputs: number of outputs rendered as stderr (warnings, logs and errors alike).
        seconds: time from clicking Run All Cells until the kernel was idle again.
        screenshot: where the full-page screenshot was saved (None when not asked for).
        outputs: the text each code cell's output area shows (widgets' text included).
        widgets: number of widget outputs (ipywidgets/anywidget views) in the notebook model.
        drawn_widgets: for each of WIDGETS' selectors, how many the output areas show drawn.
        broken_widgets: "cell N: text" for every widget output that shows an error or is still loading.
    """

    path: str
    code_cells: int
    prompts: list[str]
    errors: list[str]
    images: int
    broken_images: list[str]
    image_outputs: int
    stderr_outputs: int
    seconds: float
    screenshot: Path | None = None
    outputs: list[str] = dataclasses.field(default_factory=list)
    widgets: int = 0
    drawn_widgets: dict[str, int] = dataclasses.field(default_factory=dict)
    broken_widgets: list[str] = dataclasses.field(default_factory=list)

    @property
    def unexecuted(self) -> list[str]:
        return [f"cell {i}: {p}" for i, p in enumerate(self.prompts) if not p.strip("[]: ").isdigit()]

    def problems(self) -> list[str]:
        """Everything that makes this run a failure, each in words a course author can act on."""
        found = [f"error output in {e}" for e in self.errors]
        if len(self.prompts) != self.code_cells:
            found.append(f"the page shows {len(self.prompts)} code cells, the file has {self.code_cells}")
        found += [f"not executed (run stopped?): {u}" for u in self.unexecuted]
        found += [f"image does not render in {b}" for b in self.broken_images]
        if self.images < self.image_outputs:
            found.append(f"{self.image_outputs} image outputs but only {self.images} <img> on the page")
        found += [f"widget not shown in {b}" for b in self.broken_widgets]
        return found


_PAGE_STATE_JS = """
([notebookSelector, errorMime, imageMimes, drawnSelectors]) => {
  const panel = document.querySelector(notebookSelector);
  const codeCells = [...panel.querySelectorAll('.jp-Notebook .jp-CodeCell')];
  const prompts = codeCells.map(c => (c.querySelector('.jp-InputArea-prompt') || {}).innerText || '');
  const outputs = codeCells.map(c => (c.querySelector('.jp-Cell-outputArea') || {}).innerText || '');
  const images = [];
  codeCells.forEach((c, i) => c.querySelectorAll('.jp-OutputArea img').forEach(img =>
      images.push({cell: i, ok: img.complete && img.naturalWidth > 0})));
  const widgetOutputs = [...panel.querySelectorAll(
    '.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.widget-view+json"]')];
  const brokenWidgets = widgetOutputs.filter(w => /Error displaying widget|Loading widget/.test(w.innerText))
      .map(w => codeCells.findIndex(c => c.contains(w)) + ': ' + w.innerText.slice(0, 120));
  const drawnWidgets = Object.fromEntries(drawnSelectors.map(
      s => [s, panel.querySelectorAll('.jp-OutputArea ' + s).length]));
  const stderr = panel.querySelectorAll(
    '.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.stderr"]').length;
  const app = window.jupyterapp;
  if (!app) return {error: 'window.jupyterapp is missing (start the server with expose_app_in_browser)'};
  const widget = app.shell.currentWidget;
  const errors = [];
  let imageOutputs = 0;
  let widgets = 0;
  const widgetMime = 'application/vnd.jupyter.widget-view+json';
  let codeIndex = -1;
  for (const cell of widget.content.model.cells) {
    if (cell.type !== 'code') continue;
    codeIndex += 1;
    for (let k = 0; k < cell.outputs.length; k++) {
      const data = cell.outputs.get(k).data;
      if (data[errorMime]) errors.push(`cell ${codeIndex}: ${data[errorMime].ename}: ${data[errorMime].evalue}`);
      if (imageMimes.some(m => m in data)) imageOutputs += 1;
      if (widgetMime in data) widgets += 1;
    }
  }
  return {prompts, images, errors, imageOutputs, stderr, outputs, widgets, drawnWidgets, brokenWidgets};
}
"""

_RUNNING_JS = """(notebookSelector) => {
  const panel = document.querySelector(notebookSelector);
  const indicator = panel.querySelector('.jp-Notebook-ExecutionIndicator');
  const busy = [...panel.querySelectorAll('.jp-CodeCell .jp-InputArea-prompt')]
      .some(p => p.textContent.includes('*'));
  return !busy && indicator && indicator.dataset.status === 'idle';
}
"""


def run_notebook(page, path: str, code_cells: int, timeout: float, screenshot: Path | None = None,
                 screenshot_always: bool = True) -> NotebookRun:
    """Run > Run All Cells in the open notebook, wait until nothing runs, and report the result.

    Args:
        page: a page from open_notebook.
        path: the notebook path, for the report.
        code_cells: the number of code cells in the file, to check that the page shows them all.
        timeout: seconds to allow for the whole run.
        screenshot: where to save a full-page screenshot, or None.
        screenshot_always: False: only when the run has problems (a full-page screenshot of a
            long notebook costs Chromium about 8 s of processor time).
    """
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    started = time.monotonic()
    click_menu(page, "Run", "Run All Cells")
    # Run All queues every cell at once and marks each "[*]"; it has started when the first
    # prompt changed, and it is done when no prompt shows "[*]" and the kernel is idle, twice
    # in a row (the last outputs settle).
    try:
        page.wait_for_function(_FIRST_CELL_STARTED_JS, arg=NOTEBOOK, timeout=30_000, polling=100)
        for _ in range(2):
            remaining = max(1.0, timeout - (time.monotonic() - started))
            page.wait_for_function(_RUNNING_JS, arg=NOTEBOOK, timeout=remaining * 1000, polling=250)
            page.wait_for_timeout(300)
    except PlaywrightTimeout:
        prompts = page.locator(f"{NOTEBOOK} .jp-CodeCell .jp-InputArea-prompt").all_inner_texts()
        if screenshot is not None:
            save_full_notebook_screenshot(page, screenshot)
        raise TimeoutError(f"{path} still running {time.monotonic() - started:.0f} s after Run All Cells; "
                           f"prompts: {prompts}") from None
    seconds = time.monotonic() - started
    # Images decode asynchronously after their output is attached.
    page.wait_for_function(f"""() => [...document.querySelectorAll('{NOTEBOOK} .jp-OutputArea img')]
                               .every(img => img.complete)""", timeout=30_000)
    state = page.evaluate(_PAGE_STATE_JS, [NOTEBOOK, ERROR_MIME, list(IMAGE_MIMES), list(WIDGETS.values())])
    if "error" in state:
        raise RuntimeError(state["error"])
    run = NotebookRun(
        path=path, code_cells=code_cells, prompts=state["prompts"], errors=state["errors"],
        images=len(state["images"]), broken_images=[f"cell {i['cell']}" for i in state["images"] if not i["ok"]],
        image_outputs=state["imageOutputs"], stderr_outputs=state["stderr"], seconds=seconds,
        outputs=state["outputs"], widgets=state["widgets"], drawn_widgets=state["drawnWidgets"],
        broken_widgets=[f"cell {b}" for b in state["brokenWidgets"]])
    if screenshot is not None and (screenshot_always or run.problems()):
        save_full_notebook_screenshot(page, screenshot)
        run.screenshot = screenshot
    return run


def save_full_notebook_screenshot(page, target: Path) -> None:
    """Save a screenshot that shows the whole notebook: the window grows to fit it, then shrinks back.

    JupyterLab scrolls the notebook inside a panel, so a plain full-page screenshot would show
    only the first screen of it.
    """
    target.parent.mkdir(parents=True, exist_ok=True)
    # How far the last cell reaches below the visible part of the notebook.
    extra = page.evaluate(f"""() => {{
        const scroller = document.querySelector('{NOTEBOOK} .jp-WindowedPanel-outer');
        const cells = document.querySelectorAll('{NOTEBOOK} .jp-Notebook .jp-Cell');
        if (!scroller || !cells.length) return 0;
        const last = cells[cells.length - 1].getBoundingClientRect();
        return last.bottom - scroller.getBoundingClientRect().bottom + scroller.scrollTop; }}""")
    height = min(VIEWPORT["height"] + max(0, round(extra)) + 40, MAX_SCREENSHOT_HEIGHT)
    page.set_viewport_size({"width": VIEWPORT["width"], "height": height})
    try:
        page.evaluate(f"() => document.querySelector('{NOTEBOOK} .jp-WindowedPanel-outer')?.scrollTo(0, 0)")
        page.wait_for_timeout(500)  # let Lumino lay out the taller window
        page.screenshot(path=str(target), full_page=True)
    finally:
        page.set_viewport_size(VIEWPORT)


# --- the course's lessons ------------------------------------------------------------------

LESSONS_DIR = contract.ROOT / "notebooks"
SCREENSHOTS = contract.ROOT / "artifacts" / "browser"
#: Seconds a lesson may take from Run All Cells until nothing runs (ROS nodes and colcon builds
#: take a minute on a busy 2-core machine; allow plenty).
LESSON_RUN_TIMEOUT = 300

def course_lessons() -> list[str]:
    """Every lesson: its path under notebooks/."""
    return sorted(str(p.relative_to(LESSONS_DIR)) for p in LESSONS_DIR.rglob("*.ipynb")
                  if ".ipynb_checkpoints" not in p.parts)


def widgets_shown(lesson: str) -> list[str]:
    """The modules of WIDGETS whose widgets `lesson` (its path under notebooks/) shows."""
    import nbformat

    code = "\n".join(cell.source for cell in nbformat.read(LESSONS_DIR / lesson, as_version=4).cells
                     if cell.cell_type == "code")
    return [module for module in WIDGETS if module in code]


def widget_lessons() -> list[str]:
    """The lessons that show a widget (WIDGETS): they run top to bottom in Chromium as well as under
    nbmake, to show that their widgets draw beside the student's code."""
    return [lesson for lesson in course_lessons() if widgets_shown(lesson)]


def copy_lessons(root: Path) -> None:
    """Copy notebooks/ to root/notebooks as in a fresh checkout: no checkpoints, no colcon output."""
    if LESSONS_DIR.is_dir():
        shutil.copytree(LESSONS_DIR, root / "notebooks",
                        ignore=shutil.ignore_patterns(".ipynb_checkpoints", "build", "install", "log"))


def run_in_lab(context, lab: JupyterLab, path: str, screenshot: Path | None = None,
               screenshot_always: bool = True) -> NotebookRun:
    """Open path in JupyterLab, run all cells, shut its kernel down; return the NotebookRun."""
    page = open_notebook(context, lab, path)
    try:
        run = run_notebook(page, path, code_cell_count(lab.root_dir / path), LESSON_RUN_TIMEOUT, screenshot,
                           screenshot_always)
    except TimeoutError as stuck:
        raise TimeoutError(f"{stuck}\nPython stacks of the kernels, {lab.kernel_stacks()}") from None
    finally:
        close_notebook(page, lab, path)
    print(f"\n{path}: Run All Cells took {run.seconds:.1f} s")
    return run


def assert_lesson_runs_clean(context, lab: JupyterLab, notebook: str) -> NotebookRun:
    """Run a lesson (its path under notebooks/) top to bottom in lab: every code cell ran, none
    shows an error, every image and widget renders, each of the course's widgets it shows is drawn.
    A run with problems leaves a screenshot in artifacts/browser/ (every run does with
    COURSE_TEST_SCREENSHOTS=1). Returns the run."""
    screenshot = SCREENSHOTS / (notebook.removesuffix(".ipynb").replace("/", "__") + ".png")
    run = run_in_lab(context, lab, f"notebooks/{notebook}", screenshot,
                     screenshot_always=os.environ.get("COURSE_TEST_SCREENSHOTS") == "1")
    assert not run.problems(), f"{notebook} in JupyterLab (screenshot {screenshot}):\n" + "\n".join(run.problems())
    undrawn = [module for module in widgets_shown(notebook) if not run.drawn_widgets[WIDGETS[module]]]
    assert not undrawn, f"{notebook} in JupyterLab shows no drawn widget of {undrawn} (screenshot {screenshot})"
    return run



# Each markdown cell of the open notebook as JupyterLab rendered it: what a reader would see wrong.
_TEXT_PROBLEMS_JS = """(notebookSelector) => {
  const cells = [...document.querySelectorAll(notebookSelector + ' .jp-Notebook .jp-Cell')];
  const found = [];
  cells.forEach((cell, i) => {
    if (!cell.classList.contains('jp-MarkdownCell')) return;
    const shown = cell.querySelector('.jp-RenderedMarkdown');
    if (!shown) { found.push(`cell ${i}: not rendered`); return; }
    if (shown.innerText.includes('```')) found.push(`cell ${i}: a code fence shows as text`);
    shown.querySelectorAll('p').forEach(p => {
      if (/^\\s*\\|.*\\|\\s*$/m.test(p.innerText))
        found.push(`cell ${i}: a table shows as text: ${p.innerText.slice(0, 80)}`);
    });
    shown.querySelectorAll('img').forEach(img => {
      if (!(img.complete && img.naturalWidth > 0))
        found.push(`cell ${i}: image ${img.getAttribute('src')} does not load`);
    });
    if (shown.querySelector('mjx-merror, .MathJax_Error')) found.push(`cell ${i}: a formula does not typeset`);
  });
  if (!cells.length || !cells[0].querySelector('.jp-RenderedMarkdown h1')) found.push('cell 0: no title (# heading)');
  return found;
}"""


def text_problems(context, lab: JupyterLab, path: str) -> list[str]:
    """Open path and return what its markdown cells show wrong, rendered by JupyterLab: a cell left
    unrendered, a code fence (e.g. one on the line of a text) or a table shown as plain text, an
    image that does not load, a formula that does not typeset, no title. Nothing runs."""
    page = open_notebook(context, lab, path)
    try:
        page.wait_for_function(f"""() => [...document.querySelectorAll('{NOTEBOOK} .jp-RenderedMarkdown img')]
                                   .every(img => img.complete)""", timeout=30_000)
        return page.evaluate(_TEXT_PROBLEMS_JS, NOTEBOOK)
    finally:
        close_notebook(page, lab, path)
