"""The notebook's teleop pad (course_lib.robot.teleop_widget) in JupyterLab in headless Chromium:
a key held on the pad (keydown, a wait, keyup) makes the kernel publish nonzero twists on the
pad's topic while it is held and one zero twist after it is let go; the pad losing focus while a
key is still down stops the robot as well. A subscriber in this process (real DDS) hears them.
"""

import pytest
from support.browser import running_jupyterlab
from support.browser_notebook import close_notebook, code_cell_count, open_notebook, run_notebook, write_notebook

pytestmark = pytest.mark.browser

#: A topic of this test's own, so that no other pad or robot on the domain is heard or driven.
TOPIC = "/teleop_browser_test/cmd_vel"
NOTEBOOK_CELLS = [f"""from course_lib.robot import teleop_widget
pad = teleop_widget.KeyboardTeleop(topic={TOPIC!r})
pad"""]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    root = tmp_path_factory.mktemp("teleop-lab")
    write_notebook(root / "teleop.ipynb", NOTEBOOK_CELLS)
    with running_jupyterlab(root, tmp_path_factory.mktemp("teleop-lab-state")) as server:
        yield server


@pytest.fixture(scope="module")
def pad(browser, lab):
    """(page, the pad's element, the twists heard on TOPIC as (linear.x, angular.z)) once the
    notebook has run and the kernel's publisher has matched the subscriber here."""
    from geometry_msgs.msg import Twist

    from course_lib.ros import session

    path = "teleop.ipynb"
    page = open_notebook(browser, lab, path)
    session.start()
    node = session.tool_node()
    heard = []
    subscription = node.create_subscription(Twist, TOPIC, lambda m: heard.append((m.linear.x, m.angular.z)), 100)
    try:
        run = run_notebook(page, path, code_cell_count(lab.root_dir / path), 240)
        assert run.problems() == [], run.problems()
        element = page.locator(".course-teleop")
        element.wait_for(state="visible", timeout=60_000)
        assert session.wait_for(lambda: node.count_publishers(TOPIC) >= 1, timeout=60), "the pad's publisher"
        yield page, element, heard
    finally:
        node.destroy_subscription(subscription)
        close_notebook(page, lab, path)


def held_twists(page, heard: list, key: str) -> list:
    """Focus the pad, press `key` and wait until the kernel publishes its twists (several, while it
    stays down); returns what was heard since the press. The key is left down."""
    from course_lib.ros import session

    start = len(heard)
    page.keyboard.down(key)
    assert session.wait_for(lambda: sum(1 for t in heard[start:] if t != (0.0, 0.0)) >= 5, timeout=60), heard[start:]
    return heard[start:]


@pytest.mark.timeout(400)
def test_a_held_key_drives_and_letting_it_go_stops_the_robot(pad):
    from course_lib.ros import session

    page, element, heard = pad
    element.click()
    assert "driving: hold a key" in element.inner_text()
    assert set(held_twists(page, heard, "i")) == {(0.5, 0.0)}, "i: forward at 0.5 m/s while held"
    assert "[i]" in element.inner_text()
    page.keyboard.up("i")
    assert session.wait_for(lambda: heard[-1] == (0.0, 0.0), timeout=30), heard[-5:]
    stopped = len(heard)
    session.wait_for(lambda: False, timeout=1.0)  # the pad publishes at 10 Hz: ten more if it had not stopped
    assert heard[stopped:] == [], "nothing more after the zero twist"


@pytest.mark.timeout(400)
def test_the_pad_losing_focus_while_a_key_is_down_stops_the_robot(pad):
    from course_lib.ros import session

    page, element, heard = pad
    element.click()
    twists = held_twists(page, heard, "j")
    assert set(twists) - {(0.0, 0.0)} == {(0.0, 1.0)}, "j: turning left at 1 rad/s while held"
    try:
        page.locator(".jp-Notebook").first.click(position={"x": 5, "y": 5})  # focus elsewhere, key still down
        assert session.wait_for(lambda: heard[-1] == (0.0, 0.0), timeout=30), heard[-5:]
        assert "click here to drive" in element.inner_text()
        stopped = len(heard)
        session.wait_for(lambda: False, timeout=1.0)
        assert heard[stopped:] == [], "nothing more after the zero twist, though the key is still down"
    finally:
        page.keyboard.up("j")
