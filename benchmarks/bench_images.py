"""How fast course_lib.imaging.images converts, next to the obvious alternatives, measured in one run.

Not a test: timings depend on the machine, so this prints numbers instead of asserting them.
Ratios between rows measured side by side in the same run are what to compare.

    .venv/bin/python benchmarks/bench_images.py [--repeat 7] [--check-fields]

Rows, per image size (bgr8):

- send, image_to_msg: numpy -> Image through course_lib.imaging.images;
- send, raw tobytes: ``msg.data = arr.tobytes()``, the shortest correct hand-written way;
- send, naive list: ``msg.data = arr.ravel().tolist()``, timed on a 160x120 image and scaled by
  the pixel count (it is linear in the pixels, and timing it at 1080p would take seconds);
- receive, msg_to_image: Image -> numpy through course_lib.imaging.images;
- receive, raw frombuffer: ``np.frombuffer(msg.data, np.uint8).reshape(h, w, 3)``.
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import shlex
import sys
import timeit


def best_seconds(statement, repeat: int) -> float:
    """The fastest of `repeat` timings of statement(), each averaged over enough calls for 0.2 s."""
    timer = timeit.Timer(statement)
    number, _ = timer.autorange()
    number = max(1, number)
    return min(timer.repeat(repeat=repeat, number=number)) / number


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="timings per row; the fastest counts")
    parser.add_argument("--check-fields", action="store_true",
                        help="run with ROS_PYTHON_CHECK_FIELDS=1 (rclpy validates every field it is given)")
    args = parser.parse_args(argv)
    if args.check_fields:
        os.environ["ROS_PYTHON_CHECK_FIELDS"] = "1"  # read when sensor_msgs is first imported

    import numpy as np
    from sensor_msgs.msg import Image

    from course_lib.imaging.images import image_to_msg, msg_to_image

    rng = np.random.default_rng(0)
    small = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)

    def send_list(image):
        msg = Image(height=image.shape[0], width=image.shape[1], encoding="bgr8", step=image.shape[1] * 3)
        msg.data = image.ravel().tolist()
        return msg

    def send_raw(image):
        msg = Image(height=image.shape[0], width=image.shape[1], encoding="bgr8", step=image.shape[1] * 3)
        msg.data = image.tobytes()
        return msg

    def receive_raw(msg, height, width):
        return np.frombuffer(msg.data, np.uint8).reshape(height, width, 3)

    list_small = best_seconds(lambda: send_list(small), args.repeat)

    rows = []
    for width, height in ((640, 480), (1920, 1080)):
        image = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
        msg = image_to_msg(image)
        assert np.array_equal(msg_to_image(msg), image)
        assert send_raw(image).data == msg.data
        scale = image.size / small.size
        send_ours = best_seconds(functools.partial(image_to_msg, image), args.repeat)
        send_bytes = best_seconds(functools.partial(send_raw, image), args.repeat)
        recv_ours = best_seconds(functools.partial(msg_to_image, msg), args.repeat)
        recv_raw = best_seconds(functools.partial(receive_raw, msg, height, width), args.repeat)
        size = f"{width}x{height}"
        rows += [
            (size, "send: image_to_msg", send_ours, send_ours / send_bytes),
            (size, "send: msg.data = arr.tobytes()", send_bytes, 1.0),
            (size, "send: msg.data = arr.ravel().tolist() (scaled from 160x120)", list_small * scale,
             list_small * scale / send_bytes),
            (size, "receive: msg_to_image", recv_ours, recv_ours / recv_raw),
            (size, "receive: np.frombuffer(...).reshape(...)", recv_raw, 1.0),
        ]

    command = " ".join(shlex.quote(part) for part in [os.path.relpath(sys.executable), *sys.argv])
    print(f"Command: `{command}`")
    print(f"Python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}, "
          f"{os.cpu_count()} cores, ROS_PYTHON_CHECK_FIELDS={os.environ.get('ROS_PYTHON_CHECK_FIELDS', '')!r}, "
          f"best of {args.repeat}")
    print()
    print("| image | conversion | time per image | ratio to the raw way |")
    print("|---|---|---:|---:|")
    for size, name, seconds, ratio in rows:
        print(f"| {size} | {name} | {format_time(seconds)} | {ratio:.3g}× |")
    return 0


def format_time(seconds: float) -> str:
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds * 1e6:.1f} µs"


if __name__ == "__main__":
    sys.exit(main())
