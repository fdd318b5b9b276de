"""The notebook's RViz in JupyterLab in headless Chromium: a marker at a known pose, a scan of a
known wall and a TF frame land at the expected pixels of the canvas, with the camera fixed; a click
with Publish Point and a drag with 2D Goal Pose publish the point and pose under the mouse; after a
kernel restart and a re-run cell there is one view, one node with one subscription, still drawing.

The notebook's kernel publishes (a node in its own session, 5 Hz) a scan of a wall 2 m ahead of
the laser, the laser 1 m along x of odom (as geometry_msgs/TransformStamped on /rviz_test_tf:
tf2_msgs is not on PyPI yet), a red cube marker at (-2, 1.5), and a blue PointCloud2 square in the
laser's frame at (0, -2) (the browser places it by its pose: odom's (1, -2)). The view looks straight down
(RViz's TopDownOrtho) at 50 pixels per metre on a 640×480 canvas: odom's (x, y) is drawn at
pixel (320 + 50 x, 240 - 50 y).
"""

from pathlib import Path

import cv2
import numpy as np
import pytest
from support.browser import running_jupyterlab
from support.browser_notebook import (
    SCREENSHOTS,
    close_notebook,
    code_cell_count,
    open_notebook,
    run_notebook,
    write_notebook,
)

from course_lib.notebook.rviz import view as rviz_view

pytestmark = [pytest.mark.browser, pytest.mark.skipif(not rviz_view.BUNDLE.exists(),
                                                      reason=f"no {rviz_view.BUNDLE}: {rviz_view.BUNDLE_FIX}")]

WIDTH, HEIGHT, SCALE = 640, 480, 50
BACKGROUND = (48, 48, 48)
NOTEBOOK_CELLS = [
    """import math
import numpy as np
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from visualization_msgs.msg import Marker
from course_lib.notebook.rviz.clouds import xyz_rgb_cloud_bytes
from course_lib.ros import session

class Scene(Node):
    def __init__(self):
        super().__init__("rviz_scene")
        self.scan = self.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
        self.marker = self.create_publisher(Marker, "visualization_marker", 10)
        self.tf = self.create_publisher(TransformStamped, "rviz_test_tf", 10)
        self.points = self.create_publisher(PointCloud2, "points", qos_profile_sensor_data)
        square = np.stack(np.meshgrid(np.linspace(-0.1, 0.1, 5), np.linspace(-2.1, -1.9, 5), [0.0]), -1).reshape(-1, 3)
        fields, data, step = xyz_rgb_cloud_bytes(square, np.tile([[0, 0, 255]], (25, 1)))
        self.cloud = PointCloud2(height=1, width=25, point_step=step, row_step=25 * step, data=data,
                                 fields=[PointField(name=n, offset=o, datatype=t, count=1) for n, o, t in fields])
        self.cloud.header.frame_id = "laser"
        self.create_timer(0.2, self.tick)

    def tick(self):
        tf = TransformStamped(child_frame_id="laser")
        tf.header.frame_id = "odom"
        tf.transform.translation.x, tf.transform.rotation.w = 1.0, 1.0
        self.tf.publish(tf)
        scan = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / 720, range_min=0.1, range_max=10.0)
        scan.header.frame_id = "laser"
        angles = scan.angle_min + scan.angle_increment * np.arange(720)
        scan.ranges = np.where(np.abs(angles) < math.radians(40), 2.0 / np.cos(angles), np.inf).tolist()
        self.scan.publish(scan)
        cube = Marker(type=Marker.CUBE, ns="test", id=1)
        cube.header.frame_id = "odom"
        cube.pose.position.x, cube.pose.position.y, cube.pose.orientation.w = -2.0, 1.5, 1.0
        cube.scale.x = cube.scale.y = cube.scale.z = 0.6
        cube.color.r, cube.color.a = 1.0, 1.0
        self.marker.publish(cube)
        self.points.publish(self.cloud)

session.start()
scene = session.add_node(Scene())""",
    f"""from course_lib.notebook.rviz import RViz
view = RViz("odom", transform_topics=["/rviz_test_tf"], seconds=300, size=[{WIDTH}, {HEIGHT}],
            camera={{"mode": "top", "target": [0, 0, 0], "scale": {SCALE}}})
view.add("TF", length=1.0, names=False)
view.add("LaserScan", topic="/scan", size=0.1)
view.add("Marker")
view.add("PointCloud2", topic="/points", size=0.1)
view""",
]

# The statuses once the scan and the marker are drawn in odom and the newest drawing is on screen
# (a drawing exactly as the last one is not sent again, so one drawing may be all there is).
DRAWN_JS = """() => { const lines = [...document.querySelectorAll('.rviz-display')].map(e => e.innerText);
  const el = document.querySelector('.rviz-view');
  return el && Number(el.dataset.seq || 0) >= 1 && el.dataset.seq === el.dataset.received
    && lines.some(l => l.includes('points of 720 beams'))
    && lines.some(l => l.includes('1 markers (test: 1)'))
    && lines.some(l => l.includes('PointCloud2 (/points): 25 points')) ? lines : null; }"""


def pixel(x: float, y: float) -> tuple[int, int]:
    """(column, row) of odom's (x, y) on the canvas."""
    return round(WIDTH / 2 + SCALE * x), round(HEIGHT / 2 - SCALE * y)


def colours_near(picture, x, y, radius=2):
    column, row = pixel(x, y)
    return picture[row - radius:row + radius + 1, column - radius:column + radius + 1].reshape(-1, 3)


def is_background(rgb) -> bool:
    return bool(np.all(np.abs(np.asarray(rgb, int) - BACKGROUND) <= 3))


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    root = tmp_path_factory.mktemp("rviz-lab")
    write_notebook(root / "rviz.ipynb", NOTEBOOK_CELLS)
    with running_jupyterlab(root, tmp_path_factory.mktemp("rviz-lab-state")) as server:
        yield server


@pytest.fixture(scope="module")
def shown(browser, lab):
    """The notebook run in JupyterLab, its view drawn: (page, the statuses)."""
    path = "rviz.ipynb"
    page = open_notebook(browser, lab, path)
    try:
        run = run_notebook(page, path, code_cell_count(lab.root_dir / path), 240)
        assert run.problems() == [], run.problems()
        statuses = page.wait_for_function(DRAWN_JS, timeout=60_000, polling=100).json_value()
        yield page, statuses
    finally:
        close_notebook(page, lab, path)


def canvas_box(page) -> dict:
    """The canvas's box on the page; it may start at a fractional pixel, so rounded."""
    canvas = page.locator(".rviz-canvas")
    canvas.scroll_into_view_if_needed()
    box = canvas.bounding_box()
    return {"x": round(box["x"]), "y": round(box["y"]), "width": WIDTH, "height": HEIGHT}


@pytest.mark.timeout(400)
def test_a_marker_a_wall_scan_a_tf_frame_and_a_cloud_are_drawn_at_their_pixels(shown):
    page, statuses = shown
    shot = page.screenshot(path=str(_target()), clip=canvas_box(page))
    picture = cv2.cvtColor(cv2.imdecode(np.frombuffer(shot, np.uint8), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    assert picture.shape == (HEIGHT, WIDTH, 3), picture.shape
    assert "TF: 2 frames" in " ".join(statuses), statuses
    # The cube: red (lit), 0.6 m wide around (-2, 1.5); background 0.5 m beside it.
    r, g, b = colours_near(picture, -2.0, 1.5).mean(axis=0)
    assert r > 120 and g < 60 and b < 60, (r, g, b)
    assert all(is_background(c) for c in colours_near(picture, -2.5, 1.5, radius=1))
    # The wall: x = 3 in odom (the laser at x = 1, the wall 2 m ahead), from y = -1.6 to 1.6.
    for y in (-1.5, -0.5, 0.5, 1.5):
        assert not all(is_background(c) for c in colours_near(picture, 3.0, y)), y
        assert all(is_background(c) for c in colours_near(picture, 3.4, y)), y
    # The laser frame's y axis: green, 1 m long from (1, 0) up to (1, 1).
    green = colours_near(picture, 1.0, 0.5)
    assert any(c[1] > 200 and c[0] < 60 and c[2] < 60 for c in green), green
    # The cloud's square: blue, 0.2 m wide around the laser frame's (0, -2), odom's (1, -2).
    r, g, b = colours_near(picture, 1.0, -2.0).mean(axis=0)
    assert b > 200 and r < 60 and g < 60, (r, g, b)
    assert all(is_background(c) for c in colours_near(picture, 0.0, -2.0, radius=1))


@pytest.mark.timeout(200)
def test_a_click_publishes_the_point_and_a_drag_the_goal_pose_under_the_mouse(shown):
    """Publish Point at the pixel of odom's (1.5, -1) and a 2D Goal Pose dragged from (-1, -1)
    towards +y reach a subscriber in this process (real DDS) in the fixed frame."""
    from geometry_msgs.msg import PointStamped, PoseStamped

    from course_lib.ros import session

    page, _ = shown
    session.start()
    node = session.tool_node()
    got = {}
    subscriptions = [node.create_subscription(PointStamped, "/clicked_point", lambda m: got.setdefault("point", m), 10),
                     node.create_subscription(PoseStamped, "/goal_pose", lambda m: got.setdefault("goal", m), 10)]
    try:
        box = canvas_box(page)

        def use_tools():  # again until both arrive: the view's publishers are made at first use
            page.get_by_role("button", name="Publish Point").click()
            column, row = pixel(1.5, -1.0)
            page.mouse.click(box["x"] + column, box["y"] + row)
            page.get_by_role("button", name="2D Goal Pose").click()
            page.mouse.move(box["x"] + pixel(-1, -1)[0], box["y"] + pixel(-1, -1)[1])
            page.mouse.down()
            page.mouse.move(box["x"] + pixel(-1, 0)[0], box["y"] + pixel(-1, 0)[1], steps=4)
            page.mouse.up()
            page.wait_for_timeout(200)
            return len(got) == 2
        assert session.wait_for(use_tools, timeout=60)
    finally:
        for subscription in subscriptions:
            node.destroy_subscription(subscription)
    point, goal = got["point"], got["goal"]
    assert point.header.frame_id == "odom" and goal.header.frame_id == "odom"
    assert np.allclose([point.point.x, point.point.y, point.point.z], [1.5, -1.0, 0.0], atol=0.03)
    assert np.allclose([goal.pose.position.x, goal.pose.position.y], [-1.0, -1.0], atol=0.03)
    assert np.allclose([goal.pose.orientation.z, goal.pose.orientation.w], [0.5 ** 0.5] * 2, atol=0.01)


RESTART_JS = "() => window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.restart()"
RUN_VIEW_CELL_JS = """() => { const panel = window.jupyterapp.shell.currentWidget;
  panel.content.activeCellIndex = 1; return window.jupyterapp.commands.execute('notebook:run-cell'); }"""
VIEW_PROMPT_JS = """(n) => { const prompts = [...document.querySelectorAll('.jp-NotebookPanel:not(.lm-mod-hidden)'
  + ' .jp-CodeCell .jp-InputArea-prompt')].map(p => p.textContent);
  return prompts[1] === `[${n}]:` && !prompts.some(p => p.includes('*')); }"""
# The one view on the page has shown `after` drawings or more, the newest it received.
DRAWING_JS = """(after) => { const views = document.querySelectorAll('.rviz-view');
  if (views.length !== 1) return null;
  const el = views[0], seq = Number(el.dataset.seq || 0);
  return seq >= after && el.dataset.seq === el.dataset.received ? seq : null; }"""


@pytest.mark.timeout(400)
def test_the_view_keeps_drawing_after_a_kernel_restart_and_a_re_run_cell_with_one_node(shown, lab):
    """Restart the kernel, run all, run the view's cell again: one view on the page, one node
    _rviz_rviz in the ROS graph with one subscription to /scan, and a new marker drawn at its pixels."""
    from course_lib.ros import session

    page, _ = shown
    page.evaluate(RESTART_JS)
    run = run_notebook(page, "rviz.ipynb", len(NOTEBOOK_CELLS), 240)
    assert run.problems() == [], run.problems()
    page.evaluate(RUN_VIEW_CELL_JS)
    page.wait_for_function(VIEW_PROMPT_JS, arg=3, timeout=60_000, polling=100)
    session.start()
    node = session.tool_node()

    def views_in_graph():
        nodes = [name for name, _ in node.get_node_names_and_namespaces() if name == "_rviz_rviz"]
        scans = [info for info in node.get_subscriptions_info_by_topic("/scan") if info.node_name == "_rviz_rviz"]
        return len(nodes), len(scans)
    # The restarted kernel's participant may take a moment to leave the graph.
    session.wait_for(lambda: views_in_graph() == (1, 1), timeout=60)
    if views_in_graph() != (1, 1):  # which kernels still run, and where they are
        kernels = [(process.pid, " ".join(process.cmdline())[-60:]) for process in lab.descendants()
                   if "ipykernel" in " ".join(process.cmdline())]
        raise AssertionError(f"(nodes _rviz_rviz, their subscriptions to /scan) = {views_in_graph()}; the "
                             f"server's kernels {kernels}\n{lab.kernel_stacks()}")
    # A new message reaches the new view: a green cube at (2, -2), from this process.
    from visualization_msgs.msg import Marker

    publisher = node.create_publisher(Marker, "/visualization_marker", 10)
    cube = Marker(type=Marker.CUBE, ns="restart", id=1)
    cube.header.frame_id = "odom"
    cube.pose.position.x, cube.pose.position.y, cube.pose.orientation.w = 2.0, -2.0, 1.0
    cube.scale.x = cube.scale.y = cube.scale.z = 0.6
    cube.color.g, cube.color.a = 1.0, 1.0
    try:
        def drawn():  # again until it arrives: the view's subscription may not have matched yet
            publisher.publish(cube)
            return page.evaluate(DRAWING_JS, 1) is not None and page.locator(".rviz-display").filter(
                has_text="restart: 1").count() == 1
        assert session.wait_for(drawn, timeout=60, poll=0.2), page.locator(".rviz-display").all_inner_texts()
    finally:
        node.destroy_publisher(publisher)
    shot = page.screenshot(clip=canvas_box(page))
    picture = cv2.cvtColor(cv2.imdecode(np.frombuffer(shot, np.uint8), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    r, g, b = colours_near(picture, 2.0, -2.0).mean(axis=0)
    assert g > 120 and r < 60 and b < 60, (r, g, b)
    assert page.locator(".rviz-display").filter(has_text="points of 720 beams").count() == 1


def _target() -> Path:
    target = SCREENSHOTS / "rviz_top_down.png"
    target.parent.mkdir(parents=True, exist_ok=True)
    return target
