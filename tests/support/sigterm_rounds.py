"""SIGTERM sent to a node's main() while it spins, round after round in one process.

A process start costs seconds, so `run_rounds` runs a module's main() ROUNDS times in one process
(this file as a script), as `ros2 run` runs it once, and a thread sends SIGTERM to the process a
seeded 0-50 ms after each spin starts. Between rounds rclpy's signal handlers are taken out, as a
new process starts without them (main() installs them again), and the SIGTERM disposition main()
found is put back. The script ends with exit code 3 when a round does not end within ENDS_WITHIN
seconds of its SIGTERM (it prints where each thread was), and prints "all rounds ended" when every round did.

Without a handler of its own, a node without timers hangs (or fails to make its wait set) in about
7 % of rounds, spun by a MultiThreadedExecutor or a SingleThreadedExecutor: ROUNDS miss it with a
chance under 1 %. main() passes rclpy.spin an executor of its own: rclpy's global executor would
outlive a round's context.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

#: main() runs, each ended by a SIGTERM while it spins.
ROUNDS = 80

#: Seconds a round may take to end after its SIGTERM.
ENDS_WITHIN = 5.0

DONE = "all rounds ended"


def run_rounds(module: str, env: dict, cwd: Path | None = None, rounds: int = ROUNDS) -> subprocess.CompletedProcess:
    """Run `module`'s main() `rounds` times in one process, each ended by SIGTERM while it spins."""
    return subprocess.run([sys.executable, __file__, module, str(rounds)], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=rounds * ENDS_WITHIN + 60)


def exit_code_after_sigterm(command: list[str], node: str, env: dict, cwd: Path | None = None) -> tuple[int, str]:
    """Start `command` (a node process), wait until its node `node` is in the graph, send it SIGTERM
    and return its exit code within ENDS_WITHIN seconds, and its log (the process is stopped
    whatever happens)."""
    from course_lib.ros.processes import NodeProcess

    process = NodeProcess(command, env=env, cwd=cwd)
    process.start()
    try:
        process.wait_for_node(node, timeout=30)
        process.send_signal(signal.SIGTERM)
        return process.wait(timeout=ENDS_WITHIN), process.log
    finally:
        process.stop()


def _main(module: str, rounds: int) -> None:
    import faulthandler
    import importlib
    import os
    import random
    import signal
    import threading

    import rclpy
    import rclpy.signals

    node_module = importlib.import_module(module)
    spinning, ended = threading.Event(), threading.Event()
    spin = rclpy.spin

    def announced_spin(node, executor=None):
        spinning.set()
        return spin(node, executor)

    rclpy.spin = announced_spin

    def kill_each_round():
        rng = random.Random(0)
        for number in range(rounds):
            spinning.wait()
            spinning.clear()
            ended.wait(rng.uniform(0.0, 0.05))
            os.kill(os.getpid(), signal.SIGTERM)
            if not ended.wait(ENDS_WITHIN):
                print(f"round {number}: main() still runs {ENDS_WITHIN} s after SIGTERM (the context is "
                      f"{'up' if rclpy.ok() else 'down'}); its threads:", flush=True)
                faulthandler.dump_traceback(sys.stdout)
                os._exit(3)
            ended.clear()

    threading.Thread(target=kill_each_round, daemon=True).start()
    disposition = signal.getsignal(signal.SIGTERM)
    for _ in range(rounds):
        node_module.main()
        rclpy.signals.uninstall_signal_handlers()  # as a new process starts: main() installs them again
        signal.signal(signal.SIGTERM, disposition)
        ended.set()
    print(DONE, flush=True)


if __name__ == "__main__":
    _main(sys.argv[1], int(sys.argv[2]))
