"""Frame rates of the vision pipelines next to the bare transport, measured side by side in one run.

Not a test: rates depend on the machine and on what else runs, so this prints numbers instead of
asserting them. Compare the ratios between rows measured at the same time.

    .venv/bin/python benchmarks/bench_vision.py [--seconds 5] [--rate 0] [--skip-node] [--parts abc]

(a) Brightness pipeline, per frame size (640x480, 1920x1080), one run of three processes over
    Fast DDS in a reserved ROS domain, all with sensor-data QoS:
    - a publisher sends one bgr8 Image over and over, as fast as it can (or --rate Hz);
    - a bare subscriber only counts the frames (and the UInt8 brightness messages);
    - a brightness subscriber converts each frame with msg_to_image, computes the mean of all
      bytes with numpy (as in the brightness assignment) and publishes it as std_msgs/UInt8.
    Both subscribers listen at the same time and count frames in the same wall-clock window;
    a subscriber that cannot keep up loses frames (best effort), so its rate is what it sustains.
    Also: the mean of one frame with a per-byte Python loop against numpy (in this process).
(b) Marker reader at 640x480: readmarker.crop.crop_pictures on rendered webcam frames and hard
    scenes (in this process), and the MarkerReader node end to end: a publisher sends webcam
    frames as fast as it can, the node crops them, a counter counts frames and cat crops.
(c) Frame delivery at 640x480 and 1920x1080, 30 Hz: the share of the frames sent that reach a
    best-effort subscriber in another process, with Fast DDS's defaults, with its LARGE_DATA
    builtin transports, and with the course's set-up (course_lib.ros.rosenv.large_data_environment),
    one after the other in the same run. Two senders: the camera node itself
    (course_lib.imaging.camera.WebcamNode, rendering every frame, so its rate is what the machine can
    draw) and a 30 Hz timer sending pre-rendered webcam frames. Frames are matched by their
    header stamps, counted from the first one that arrived.
(a) and (b) run with the course's set-up, as every process course_lib starts.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import shlex
import sys
import time
import timeit
from pathlib import Path

from bench_images import format_time  # the sibling script; benchmarks/ is on sys.path when run

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader's answer key (autograder/) runs from the repository, uninstalled
READMARKER = ROOT / "assignments" / "reference_ws" / "src" / "readmarker"
RESULT = "RESULT "
WARMUP = 6.0  # seconds for the processes to start and discover each other before the window


# ---- the roles run as processes ------------------------------------------------------------

def average_brightness(image):
    """The brightness assignment's definition, as the grader computes it (its answer key)."""
    from autograder.answers.brightness import average_brightness as answer

    return answer(image)


def msg_brightness(msg) -> int:
    """The brightness of an Image message the numpy way: msg_to_image, then the answer key."""
    from course_lib.imaging import images

    return average_brightness(images.msg_to_image(msg))


def python_loop_brightness(data) -> int:
    """The same mean with a Python loop over every byte: what numpy saves."""
    total = 0
    for value in data:
        total += value
    return total // len(data)


def run_role(args) -> int:
    """Run one process of a measurement: publisher, camera, counter, brightness or marker_reader."""
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import CompressedImage, Image
    from std_msgs.msg import UInt8

    from course_lib.imaging import images

    start, end = args.start, args.start + args.seconds
    counts: dict[str, int] = {}
    first: dict[str, float] = {}

    def counter(topic):
        counts[topic] = 0

        def count(_msg):
            now = time.time()
            first.setdefault(topic, now)
            if start <= now < end:
                counts[topic] += 1
        return count

    stamps: dict[str, list[int]] = {}

    def stamp_keeper(topic):
        """Keep the stamps (ns) of the messages stamped inside the window, whenever they arrive."""
        kept = stamps.setdefault(topic, [])

        def keep(msg):
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            if start <= stamp * 1e-9 < end:
                kept.append(stamp)
        return keep

    rclpy.init()
    node = Node(f"bench_{args.role}")
    stop = end + 0.3
    if args.role == "publisher":
        width, height = (int(v) for v in args.size.split("x"))
        frames = publisher_frames(args.frames, (width, height))
        messages = [images.image_to_msg(frame, "bgr8") for frame in frames]
        publisher = node.create_publisher(Image, "image", qos_profile_sensor_data)
        counts["sent"] = 0
        sent = [0]
        keep = stamp_keeper("sent")

        def publish():
            msg = messages[sent[0] % len(messages)]
            now = node.get_clock().now()
            msg.header.stamp = now.to_msg()
            publisher.publish(msg)
            sent[0] += 1
            if start <= now.nanoseconds * 1e-9 < end:
                counts["sent"] += 1
            keep(msg)
        # Period 0: the timer fires whenever the executor is free, i.e. as fast as possible.
        node.create_timer(1.0 / args.rate if args.rate > 0 else 0.0, publish)
        stop += 1.0  # keep sending until the subscribers have closed their windows
    elif args.role == "camera":
        from rclpy.parameter import Parameter

        from course_lib.imaging.camera import WebcamNode

        width, height = (int(v) for v in args.size.split("x"))
        node.destroy_node()
        node = WebcamNode(parameter_overrides=[Parameter("rate", value=args.rate), Parameter("width", value=width),
                                               Parameter("height", value=height)])
        # The camera node as it is; its publisher also keeps the stamp of each frame it sends.
        publish, keep = node._publisher.publish, stamp_keeper("sent")

        def publish_and_keep(msg):
            publish(msg)
            keep(msg)
        node._publisher.publish = publish_and_keep
        stop += 1.0
    elif args.role == "counter":
        node.create_subscription(Image, "image", counter("image"), qos_profile_sensor_data)
        node.create_subscription(UInt8, "brightness", counter("brightness"), qos_profile_sensor_data)
        node.create_subscription(CompressedImage, "cropped_img/cat", counter("cat"), 10)
    elif args.role == "receiver":
        node.create_subscription(Image, "image", stamp_keeper("image"), qos_profile_sensor_data)
    elif args.role == "brightness":
        out = node.create_publisher(UInt8, "brightness", qos_profile_sensor_data)
        count = counter("image")

        def on_image(msg):
            out.publish(UInt8(data=average_brightness(images.msg_to_image(msg))))
            count(msg)
        node.create_subscription(Image, "image", on_image, qos_profile_sensor_data)
    elif args.role == "marker_reader":
        sys.path.insert(0, str(READMARKER))
        from readmarker.marker_reader import MarkerReader

        count = counter("image")

        class CountingMarkerReader(MarkerReader):
            """The node as it is, counting each image after its work is done."""

            def on_image(self, msg):
                super().on_image(msg)
                count(msg)
        node.destroy_node()
        node = CountingMarkerReader()
    else:
        raise SystemExit(f"unknown role {args.role!r}")
    cpu_before = time.process_time()
    try:
        while time.time() < stop:
            rclpy.spin_once(node, timeout_sec=0.05)
    finally:
        cpu = time.process_time() - cpu_before
        node.destroy_node()
        rclpy.try_shutdown()
    late = [topic for topic, at in first.items() if at > start]
    print(RESULT + json.dumps({"role": args.role, "counts": counts, "stamps": stamps, "cpu_seconds": cpu,
                               "late": late}),
          flush=True)
    return 0


def publisher_frames(count, size):
    """Frames of the simulated webcam (what image_publisher sends), `count` of them 1/30 s apart."""
    from course_lib.imaging import scenes

    path = scenes.CameraPath(seed=0, size=size)
    return [path.scene_at(i / 30).frame for i in range(count)]


# ---- the measurements -----------------------------------------------------------------------

def measure(roles, seconds, domain_id, *, size, frames=1, rate=0.0, env=None):
    """Start one process per role, all counting in the same window; their results by role.

    env: variables for the processes on top of this one's (None removes one), as NodeProcess takes.
    """
    from course_lib.ros import processes

    start = time.time() + WARMUP
    running = []
    try:
        for role in roles:
            command = [sys.executable, str(Path(__file__).resolve()), "--role", role, "--start", repr(start),
                       "--seconds", str(seconds), "--size", size, "--frames", str(frames),
                       "--rate", str(rate)]
            running.append(processes.NodeProcess(command, name=f"bench-{role}", domain_id=domain_id,
                                                 env=env).start())
        results = {}
        for process in running:
            process.wait(timeout=WARMUP + seconds + 60)
            line = next((line for line in process.log.splitlines() if line.startswith(RESULT)), None)
            if line is None:
                raise RuntimeError(f"{process.name} gave no result ({process.describe_exit()}):\n"
                                   f"{process.log_tail()}")
            result = json.loads(line[len(RESULT):])
            if result["late"]:
                print(f"warning: {process.name} saw its first {result['late']} message after the window "
                      f"opened; raise WARMUP", file=sys.stderr)
            results[result["role"]] = result
        return results
    finally:
        for process in running:
            process.stop()


def each(function, frames: list) -> list:
    """function(frame) for each of `frames`: what one timing of a per-frame step runs."""
    return [function(frame) for frame in frames]


def best_seconds(statement, repeat: int, number: int | None = None) -> float:
    timer = timeit.Timer(statement)
    if number is None:
        number = max(1, timer.autorange()[0])
    return min(timer.repeat(repeat=repeat, number=number)) / number


def measure_brightness(args, domain_id) -> list:
    """Part (a): the brightness pipeline against the bare transport, and numpy against a loop."""
    from course_lib.imaging import images

    table = []
    for width, height in ((640, 480), (1920, 1080)):
        size = f"{width}x{height}"
        print(f"(a) brightness pipeline at {size} ...", file=sys.stderr)
        results = measure(["publisher", "counter", "brightness"], args.seconds, domain_id, size=size,
                          rate=args.rate)
        sent = results["publisher"]["counts"]["sent"] / args.seconds
        bare = results["counter"]["counts"]["image"] / args.seconds
        bright = results["brightness"]["counts"]["image"] / args.seconds
        outputs = results["counter"]["counts"]["brightness"] / args.seconds
        table += [
            ("a", size, "publisher: Image messages sent", f"{sent:.1f} /s", ""),
            ("a", size, "bare subscriber: frames received", f"{bare:.1f} /s", "1 (reference)"),
            ("a", size, "brightness subscriber: msg_to_image + numpy mean + UInt8", f"{bright:.1f} /s",
             f"{bright / bare:.2f}" if bare else "n/a"),
            ("a", size, "UInt8 brightness messages received", f"{outputs:.1f} /s", ""),
        ]
        frame = publisher_frames(1, (width, height))[0]
        msg = images.image_to_msg(frame)
        assert python_loop_brightness(msg.data) == msg_brightness(msg)
        loop = best_seconds(functools.partial(python_loop_brightness, msg.data), 1 if width > 1000 else 3, number=1)
        vectorised = best_seconds(functools.partial(msg_brightness, msg), 5)
        table += [
            ("a", size, "mean of one frame: numpy (msg_to_image + sum)", format_time(vectorised),
             "1 (reference)"),
            ("a", size, "mean of one frame: Python loop over msg.data bytes", format_time(loop),
             f"{loop / vectorised:.0f}× slower"),
        ]
    return table


def measure_marker_reader(args, domain_id) -> list:
    """Part (b): crop_pictures in this process, and the marker_reader node end to end."""
    from course_lib.imaging import scenes

    sys.path.insert(0, str(READMARKER))
    from readmarker.crop import crop_pictures, find_markers

    table = []
    print("(b) crop_pictures at 640x480 ...", file=sys.stderr)
    webcam = publisher_frames(30, (640, 480))
    hard = [scenes.render_scene(seed, difficulty="hard").frame for seed in range(30)]
    for label, frames in (("webcam frames (CameraPath)", webcam), ("hard scenes", hard)):
        full = best_seconds(functools.partial(each, crop_pictures, frames), 3, number=1) / len(frames)
        detect = best_seconds(functools.partial(each, find_markers, frames), 3, number=1) / len(frames)
        table += [
            ("b", "640x480", f"crop_pictures, {label}", f"{1 / full:.1f} frames/s", f"{format_time(full)}"),
            ("b", "640x480", f"  of which find_markers (ArUco detection), {label}", f"{1 / detect:.1f} frames/s",
             f"{detect / full:.0%} of the time"),
        ]
    if not args.skip_node:
        print("(b) marker_reader node end to end ...", file=sys.stderr)
        results = measure(["publisher", "counter", "marker_reader"], args.seconds, domain_id,
                          size="640x480", frames=30, rate=args.rate)
        bare = results["counter"]["counts"]["image"] / args.seconds
        processed = results["marker_reader"]["counts"]["image"] / args.seconds
        cats = results["counter"]["counts"]["cat"] / args.seconds
        table += [
            ("b", "640x480", "node: webcam frames reaching a bare subscriber", f"{bare:.1f} /s",
             "1 (reference)"),
            ("b", "640x480", "node: frames marker_reader processed", f"{processed:.1f} /s",
             f"{processed / bare:.2f}" if bare else "n/a"),
            ("b", "640x480", "node: cat crops received (PNG CompressedImage)", f"{cats:.1f} /s",
             f"{cats / bare:.2f}" if bare else "n/a"),
        ]
    return table


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="length of each counting window")
    parser.add_argument("--rate", type=float, default=0.0,
                        help="frames per second the publisher sends; 0 (default): as fast as it can")
    parser.add_argument("--skip-node", action="store_true", help="leave out the marker_reader node run")
    parser.add_argument("--parts", default="abc", help="which parts to run, e.g. c (default: abc)")
    parser.add_argument("--role", help=argparse.SUPPRESS)
    parser.add_argument("--start", type=float, help=argparse.SUPPRESS)
    parser.add_argument("--size", default="640x480", help=argparse.SUPPRESS)
    parser.add_argument("--frames", type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.role:
        return run_role(args)

    import numpy as np
    from sensor_msgs.msg import Image  # noqa: F401  (fail early when ROS is missing)

    from course_lib.ros import rosenv

    table = []  # (part, size, what, value, ratio)
    with rosenv.reserve_domain_id() as reservation:
        if "a" in args.parts:
            table += measure_brightness(args, reservation.domain_id)
        if "b" in args.parts:
            table += measure_marker_reader(args, reservation.domain_id)
        if "c" in args.parts:
            delivery = measure_delivery(args.seconds, reservation.domain_id)

    command = " ".join(shlex.quote(part) for part in [os.path.relpath(sys.executable), *sys.argv])
    print(f"Command: `{command}`")
    print(f"Python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}, "
          f"{os.cpu_count()} cores, RMW {os.environ.get('RMW_IMPLEMENTATION', 'default (Fast DDS)')}, "
          f"windows of {args.seconds:g} s, (a) and (b) publisher rate "
          f"{f'{args.rate:g} Hz' if args.rate > 0 else 'as fast as possible'}")
    if table:
        print()
        print("| part | frames | measurement | value | ratio |")
        print("|---|---|---|---:|---:|")
        for part, size, what, value, ratio in table:
            print(f"| {part} | {size} | {what} | {value} | {ratio} |")
    if "c" in args.parts:
        print()
        print(f"(c) frames delivered to a best-effort subscriber in another process, 30 Hz; course set-up: "
              f"{delivery['setup']}; LARGE_DATA: "
              f"FASTDDS_BUILTIN_TRANSPORTS={SETUPS['LARGE_DATA']['FASTDDS_BUILTIN_TRANSPORTS']}")
        print()
        print(f"| frames | sender | sent ({' / '.join(SETUPS)}) | "
              + " | ".join(f"{name}: received of sent" for name in SETUPS) + " |")
        print("|---|---|---:|" + "---:|" * len(SETUPS))
        for row in delivery["rows"]:
            print("| " + " | ".join(row) + " |")
    return 0


#: The Fast DDS set-ups part (c) compares, as environment changes for the processes: the defaults
#: (asked for by name, a choice the course keeps), the LARGE_DATA builtin transports (TCP for
#: data, with messages and socket buffers big enough for a 1080p frame), and the course's profile.
SETUPS = {
    "default Fast DDS": {"FASTRTPS_DEFAULT_PROFILES_FILE": None, "FASTDDS_BUILTIN_TRANSPORTS": "DEFAULT"},
    "LARGE_DATA": {"FASTRTPS_DEFAULT_PROFILES_FILE": None,
                   "FASTDDS_BUILTIN_TRANSPORTS": "LARGE_DATA?max_msg_size=8MB&sockets_size=8MB&non_blocking=true"},
    "course set-up": {"FASTRTPS_DEFAULT_PROFILES_FILE": None, "FASTDDS_BUILTIN_TRANSPORTS": None},
}


def measure_delivery(seconds, domain_id) -> dict:
    """Part (c): frames sent and received at 30 Hz per size and sender, default against course set-up.

    Frames are matched by their stamps, counted from the first one that arrived (a receiver that
    discovered the sender late loses nothing to this measurement).
    """
    from course_lib.ros import rosenv

    chosen = rosenv.large_data_environment({})
    setup = f"FASTRTPS_DEFAULT_PROFILES_FILE={os.path.relpath(chosen['FASTRTPS_DEFAULT_PROFILES_FILE'])}" \
        if chosen else "none (/dev/shm is too small: the course keeps the defaults)"
    rows = []
    for size in ("640x480", "1920x1080"):
        for sender, label in (("camera", "camera node (course_lib.imaging.camera, rate 30)"),
                              ("publisher", "30 Hz timer, pre-rendered frames")):
            row = [size, label]
            rates = []
            for name, env in SETUPS.items():
                print(f"(c) delivery at {size}, {sender}, {name} ...", file=sys.stderr)
                results = measure([sender, "receiver"], seconds, domain_id, size=size, frames=2, rate=30.0,
                                  env=env)
                sent = results[sender]["stamps"]["sent"]
                received = set(results["receiver"]["stamps"]["image"])
                rates.append(f"{len(sent) / seconds:.1f}")
                counted = [stamp for stamp in sent if stamp >= min(received, default=0)]
                arrived = sum(stamp in received for stamp in counted)
                row.append(f"{arrived} of {len(counted)} ({arrived / len(counted):.0%})" if counted else "none sent")
            rows.append(row[:2] + [" / ".join(rates) + " /s"] + row[2:])
    return {"setup": setup, "rows": rows}



if __name__ == "__main__":
    sys.exit(main())
