"""``ros2 run tf2_tools view_frames [-t SECONDS] [-o NAME]``: listen to /tf and /tf_static, then write
the tree of frames as ``frames_<date>.gv`` and ``frames_<date>.pdf`` (or ``NAME.gv``/``NAME.pdf``),
with tf2_tools' options and log lines (it is not on PyPI).

The PDF is Graphviz's when ``dot`` is installed, else the course's drawing of the same graph
(:mod:`course_lib.robot.frame_graph`, which also shows a ``.gv`` in the notebook). Beyond
upstream, which listens for exactly ``--wait-time`` seconds, it also waits (up to a minute more)
until discovery has shown every ROS process on this machine and every /tf and /tf_static
publisher found has been heard once: on a busy machine a frame is not missed because its
publisher was discovered late.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time

#: Seconds the listening goes on at most after --wait-time, for discovery and the first messages.
DISCOVERY_BACKSTOP = 60.0


def parse_args(args: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="view_frames",
                                     description="Create a diagram of the TF frames being broadcast over ROS")
    parser.add_argument("--wait-time", "-t", type=float, default=5.0,
                        help="Listen to the /tf topic for this many seconds before rendering the frame tree")
    parser.add_argument("-o", "--output", help="Output filename")
    parser.add_argument("--tf_topic", help="Topic for dynamic transforms", default="/tf")
    parser.add_argument("--tf_static_topic", help="Topic for static transforms", default="/tf_static")
    return parser.parse_args(args)


def write_pdf(gv: str, pdf: str) -> None:
    """``dot -Tpdf`` when Graphviz is installed, else the course's drawing of the same graph."""
    if shutil.which("dot"):
        subprocess.run(["dot", "-Tpdf", gv, "-o", pdf], check=False)
        return
    from course_lib.robot import frame_graph

    figure = frame_graph.draw(frame_graph.read_gv(gv))
    figure.savefig(pdf)


def listen(node, tf_topic: str, tf_static_topic: str, wait_time: float):
    """A Buffer filled from the two topics for `wait_time` s, and until every publisher found was heard."""
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from tf2_msgs.msg import TFMessage

    from course_lib.robot.tf_buffer import Buffer, TransformListener
    from course_lib.ros import discovery, session

    buffer = Buffer()
    node.listener = TransformListener(buffer, node)
    for subscription, topic in ((node.listener.tf_sub, tf_topic), (node.listener.tf_static_sub, tf_static_topic)):
        if topic != subscription.topic_name:  # --tf_topic and --tf_static_topic
            node.destroy_subscription(subscription)
            static = topic == tf_static_topic
            qos = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL if static else
                             DurabilityPolicy.VOLATILE)
            callback = node.listener.on_tf_static if static else node.listener.on_tf
            node.create_subscription(TFMessage, topic, callback, qos)
    # Messages heard per topic: a static broadcaster sends one latched message to each new subscriber,
    # so as many as there are publishers means each was heard (Jazzy's MessageInfo names no sender).
    heard = {tf_topic: 0, tf_static_topic: 0}
    for topic in heard:
        qos = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL if topic == tf_static_topic
                         else DurabilityPolicy.VOLATILE)
        node.create_subscription(TFMessage, topic, lambda _msg, t=topic: heard.__setitem__(t, heard[t] + 1), qos)
    session.wait_for(lambda: False, timeout=wait_time, poll=0.1)
    began = time.monotonic()
    discovery.wait_for_every_process(DISCOVERY_BACKSTOP)
    left = max(0.0, DISCOVERY_BACKSTOP - (time.monotonic() - began))
    session.wait_for(lambda: all(heard[t] >= node.count_publishers(t) for t in heard), timeout=left, poll=0.05)
    return buffer


def main(args=None) -> int:
    import rclpy
    import yaml
    from rclpy.node import Node
    from tf2_msgs.srv import FrameGraph

    from course_lib.robot import frame_graph
    from course_lib.ros import session

    argv = sys.argv if args is None else args
    options = parse_args(rclpy.utilities.remove_ros_args(argv)[1:])
    session.start()
    node = session.add_node(Node("view_frames"))
    try:
        node.get_logger().info(f"Listening to tf data for {options.wait_time} seconds...")
        buffer = listen(node, options.tf_topic, options.tf_static_topic, options.wait_time)
        node.get_logger().info("Generating graph...")
        result = FrameGraph.Response(frame_yaml=buffer.all_frames_as_yaml())
        node.get_logger().info("Result:" + str(result))
        data = yaml.safe_load(result.frame_yaml) or {}
        name = options.output if options.output is not None else "frames_" + time.strftime("%Y-%m-%d_%H.%M.%S")
        gv, pdf = f"{name}.gv", f"{name}.pdf"
        node.get_logger().info(f"Exporting graph in {pdf} file...")
        seconds, nanoseconds = node.get_clock().now().seconds_nanoseconds()
        with open(gv, "w") as file:
            file.write(frame_graph.dot_text(data, seconds + nanoseconds / 1e9))
        write_pdf(gv, pdf)
    except KeyboardInterrupt:
        return 130
    finally:
        session.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
