"""The course's notebooks in JupyterLab, as a student sees them: what only a browser shows.

nbmake runs every lesson top to bottom (conftest.py, support.lesson_runs). Here, every lesson's text
renders as written, and the lessons that show a widget (the RViz view, the keyboard pad) run top
to bottom with Run > Run All Cells, their widgets drawn beside the student's code.

One JupyterLab server and one headless Chromium serve the whole module. The server's root is a
scratch directory holding a copy of notebooks/ (outputs never reach the repository) and the
checker's own small notebooks, which prove that the checker passes a good notebook and fails
one that raises, and a small notebook whose live image view (course_lib.notebook.live) must change
while the camera runs. Screenshots go to artifacts/browser/<notebook>.png.
"""

import json
import time

import pytest
from support.browser import running_jupyterlab
from support.browser_notebook import (
    LESSON_RUN_TIMEOUT,
    NOTEBOOK,
    SCREENSHOTS,
    assert_lesson_runs_clean,
    click_menu,
    click_toolbar_button,
    close_notebook,
    code_cell_count,
    copy_lessons,
    course_lessons,
    open_notebook,
    run_in_lab,
    run_notebook,
    text_problems,
    toolbar_labels,
    widget_lessons,
    write_notebook,
)

from course_lib import contract

ROOT = contract.ROOT
NOTEBOOKS = ROOT / "notebooks"
RUN_TIMEOUT = LESSON_RUN_TIMEOUT

COURSE_NOTEBOOKS = course_lessons()
WIDGET_LESSONS = widget_lessons()

pytestmark = pytest.mark.browser

CHECKER_NOTEBOOKS = {
    "prints.ipynb": ["print('hello from the kernel')",
                     "import sys\nprint('a warning is not an error', file=sys.stderr)\n6 * 7"],
    "plots.ipynb": ["%matplotlib inline\nimport matplotlib.pyplot as plt",
                    "plt.plot([0, 1, 2], [0, 1, 4])\nplt.title('a parabola')\nplt.show()"],
    "raises.ipynb": ["x = 1", "1 / 0", "print('never reached')"],
    "broken_image.ipynb": ["from IPython.display import Image\nImage(data=b'these bytes are no PNG', format='png')"],
}

# A long call in a cell: it waits until the test makes the file `go` (course_lib.progress's line).
PROGRESS_NOTEBOOK = ["""from pathlib import Path
from course_lib import progress, waiting
with progress.Progress("waiting for the test") as shown:
    shown.step("until the file go exists")
    waiting.spin_until(lambda: Path("go").exists(), timeout=600)"""]

# Markdown a reader would see garbled, one way per cell (text_problems must name each).
GARBLED_TEXT = (
    "Lesson without a title",
    "**1.** ```\nros2 topic list -t\n/chatter [std_msgs/msg/String]\n/parameter_events [rcl_interfaces/msg/"
    "ParameterEvent]\n/rosout [rcl_interfaces/msg/Log]\n```\nWhich topic carries the talker's text?",
    "| topic | type |\n| /chatter | std_msgs/msg/String |",
    "![the board](no_such_picture.png)",
    "  ```python\nprint('an indented fence')\n```  ```",
)

# A node cell run three times in one kernel (a student re-running it), then the graph.
NODE_CELL = "listener = session.add_node(Listener())"
RERUN_NOTEBOOK = [
    """from rclpy.node import Node
from std_msgs.msg import String
from course_lib import discovery, graph, session
discovery.SETTLE_SECONDS = 0  # only this kernel's nodes matter: no wait for other processes
session.start()

class Listener(Node):
    def __init__(self):
        super().__init__("listener")
        self.create_subscription(String, "chatter", lambda msg: None, 10)
        self.get_logger().info(f"listening ({id(self)})")""",
    NODE_CELL, NODE_CELL, NODE_CELL,
    'print([endpoint.node for endpoint in graph.topic_info("/chatter").subscriptions], graph.node_list())',
]


# The virtual camera as a process, its /image in live.image_view.
CAMERA_SIZE = (320, 240)
LIVE_NOTEBOOK = [
    "from course_lib import live, processes\n"
    f"camera = processes.python_node('course_lib.imaging.camera:main', '--ros-args', '-p', 'width:={CAMERA_SIZE[0]}', "
    f"'-p', 'height:={CAMERA_SIZE[1]}',\n"
    "                               '-p', 'rate:=10.0', name='camera')\n"
    "camera.wait_for_node('image_publisher', timeout=60)",
    # Explicit bounds: under test a view would stop after live.LIMITED_UPDATES redraws.
    "view = live.image_view('/image', updates=3000, seconds=300)\nview",
]
# The <img> of the ipywidgets Image in the live view's output.
PICTURE = f"{NOTEBOOK} .jp-OutputArea .widget-image"


def lesson_line(notebook: str, start: str) -> str:
    """The one source line of a lesson that starts with `start` (a test then runs it as the lesson does)."""
    import nbformat

    lines = [line for cell in nbformat.read(NOTEBOOKS / notebook, as_version=4).cells if cell.cell_type == "code"
             for line in cell.source.splitlines() if line.startswith(start)]
    assert len(lines) == 1, f"{notebook} has {len(lines)} lines starting with {start!r}"
    return lines[0]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """JupyterLab on a scratch root holding a copy of notebooks/ and the checker's notebooks."""
    root = tmp_path_factory.mktemp("lab-root")
    copy_lessons(root)
    (root / "checker").mkdir()
    for name, sources in CHECKER_NOTEBOOKS.items():
        write_notebook(root / "checker" / name, sources)
    write_notebook(root / "checker" / "rerun_node.ipynb", RERUN_NOTEBOOK)
    write_notebook(root / "checker" / "progress.ipynb", PROGRESS_NOTEBOOK)
    write_notebook(root / "checker" / "live_view.ipynb", LIVE_NOTEBOOK)
    write_notebook(root / "checker" / "garbled_text.ipynb", [], markdown=GARBLED_TEXT)
    # Lesson 02's camera, started as lesson 02 starts it; and lesson 03's, as lesson 03 does.
    write_notebook(root / "checker" / "lesson02_left_running.ipynb", [
        "from course_lib import processes", lesson_line("02_images_and_brightness.ipynb", "CAMERA_ARGS = "),
        lesson_line("02_images_and_brightness.ipynb",
                    'camera = processes.python_node("course_lib.imaging.camera:main", *CAMERA_ARGS, name=')])
    write_notebook(root / "checker" / "lesson03_camera.ipynb", [
        "from course_lib import processes",
        lesson_line("03_aruco_and_homography.ipynb", "camera = processes.python_node(")])
    with running_jupyterlab(root, tmp_path_factory.mktemp("lab-state")) as server:
        print(f"\nJupyterLab answered after {server.startup_seconds:.1f} s")
        yield server


@pytest.mark.timeout(RUN_TIMEOUT + 180)
@pytest.mark.parametrize("notebook", WIDGET_LESSONS or [
    pytest.param(None, marks=pytest.mark.skip(reason=f"no lesson in {NOTEBOOKS} shows a widget"))])
def test_a_lesson_with_widgets_runs_clean_in_jupyterlab_and_draws_them(notebook, browser, lab):
    """After Run All Cells every code cell has run, none shows an error, every image renders, and
    each of the course's widgets the lesson shows is drawn."""
    assert_lesson_runs_clean(browser, lab, notebook)


@pytest.mark.parametrize("notebook", COURSE_NOTEBOOKS or [
    pytest.param(None, marks=pytest.mark.skip(reason=f"no notebooks in {NOTEBOOKS} yet"))])
def test_every_lessons_text_renders_as_written(notebook, browser, lab):
    """JupyterLab renders every markdown cell: no code fence or table shown as plain text, every
    image loads, every formula typesets, a title on top."""
    assert text_problems(browser, lab, f"notebooks/{notebook}") == []


# The first code cell's output while its prompt shows "[*]" and the output holds `text`, else null.
_RUNNING_OUTPUT_JS = """([notebook, text]) => {
  const cell = document.querySelector(notebook + ' .jp-Notebook .jp-CodeCell');
  const prompt = (cell.querySelector('.jp-InputArea-prompt') || {}).innerText || '';
  const output = (cell.querySelector('.jp-Cell-outputArea') || {}).innerText || '';
  return prompt.includes('*') && output.includes(text) ? output : null;
}"""


@pytest.mark.timeout(RUN_TIMEOUT)
def test_a_long_call_shows_what_it_does_and_for_how_long_while_the_cell_runs(browser, lab):
    """course_lib.progress: the line is under the cell while the cell still runs, its seconds count
    up, and when the call ends it says how long it took."""
    path = "checker/progress.ipynb"
    running = "⏳ waiting for the test … until the file go exists ("
    page = open_notebook(browser, lab, path)
    try:
        click_menu(page, "Run", "Run All Cells")
        first = page.wait_for_function(_RUNNING_OUTPUT_JS, arg=[NOTEBOOK, running], timeout=120_000,
                                       polling=100).json_value()
        page.wait_for_function(f"([notebook, text, first]) => {{ const now = ({_RUNNING_OUTPUT_JS})([notebook, text]);"
                               " return now !== null && now !== first; }", arg=[NOTEBOOK, running, first],
                               timeout=120_000, polling=100)
        (lab.root_dir / "checker" / "go").touch()
        page.wait_for_function("""(notebook) => { const cell = document.querySelector(notebook + ' .jp-CodeCell');
            return cell.querySelector('.jp-InputArea-prompt').innerText.trim() === '[1]:'
              && cell.querySelector('.jp-Cell-outputArea').innerText
                   .includes('waiting for the test: finished after'); }""",
                               arg=NOTEBOOK, timeout=120_000, polling=100)
        shown = page.locator(f"{NOTEBOOK} .jp-CodeCell .jp-Cell-outputArea").first.inner_text().strip()
    finally:
        close_notebook(page, lab, path)
    assert first.strip().startswith(running), first
    assert shown.startswith("waiting for the test: finished after ") and "⏳" not in shown, shown


def test_the_students_lab_has_no_instructor_side(lab):
    """Like `make lab`: no Create Assignment sidebar, formgrader or course list; Validate and the
    assignment list stay (nbgrader's server extensions and JupyterLab's page config)."""
    import urllib.error
    import urllib.request

    page = urllib.request.urlopen(f"{lab.url}/lab?token={lab.token}", timeout=30).read().decode()
    disabled = json.loads(page.split('id="jupyter-config-data"', 1)[1].split(">", 1)[1].split("</script>", 1)[0])[
        "disabledExtensions"]
    assert {"@jupyter/nbgrader:create-assignment", "@jupyter/nbgrader:formgrader",
            "@jupyter/nbgrader:course-list"} <= set(disabled)
    assert not any("validate" in name or "assignment-list" in name for name in disabled)
    with pytest.raises(urllib.error.HTTPError, match="404"):
        urllib.request.urlopen(f"{lab.url}/formgrader?token={lab.token}", timeout=30)
    version = urllib.request.urlopen(f"{lab.url}/nbgrader_version?version=x&token={lab.token}", timeout=30)
    assert "server version is" in version.read().decode()  # the validate/assignment-list extensions answer


def test_a_lesson_that_never_ends_would_show_where_its_kernel_waits(lab):
    """A lesson still running at its timeout reports every thread's stack of the kernels
    (JupyterLab.kernel_stacks): clean-clone run #45 showed only the prompts of a hung lesson."""
    kernel = lab.api("POST", "kernels")
    try:
        waited = time.monotonic()
        while not lab.kernels_that_print_stacks():
            assert time.monotonic() - waited < 60, "no kernel handles SIGUSR1: did its startup file run?"
            time.sleep(0.25)
        stacks = lab.kernel_stacks()
    finally:
        lab.api("DELETE", f"kernels/{kernel['id']}")
    assert "Current thread" in stacks and "ipykernel" in stacks, stacks


@pytest.mark.timeout(RUN_TIMEOUT)
def test_rerunning_a_node_cell_replaces_the_node_without_warnings(browser, lab):
    """A node cell run three times: no stderr output (no "Publisher already registered"), the graph
    right at once (one /listener, its subscription under its name), each run's log line in the
    box under its own cell."""
    path = "checker/rerun_node.ipynb"
    run = run_in_lab(browser, lab, path, SCREENSHOTS / "checker" / "rerun_node.png")
    assert run.problems() == [] and run.stderr_outputs == 0, run
    assert run.outputs[4].strip() == "['/listener'] ['/listener']", run.outputs
    for cell in (1, 2, 3):
        assert run.outputs[cell].count("[listener]: listening (") == 1, run.outputs
    assert "ROS log lines of the nodes this cell added" in run.outputs[1]


@pytest.mark.timeout(RUN_TIMEOUT)
def test_a_camera_left_running_by_lesson_02_is_named_when_lesson_03_starts_its_own(browser, lab):
    """Lesson 02 left without its clean-up cell (its kernel keeps running): lesson 03's camera
    cell says plainly that lesson 02's camera still runs and how to stop it."""
    left = "checker/lesson02_left_running.ipynb"
    page = open_notebook(browser, lab, left)
    try:
        first = run_notebook(page, left, 3, RUN_TIMEOUT)
        assert first.problems() == [], first.problems()
        second = run_in_lab(browser, lab, "checker/lesson03_camera.ipynb")
    finally:
        close_notebook(page, lab, left)
    said = second.outputs[1]
    assert "another node process named 'camera'" in said and "lesson02_left_running.ipynb" in said, said
    assert "Shut Down Kernel" in said


# --- the checker itself ---------------------------------------------------------------------

@pytest.mark.timeout(RUN_TIMEOUT)
def test_checker_passes_text_output_and_does_not_take_stderr_for_an_error(browser, lab):
    run = run_in_lab(browser, lab, "checker/prints.ipynb", SCREENSHOTS / "checker" / "prints.png")
    assert run.problems() == []
    assert run.prompts == ["[1]:", "[2]:"]
    assert run.stderr_outputs == 1


@pytest.mark.timeout(RUN_TIMEOUT)
def test_checker_passes_a_notebook_whose_matplotlib_image_renders(browser, lab):
    screenshot = SCREENSHOTS / "checker" / "plots.png"
    run = run_in_lab(browser, lab, "checker/plots.ipynb", screenshot)
    assert run.problems() == []
    assert run.image_outputs == 1 and run.images == 1
    assert screenshot.stat().st_size > 10_000


@pytest.mark.timeout(RUN_TIMEOUT)
def test_checker_fails_a_notebook_that_raises_and_names_the_error(browser, lab):
    run = run_in_lab(browser, lab, "checker/raises.ipynb", SCREENSHOTS / "checker" / "raises.png")
    assert run.errors == ["cell 1: ZeroDivisionError: division by zero"]
    # Run All stops at the error, so the last cell never gets an execution count.
    assert run.unexecuted == ["cell 2: [ ]:"]
    assert any("ZeroDivisionError" in p for p in run.problems())


@pytest.mark.timeout(RUN_TIMEOUT)
def test_checker_fails_an_image_that_does_not_render(browser, lab):
    run = run_in_lab(browser, lab, "checker/broken_image.ipynb")
    assert run.errors == [] and run.image_outputs == 1
    assert run.problems() == ["image does not render in cell 0"]


def test_text_check_names_each_way_markdown_shows_garbled(browser, lab):
    """text_problems, which judges the lessons' text, finds each of GARBLED_TEXT's cells."""
    found = text_problems(browser, lab, "checker/garbled_text.ipynb")
    assert [problem.split(":")[0] for problem in found] == ["cell 1", "cell 2", "cell 3", "cell 4", "cell 0"], found
    assert "code fence shows as text" in found[0] and "table shows as text" in found[1], found
    assert "no_such_picture.png" in found[2] and "does not load" in found[2], found
    assert "code fence shows as text" in found[3], found
    assert found[4] == "cell 0: no title (# heading)"


@pytest.mark.timeout(RUN_TIMEOUT)
def test_toolbar_buttons_are_clicked_by_their_label(browser, lab):
    """click_toolbar_button presses the button named (the way in for nbgrader's Validate)."""
    page = open_notebook(browser, lab, "checker/prints.ipynb")
    try:
        assert "Validate" in toolbar_labels(page), "nbgrader's Validate button is missing"
        cells = f"{NOTEBOOK} .jp-Notebook .jp-Cell"
        before = page.locator(cells).count()
        click_toolbar_button(page, "Insert a cell below")
        page.wait_for_function("([selector, n]) => document.querySelectorAll(selector).length === n",
                               arg=[cells, before + 1], timeout=60_000)
        with pytest.raises(LookupError, match="Insert a cell below"):
            click_toolbar_button(page, "No such button")
    finally:
        close_notebook(page, lab, "checker/prints.ipynb")


@pytest.mark.timeout(400)
def test_live_image_view_picture_changes_while_the_camera_runs(browser, lab):
    """The live image view's picture is the camera's size, its status names the topic, and the
    picture on screen changes from one frame to the next. Screenshots: live_image_view-<n>.png."""
    path = "checker/live_view.ipynb"
    page = open_notebook(browser, lab, path)
    try:
        run = run_notebook(page, path, code_cell_count(lab.root_dir / path), 240)
        # The live picture is replaced about ten times a second, so the generic check may catch
        # it between two frames (a new source not yet decoded); the waits below check it instead.
        problems = [p for p in run.problems() if p != "image does not render in cell 1"]
        assert not problems, problems
        picture = page.locator(PICTURE)
        page.wait_for_function(f"""() => {{ const img = document.querySelector('{PICTURE}');
                                   return img && img.complete && img.naturalWidth === {CAMERA_SIZE[0]}; }}""",
                               timeout=60_000)
        status = page.locator(f"{NOTEBOOK} .jp-OutputArea .widget-label").first.inner_text()
        assert "/image · 320x240 bgr8" in status, status
        shots, sources = [], []
        for number in (1, 2):
            if sources:  # the next frame: a new blob URL in src, decoded
                page.wait_for_function("""([selector, before]) => { const img = document.querySelector(selector);
                                          return img.src !== before && img.complete && img.naturalWidth > 0; }""",
                                       arg=[PICTURE, sources[-1]], timeout=30_000)
            sources.append(picture.get_attribute("src"))
            target = SCREENSHOTS / f"live_image_view-{number}.png"
            target.parent.mkdir(parents=True, exist_ok=True)
            shots.append(picture.screenshot(path=str(target)))
        assert sources[0] != sources[1]
        assert shots[0] != shots[1], "the picture on screen changed (the simulated camera moves)"
    finally:
        close_notebook(page, lab, path)
