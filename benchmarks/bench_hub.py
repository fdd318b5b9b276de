"""Capacity of the course's JupyterHub on this machine (coursehub), and the cost of its doors.

Not a test: times depend on the machine and on what else runs, so this prints numbers instead of
asserting them. Root only (it creates Linux accounts, prefixed ``hb`` + 4 letters, and removes
them at the end).

    .venv/bin/python benchmarks/bench_hub.py [--students 10]

1. Creating the course (create-course) for the students and an instructor.
2. Hub start: from ``python -m coursehub start`` to the hub's API answering.
3. Login to JupyterLab of one student alone: the login form's POST to the lab page's 200
   (the server starts in between, in its namespaces).
4. Memory (PSS, shared pages split among their users) of that idle server, and of a kernel
   with a running ROS session (course_lib.ros.session with the virtual camera at 30 Hz, 640x480, and
   a subscriber), measured by the kernel itself.
5. All other students log in at once: the wall time until every lab answers, each one's time,
   then every student's kernel runs a talker and a listener on one domain (isolation: each must
   hear only itself), and the memory of all the idle servers.
6. The doors (coursehub.forward): round trips and throughput through TCP -> unix socket -> TCP,
   as the hub reaches a server, side by side with plain loopback TCP.
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import os
import secrets
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))  # the hub (coursehub/) and tests.support run from the repository, uninstalled

from tests.support.hub import course_processes, log_in, run_in_kernel, running_hub, why_no_hub  # noqa: E402

ROS_SESSION = '''
import time, psutil
from course_lib import session
from course_lib.imaging.camera import WebcamNode
from sensor_msgs.msg import Image
session.start()
camera = session.add_node(WebcamNode())
frames = []
listener = session.add_node(__import__("rclpy").create_node("listener"))
listener.create_subscription(Image, "image", lambda m: frames.append(1), 10)
session.spin_for(1.0)
me = psutil.Process()
cpu, started = sum(me.cpu_times()[:2]), time.monotonic()
session.spin_for(5.0)
cpu = (sum(me.cpu_times()[:2]) - cpu) / (time.monotonic() - started)
info = me.memory_full_info()
print(f"pss_mb={info.pss / 2**20:.0f} rss_mb={info.rss / 2**20:.0f} frames={len(frames)} cpu={cpu:.0%} of a core")
session.stop()
'''

TALKER = '''
import os, time
os.environ["ROS_DOMAIN_ID"] = "7"
import rclpy
from std_msgs.msg import String
rclpy.init()
try:
    node = rclpy.create_node("talker")
    heard = set()
    publisher = node.create_publisher(String, "chatter", 10)
    node.create_subscription(String, "chatter", lambda m: heard.add(m.data), 10)
    node.create_timer(0.1, lambda: publisher.publish(String(data=os.environ["USER"])))
    end = time.monotonic() + 5
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    print(sorted(heard))
finally:
    rclpy.try_shutdown()
'''


def pss_mb(processes) -> float:
    total = 0
    for process in processes:
        try:
            total += process.memory_full_info().pss
        except Exception:  # noqa: BLE001 - a process that ended meanwhile
            pass
    return total / 2**20


def server_processes(hub, user):
    import pwd

    uid = pwd.getpwnam(user).pw_uid
    return [p for p in course_processes(hub) if p.info["uids"].real == uid]


async def _doors(rounds: int, megabytes: int) -> dict:
    from coursehub import forward

    async def echo(reader, writer):
        while data := await reader.read(1 << 16):
            writer.write(data)
            await writer.drain()
        writer.close()

    async def measure(port):
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        started = time.perf_counter()
        for _ in range(rounds):
            writer.write(b"x" * 100)
            await reader.readexactly(100)
        round_trip = (time.perf_counter() - started) / rounds
        block, total = b"y" * (1 << 16), megabytes << 20
        started = time.perf_counter()

        async def send():
            for _ in range(total // len(block)):
                writer.write(block)
                await writer.drain()

        sender = asyncio.ensure_future(send())
        got = 0
        while got < total:
            got += len(await reader.read(1 << 20))
        await sender
        writer.close()
        return round_trip, megabytes / (time.perf_counter() - started)

    with tempfile.TemporaryDirectory() as folder:
        plain = await asyncio.start_server(echo, "127.0.0.1", 0)
        plain_port = plain.sockets[0].getsockname()[1]
        inner = await forward.unix_to_tcp(f"{folder}/server.sock", "127.0.0.1", plain_port)
        outer = await forward.tcp_to_unix("127.0.0.1", 0, f"{folder}/server.sock")
        outer_port = outer.sockets[0].getsockname()[1]
        direct = await measure(plain_port)
        doors = await measure(outer_port)
        for server in (plain, inner, outer):
            server.close()
    return {"direct": direct, "doors": doors}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--students", type=int, default=10)
    args = parser.parse_args()
    if why_no_hub():
        print(f"bench_hub: {why_no_hub()}", file=sys.stderr)
        return 2
    prefix = "hb" + "".join(secrets.choice("abcdefghijkmnpqrstuvwxyz") for _ in range(4))
    names = [f"s{i:02d}" for i in range(args.students + 1)]
    print(f"# {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the start")
    with tempfile.TemporaryDirectory() as scratch:
        started = time.monotonic()
        with running_hub(prefix, names, Path("/srv") / f"{prefix}-hub", Path(scratch)) as hub:
            print(f"create-course ({len(names)} students) + hub start: {time.monotonic() - started:.1f} s")
            hub_start = _hub_start_seconds(hub)
            print(f"hub start (python -m coursehub start -> API answers): {hub_start:.1f} s")
            first, *others = hub.students
            session, seconds = log_in(hub, first)
            print(f"login -> JupyterLab, one student alone: {seconds:.1f} s")
            time.sleep(3)
            print(f"idle server (PSS): {pss_mb(server_processes(hub, first)):.0f} MB")
            print(f"kernel with a running ROS session (camera 30 Hz 640x480 + subscriber): "
                  f"{run_in_kernel(hub, session, first, ROS_SESSION, timeout=180).strip()}")
            started = time.monotonic()
            with concurrent.futures.ThreadPoolExecutor(len(others)) as pool:
                logins = list(pool.map(lambda user: log_in(hub, user, timeout=600), others))
            wall = time.monotonic() - started
            times = sorted(seconds for _, seconds in logins)
            print(f"{len(others)} students logging in at once: all labs up after {wall:.1f} s "
                  f"(each: median {statistics.median(times):.1f} s, max {times[-1]:.1f} s)")
            with concurrent.futures.ThreadPoolExecutor(len(others)) as pool:
                heard = list(pool.map(lambda pair: run_in_kernel(hub, pair[1][0], pair[0], TALKER, timeout=300),
                                      zip(others, logins, strict=True)))
            isolated = sum(said.strip() == f"['{user}']" for user, said in zip(others, heard, strict=True))
            print(f"talkers on one domain in {len(others)} kernels at once: {isolated} of {len(others)} heard only "
                  f"themselves" + ("" if isolated == len(others) else f": {heard}"))
            time.sleep(3)
            idle = [pss_mb(server_processes(hub, user)) for user in hub.students]
            print(f"{len(idle)} idle servers: {sum(idle):.0f} MB in all (PSS), {statistics.median(idle):.0f} MB each")
            namespaces = {os.readlink(f"/proc/{p.pid}/ns/net") for p in course_processes(hub)}
            print(f"network namespaces of the course's processes: {len(namespaces)} for {len(hub.students)} servers")
    doors = asyncio.run(_doors(2000, 256))
    for name, (round_trip, throughput) in doors.items():
        print(f"{name:>6}: round trip {round_trip * 1e6:.0f} us, {throughput:.0f} MB/s")
    print(f"doors / direct: round trip x{doors['doors'][0] / doors['direct'][0]:.1f}, "
          f"throughput x{doors['doors'][1] / doors['direct'][1]:.2f}")
    return 0


def _hub_start_seconds(hub) -> float:
    """Stop the running hub and start it again with the same course, timed."""
    import subprocess

    import requests

    hub.stop()
    started = time.monotonic()
    with open(hub.log, "a") as out:
        hub.process = subprocess.Popen([sys.executable, "-m", "coursehub", "--hub-dir", str(hub.hub_dir), "start"],
                                       cwd=REPO, stdout=out, stderr=subprocess.STDOUT,
                                       env=dict(os.environ, PYTHONPATH=str(REPO)))
    while True:
        try:
            if requests.get(f"{hub.url}/hub/api", timeout=5).status_code == 200:
                return time.monotonic() - started
        except requests.RequestException:
            time.sleep(0.05)


if __name__ == "__main__":
    sys.exit(main())
