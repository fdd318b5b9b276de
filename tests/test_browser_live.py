"""The live image view (course_lib.notebook.live) in JupyterLab: the picture changes while the camera runs.

A small notebook, written by the test into a scratch root, starts the virtual camera as a process
and shows /image with live.image_view; headless Chromium opens it, runs all cells, then watches
the widget's picture. Screenshots go to artifacts/browser/live_image_view-<n>.png.
"""

from pathlib import Path

import pytest
from browser_notebook import NOTEBOOK, close_notebook, code_cell_count, open_notebook, run_notebook, write_notebook
from browser_support import running_jupyterlab

SCREENSHOTS = Path(__file__).resolve().parents[1] / "artifacts" / "browser"
CAMERA_SIZE = (320, 240)

pytestmark = pytest.mark.browser

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


@pytest.mark.timeout(400)
def test_live_image_view_picture_changes_while_the_camera_runs(browser, tmp_path_factory):
    root = tmp_path_factory.mktemp("live-root")
    write_notebook(root / "live_view.ipynb", LIVE_NOTEBOOK)
    with running_jupyterlab(root, tmp_path_factory.mktemp("live-state")) as lab:
        page = open_notebook(browser, lab, "live_view.ipynb")
        try:
            run = run_notebook(page, "live_view.ipynb", code_cell_count(root / "live_view.ipynb"), 240)
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
                    page.wait_for_function(f"""(before) => {{ const img = document.querySelector('{PICTURE}');
                                               return img.src !== before && img.complete && img.naturalWidth > 0; }}""",
                                           arg=sources[-1], timeout=30_000)
                sources.append(picture.get_attribute("src"))
                target = SCREENSHOTS / f"live_image_view-{number}.png"
                target.parent.mkdir(parents=True, exist_ok=True)
                shots.append(picture.screenshot(path=str(target)))
            assert sources[0] != sources[1]
            assert shots[0] != shots[1], "the picture on screen changed (the simulated camera moves)"
        finally:
            close_notebook(page, lab, "live_view.ipynb")
