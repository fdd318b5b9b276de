"""Camera frames recorded by the course's ``ros2 bag record``: frames sent against frames in the bag.

Not a test: it prints a table. A sender process publishes N 640x480 rgb8 sensor_msgs/Image frames
at 30 Hz on /bench_frames, each with its sequence number in header.stamp.sec, once ``ros2 bag
record /bench_frames`` (a process of its own, with the course's Fast DDS set-up for large data)
has subscribed; the recorder is stopped with Ctrl-C after the last frame (reliable: after the
recorder acknowledged it), and the bag's frames are counted and their numbers checked. Both QoS
the course uses: the camera's (reliable, depth 10) and the sensor-data profile (best effort, 5).

    .venv/bin/python benchmarks/bench_bag_record.py [--frames 300] [--rounds 1]
"""

from __future__ import annotations

import argparse
import os
import platform
import signal
import struct
import sys
import tempfile
from pathlib import Path

from course_lib.ros import bag_files, processes, rosenv

#: The sender: publishes the frames once the recorder has matched, then says how many it sent.
SENDER = r"""
import sys, time
import numpy as np
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import Image

frames, qos_name = int(sys.argv[1]), sys.argv[2]
rclpy.init()
node = Node("bench_frame_sender")
qos = qos_profile_sensor_data if qos_name == "sensor_data" else QoSProfile(depth=10)
publisher = node.create_publisher(Image, "bench_frames", qos)
image = Image(height=480, width=640, encoding="rgb8", step=640 * 3)
image.data = np.random.default_rng(0).integers(0, 256, 480 * 640 * 3, dtype=np.uint8).tobytes()
while publisher.get_subscription_count() < 1:
    rclpy.spin_once(node, timeout_sec=0.05)
sent = [0]

def tick():
    if sent[0] < frames:
        image.header.stamp.sec = sent[0]
        publisher.publish(image)
        sent[0] += 1

node.create_timer(1 / 30, tick)
while sent[0] < frames:
    rclpy.spin_once(node, timeout_sec=0.1)
publisher.wait_for_all_acked(Duration(seconds=10))
print(f"sent {sent[0]}", flush=True)
while True:
    rclpy.spin_once(node, timeout_sec=1.0)
"""


def sequence_numbers(bag: Path) -> list[int]:
    """header.stamp.sec of each frame in the bag (CDR: 4 bytes of encapsulation, then the int32)."""
    return [struct.unpack_from("<i", data, 4)[0]
            for _, data, _ in bag_files.read_messages(bag_files.storage_files(bag))]


def one_round(frames: int, qos: str, folder: Path, sender_script: Path) -> dict:
    ros2 = str(Path(sys.executable).parent / "ros2")
    bag = folder / f"bag_{qos}"
    with rosenv.reserve_domain_id() as reservation:
        env = {"COURSE_LIB_UNDER_TEST": None}
        recorder = processes.NodeProcess([ros2, "bag", "record", "/bench_frames", "-o", str(bag)],
                                         domain_id=reservation.domain_id, env=env).start()
        sender = processes.NodeProcess([sys.executable, str(sender_script), str(frames), qos],
                                       domain_id=reservation.domain_id, env=env).start()
        try:
            recorder.wait_for_output("Recording...", timeout=120)
            sender.wait_for_output("sent ", timeout=120 + frames / 10)
            cpu = recorder.cpu_seconds()
            recorder.send_signal(signal.SIGINT)
            code = recorder.wait(timeout=120)
        finally:
            sender.stop()
            recorder.stop()
    numbers = sequence_numbers(bag)
    return {"qos": qos, "sent": frames, "recorded": len(numbers), "distinct": len(set(numbers)),
            "in order": numbers == sorted(numbers), "exit code": code, "recorder cpu s": cpu}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=300, help="frames per round (default 300: 10 s)")
    parser.add_argument("--rounds", type=int, default=1, help="rounds of each QoS (default 1)")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    folder = Path(tempfile.mkdtemp(prefix="bench_bag_record_"))
    sender_script = folder / "sender.py"
    sender_script.write_text(SENDER)
    rows = [one_round(args.frames, qos, folder / f"round{index}", sender_script)
            for index in range(args.rounds) for qos in ("reliable", "sensor_data")]
    print(f"Python {platform.python_version()}, {platform.machine()}, {os.cpu_count()} cores, "
          f"load average before: {load:.2f}; bags in {folder}\n")
    print("| QoS | frames sent | frames in the bag | distinct | in order | exit code | recorder CPU |")
    print("|---|---:|---:|---:|---|---:|---:|")
    for row in rows:
        print(f"| {row['qos']} | {row['sent']} | {row['recorded']} | {row['distinct']} | {row['in order']} | "
              f"{row['exit code']} | {row['recorder cpu s']:.1f} s |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
