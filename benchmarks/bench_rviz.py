"""The notebook's RViz with a 720-beam scan at 20 Hz and a 50,000-point cloud at 5 Hz: the kernel's
processor time per message and the frames the browser draws per second, beside the raw message rate.

(a) In this process, no browser: the processor time of one scan update, from the message to the
bytes for the comm, for this view (course_lib.notebook.rviz: receive, draw in the fixed frame,
encode) and, when importable (``--with DIR``: a folder they were installed into with
``uv pip install --target DIR pythreejs k3d``), for pythreejs (a Points geometry's position and
colour attributes set) and k3d (a points object's positions and colours set). Widgets made outside
a kernel serialise their state as in one, and hand it to a comm that sends nothing.

(b) In JupyterLab in headless Chromium (the browser tests' set-up): a publisher process sends the
scans at 20 Hz, then the clouds at 5 Hz (with a transform each time); the notebook's kernel shows
them in RViz (Grid, TF and the stream's display; the cloud's orbit view spins, so that the browser
draws every animation frame as while a student turns it). Over a window: the messages a plain
subscriber in this process got (the raw rate), the drawings the browser has shown, the frames it
drew, the kernel's processor time per second and per message received, and one frame's render.

With ``--baseline DIR`` (a folder holding another copy of ``course_lib``, its bundle built), each
stream runs first with that copy in the notebook's kernel, then with this checkout's (``--rounds``
times, alternating: the machine's load changes by the minute), and the rows end with the ratios of
the medians and the goals: the cloud at 20 frames/s or more with 4.5 of its 5 drawings/s
shown, the still scan at 20 frames/s, and the kernel's time per cloud below the baseline's.

    .venv/bin/python benchmarks/bench_rviz.py [--seconds 10] [--updates 500] [--with /tmp/eval/k3d]
        [--parts b] [--streams cloud] [--baseline /tmp/before] [--rounds 2]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from importlib import metadata
from pathlib import Path
from types import SimpleNamespace

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))  # tests.support runs from the repository

BEAMS, RATE = 720, 20.0
CLOUD_POINTS, CLOUD_RATE = 50_000, 5.0

PUBLISHER = textwrap.dedent(f"""
    import array, math, sys
    import numpy as np
    import rclpy
    import rclpy.executors
    from geometry_msgs.msg import TransformStamped
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan, PointCloud2, PointField
    from course_lib.notebook.rviz.clouds import xyz_rgb_cloud_bytes
    rclpy.init()
    node = rclpy.create_node("bench_scanner")
    kind = sys.argv[1]
    scans = node.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
    points = node.create_publisher(PointCloud2, "points", qos_profile_sensor_data)
    tf = node.create_publisher(TransformStamped, "bench_tf", 10)
    rng = np.random.default_rng(0)
    xyz = rng.uniform(-3, 3, ({CLOUD_POINTS}, 3))
    fields, data, step = xyz_rgb_cloud_bytes(xyz, rng.integers(0, 256, ({CLOUD_POINTS}, 3)))
    record = np.frombuffer(data, np.uint8).copy().view(np.dtype({{"names": ["x", "y"], "formats": ["<f4"] * 2,
                                                                  "offsets": [0, 4], "itemsize": step}}))
    cloud = PointCloud2(height=1, width={CLOUD_POINTS}, point_step=step, row_step=step * {CLOUD_POINTS},
                        fields=[PointField(name=n, offset=o, datatype=t, count=1) for n, o, t in fields])
    cloud.header.frame_id = "laser"
    count = [0]
    def tick():
        count[0] += 1
        t = TransformStamped(child_frame_id="laser")
        t.header.frame_id = "odom"
        t.transform.translation.x, t.transform.rotation.w = 0.1 * math.sin(count[0] / 20), 1.0
        tf.publish(t)
        if kind == "cloud":  # the points turn about z (a turning sensor's), their colours stay
            c, s = math.cos(count[0] / 10), math.sin(count[0] / 10)
            record["x"], record["y"] = c * xyz[:, 0] - s * xyz[:, 1], s * xyz[:, 0] + c * xyz[:, 1]
            cloud.data = array.array("B", record.tobytes())
            points.publish(cloud)
            return
        msg = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / {BEAMS}, range_min=0.1, range_max=10.0)
        msg.header.frame_id = "laser"
        msg.ranges = (3.0 + np.sin(np.arange({BEAMS}) / 30 + count[0] / 10)).tolist()
        scans.publish(msg)
    node.create_timer(1 / float(sys.argv[2]), tick)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
""")

#: What part (b) shows: the stream, its rate, the display and the camera (the cloud's view spins,
#: so the browser draws a frame each animation frame, as while a student turns the view).
SCENARIOS = {
    "scan": (RATE, "LaserScan", "/scan", "sensor_msgs/msg/LaserScan", '{"mode": "orbit"}'),
    "scan, spinning": (RATE, "LaserScan", "/scan", "sensor_msgs/msg/LaserScan", '{"mode": "orbit", "spin": 2}'),
    "cloud": (CLOUD_RATE, "PointCloud2", "/points", "sensor_msgs/msg/PointCloud2", '{"mode": "orbit", "spin": 2}'),
}


def scan_message(seed: int) -> SimpleNamespace:
    ranges = 3.0 + np.sin(np.arange(BEAMS) / 30 + seed / 10)
    header = SimpleNamespace(frame_id="laser")
    return SimpleNamespace(header=header, ranges=ranges.tolist(), angle_min=-math.pi,
                           angle_increment=2 * math.pi / BEAMS, range_min=0.1, range_max=10.0)


def per_update(update, count: int) -> float:
    update(0)  # first use: imports and caches
    started = time.process_time()
    for i in range(1, count + 1):
        update(i)
    return (time.process_time() - started) / count


def in_process(count: int) -> list[tuple[str, float]]:
    from course_lib.notebook.rviz import displays, view
    from course_lib.notebook.rviz.transforms import TransformTree, matrix

    tree = TransformTree()
    tree.set("odom", "laser", matrix((0.1, 0, 0)))
    scan = displays.LaserScan("LaserScan")

    def course(i):
        scan.receive(scan_message(i), 0.0)
        view.encode({"LaserScan": scan.draw(tree, "odom", 0.0)}, i)

    rows = [("course_lib.notebook.rviz (anywidget + three.js)", per_update(course, count))]
    try:
        import pythreejs

        geometry = pythreejs.BufferGeometry(attributes={
            "position": pythreejs.BufferAttribute(np.zeros((BEAMS, 3), np.float32)),
            "color": pythreejs.BufferAttribute(np.zeros((BEAMS, 3), np.float32))})
        pythreejs.Points(geometry, pythreejs.PointsMaterial(vertexColors="VertexColors"))

        def three(i):
            points, ranges = _scan_in_odom(i)
            geometry.attributes["position"].array = points
            geometry.attributes["color"].array = (displays.geometry.rainbow(ranges)[:, :3] / 255).astype(np.float32)

        rows.append((f"pythreejs {metadata.version('pythreejs')}", per_update(three, count)))
    except ImportError:
        rows.append(("pythreejs (not importable: --with DIR)", float("nan")))
    try:
        import k3d

        cloud = k3d.points(np.zeros((BEAMS, 3), np.float32), point_size=0.05)
        plot = k3d.plot()
        plot += cloud

        def k3d_update(i):
            points, ranges = _scan_in_odom(i)
            rgb = displays.geometry.rainbow(ranges)[:, :3].astype(np.uint32)
            cloud.positions = points
            cloud.colors = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]

        rows.append((f"k3d {metadata.version('k3d')}", per_update(k3d_update, count)))
    except ImportError:
        rows.append(("k3d (not importable: --with DIR)", float("nan")))
    return rows


def _scan_in_odom(i):
    from course_lib.notebook.rviz import geometry
    from course_lib.notebook.rviz.transforms import matrix, transform_points

    msg = scan_message(i)
    points, ranges = geometry.scan_points(msg.ranges, msg.angle_min, msg.angle_increment, msg.range_min, msg.range_max)
    return transform_points(matrix((0.1, 0, 0)), points), ranges


NOTEBOOK = """from course_lib.notebook.rviz import RViz
view = RViz("odom", transform_topics=["/bench_tf"], seconds=3600, size=[800, 480], camera={camera})
view.add("Grid")
view.add("TF")
view.add("{display}", topic="{topic}")
view"""

STATE_JS = """() => { const el = document.querySelector('.rviz-view');
  return {seq: Number(el.dataset.seq || 0), received: Number(el.dataset.received || 0),
          frames: Number(el.dataset.frames || 0), renderMs: Number(el.dataset.renderMs || 0)}; }"""
#: The goals for this checkout's rows: (stream, measure, at least).
GOALS = (("scan", "frames", 20.0), ("cloud", "frames", 20.0), ("cloud", "shown", 0.9 * CLOUD_RATE))


@contextlib.contextmanager
def _environment(**values):
    """os.environ with these values (None: unset) inside, as it was after."""
    saved = {name: os.environ.get(name) for name in values}
    try:
        for name, value in values.items():
            os.environ.pop(name, None) if value is None else os.environ.__setitem__(name, value)
        yield
    finally:
        for name, value in saved.items():
            os.environ.pop(name, None) if value is None else os.environ.__setitem__(name, value)


def in_browser(seconds: float, scenario: str, code: Path | None = None) -> dict:
    """One stream shown in JupyterLab; `code`: a folder whose course_lib the notebook's kernel
    imports (PYTHONPATH) instead of this checkout's."""
    from course_lib.ros import message_yaml, rosenv, session
    from tests.support.browser import launched_chromium, running_jupyterlab
    from tests.support.browser_notebook import close_notebook, open_notebook, run_notebook, write_notebook

    rate, display, topic, msg_type, camera = SCENARIOS[scenario]

    with tempfile.TemporaryDirectory() as scratch, rosenv.reserve_domain_id() as reservation:
        root, state = Path(scratch, "root"), Path(scratch, "state")
        root.mkdir()
        write_notebook(root / "rviz.ipynb", [NOTEBOOK.format(camera=camera, display=display, topic=topic)])
        env = dict(rosenv.ros_environment(), ROS_DOMAIN_ID=str(reservation.domain_id))
        publisher = subprocess.Popen([sys.executable, "-c", PUBLISHER, scenario.split(",")[0], str(rate)], env=env,
                                     cwd=REPO)
        session.start(domain_id=reservation.domain_id)
        arrivals = []
        from rclpy.qos import qos_profile_sensor_data

        counter = session.tool_node().create_subscription(
            message_yaml.message_class(msg_type), topic,
            lambda msg: arrivals.append(time.monotonic()), qos_profile_sensor_data)
        try:
            with _environment(ROS_DOMAIN_ID=str(reservation.domain_id), PYTHONPATH=str(code) if code else None), \
                    running_jupyterlab(root, state) as lab, launched_chromium(Path(scratch, "chromium")) as browser:
                page = open_notebook(browser, lab, "rviz.ipynb")
                run_notebook(page, "rviz.ipynb", 1, 240)
                page.wait_for_function("() => { const c = document.querySelector('.rviz-view');"
                                       " return c && Number(c.dataset.seq || 0) > 10; }", timeout=120_000)
                kernel = next(p for p in lab.descendants() if "ipykernel_launcher" in " ".join(p.cmdline()))
                before, cpu0, t0, n0 = page.evaluate(STATE_JS), _cpu(kernel), time.monotonic(), len(arrivals)
                page.wait_for_timeout(seconds * 1000)
                after, cpu1, t1, n1 = page.evaluate(STATE_JS), _cpu(kernel), time.monotonic(), len(arrivals)
                close_notebook(page, lab, "rviz.ipynb")
        finally:
            session.tool_node().destroy_subscription(counter)
            publisher.send_signal(signal.SIGINT)
            publisher.wait(timeout=60)
            session.stop()
    window = t1 - t0
    return {"window": window, "raw": (n1 - n0) / window, "shown": (after["seq"] - before["seq"]) / window,
            "received": (after["received"] - before["received"]) / window,
            "frames": (after["frames"] - before["frames"]) / window, "kernel_cpu": (cpu1 - cpu0) / window,
            "per_message": (cpu1 - cpu0) / max(1, n1 - n0), "render_ms": after["renderMs"]}


def _cpu(process) -> float:
    times = process.cpu_times()
    return times.user + times.system


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="the browser part's window")
    parser.add_argument("--updates", type=int, default=500, help="scan updates per way in part (a)")
    parser.add_argument("--with", dest="extra", action="append", default=[],
                        help="a folder to import pythreejs or k3d from (uv pip install --target DIR ...)")
    parser.add_argument("--parts", default="ab", help="a: the kernel's time per scan in this process; b: the browser")
    parser.add_argument("--streams", default="scan,spinning,cloud", help="part b's streams, of scan,spinning,cloud")
    parser.add_argument("--rounds", type=int, default=1, help="runs of each stream (each code), alternating")
    parser.add_argument("--baseline", type=Path, help="a folder with another course_lib to run each stream with first")
    args = parser.parse_args(argv)
    sys.path[1:1] = args.extra
    if "a" in args.parts:
        print(f"(a) kernel processor time per {BEAMS}-beam scan update, {args.updates} updates each\n")
        print("| way | per scan | at 20 Hz, share of a core |\n|---|---:|---:|")
        for way, seconds in in_process(args.updates):
            print(f"| {way} | {seconds * 1e3:.2f} ms | {seconds * RATE:.1%} |")
    if "b" in args.parts:
        browser_part(args)


def browser_part(args) -> None:
    """Part (b)'s table, its ratios to the baseline and the goals."""
    print(f"\n(b) JupyterLab in headless Chromium, window {args.seconds:g} s each; the cloud's view spins; "
          f"load average {_load()}\n")
    print("| stream | code | raw messages/s (a plain subscriber) | drawings received/s | drawings shown/s | "
          "frames drawn/s | kernel CPU | kernel CPU per message | one frame's render | load average (1 min) |\n"
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    results = {}
    streams = {"scan": ("scan", f"{BEAMS}-beam LaserScan at {RATE:g} Hz"),
               "spinning": ("scan, spinning", f"{BEAMS}-beam LaserScan at {RATE:g} Hz, the view spinning"),
               "cloud": ("cloud", f"{CLOUD_POINTS:,}-point PointCloud2 (xyz, rgb) at {CLOUD_RATE:g} Hz")}
    for scenario, label in (streams[name] for name in args.streams.split(",")):
        for code in (([args.baseline] if args.baseline else []) + [None]) * args.rounds:
            result = in_browser(args.seconds, scenario, code)
            results.setdefault((scenario, code), []).append(result)
            print(f"| {label} | {code or 'this checkout'} | {result['raw']:.1f} | {result['received']:.1f} | "
                  f"{result['shown']:.1f} | {result['frames']:.1f} | {result['kernel_cpu']:.1%} of a core | "
                  f"{result['per_message'] * 1e3:.1f} ms | {result['render_ms']:.1f} ms | {os.getloadavg()[0]:.1f} |",
                  flush=True)
    print(f"\nload average at the end: {_load()}")
    if args.baseline:
        def ratio(scenario, measure):
            return _median(results[scenario, None], measure) / max(1e-9, _median(results[scenario, args.baseline],
                                                                               measure))
        print("\nthis checkout / baseline: " + "; ".join(
            f"{scenario}: frames {ratio(scenario, 'frames'):.2f}, shown {ratio(scenario, 'shown'):.2f}, "
            f"kernel per message {ratio(scenario, 'per_message'):.2f}"
            for scenario in dict.fromkeys(scenario for scenario, _ in results)))
        if ("cloud", None) in results:
            kernel = ratio("cloud", "per_message")
            print(f"goal: cloud kernel CPU per message {kernel:.2f} of the baseline's < 1: "
                  f"{'met' if kernel < 1 else 'NOT met'}")
    for scenario, measure, goal in GOALS:
        if (scenario, None) not in results:
            continue
        value = _median(results[scenario, None], measure)
        print(f"goal: {scenario} {measure} {value:.1f}/s >= {goal:g}/s: {'met' if value >= goal else 'NOT met'}")


def _median(rows: list[dict], measure: str) -> float:
    return float(np.median([row[measure] for row in rows]))


def _load() -> str:
    return ", ".join(f"{value:.1f}" for value in os.getloadavg())


if __name__ == "__main__":
    main()
