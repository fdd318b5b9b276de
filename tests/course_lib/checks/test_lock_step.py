"""course_lib.checks.lock_step: the graded lock-step simulator waits for a controller as long as it
computes, whatever the machine's load, and halts with a clear reason when the controller is to blame.

Each test runs the simulator in this process and a controller (tests/support/controller.py) in a
process of its own, in a ROS domain of the test's; what is compared is counted in simulated time.
A starved controller is played by stopping its process (SIGSTOP): no processor, like the busiest
machine, for longer than the former wall-clock timeout (5 s on an idle machine).
"""

from __future__ import annotations

import os
import signal
import sys
import time
from contextlib import contextmanager

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from sensor_msgs.msg import LaserScan

from course_lib import contract
from course_lib.checks.lock_step import JudgedSimulator
from course_lib.robot.simulator_node import RobotSimulator
from course_lib.ros.processes import NodeProcess

TESTS = contract.ROOT / "tests"  # the support package is found there
#: Wall seconds any one run may take (the test's own bound, not what is judged).
RUN_BOUND = 60.0
SEED, SECONDS = 4, 3.0


@contextmanager
def lock_step(domain_id: int, *controller_args: str, judged: bool = True, parameters: dict | None = None, **options):
    """(simulator node, controller process, executor): the pillar world of SEED in lock-step, with
    the node's `parameters` (a judged simulator's)."""
    path = os.pathsep.join(filter(None, [str(TESTS), os.environ.get("PYTHONPATH")]))
    proc = NodeProcess([sys.executable, "-m", "support.controller", *controller_args], domain_id=domain_id,
                       env={"PYTHONPATH": path}, cwd=TESTS).start()
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    overrides = [Parameter(name, value=value) for name, value in
                 {"world": "pillar", "seed": SEED, **(parameters or {})}.items()]
    if judged:
        sim = JudgedSimulator(proc, context=context, parameter_overrides=overrides, **options)
    else:
        overrides += [Parameter(name, value=value) for name, value in {"lock_step": True, **options}.items()]
        sim = RobotSimulator(context=context, parameter_overrides=overrides)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(sim)
    try:
        yield sim, proc, executor
    finally:
        os.killpg(proc.pid, signal.SIGCONT)
        proc.stop(timeout=2)
        executor.shutdown()
        sim.destroy_node()
        rclpy.try_shutdown(context=context)


def drive(sim, executor, seconds: float = SECONDS, at_each_spin=None) -> None:
    """Spin until `seconds` simulated seconds or the simulation halts."""
    deadline = time.monotonic() + RUN_BOUND
    while sim.sim.time < seconds - 1e-9 and sim.halted is None:
        assert time.monotonic() < deadline, f"not {seconds} simulated s within {RUN_BOUND:g} s"
        executor.spin_once(timeout_sec=0.05)
        if at_each_spin is not None:
            at_each_spin()


def wait_matched(sim, scan_subscribers: int) -> None:
    """Wait (without spinning: DDS matches in threads of its own) until the simulator sees the
    controller's /cmd_vel and `scan_subscribers` /scan subscriptions: a test's own listener alone
    would start the drive before the controller hears the first scan, which is then sent again."""
    deadline = time.monotonic() + RUN_BOUND
    while sim.scan_pub.get_subscription_count() < scan_subscribers or sim.cmd_sub.get_publisher_count() < 1:
        assert time.monotonic() < deadline, "the controller's endpoints never matched"
        time.sleep(0.01)


def stop_for(proc, sim, executor, at: float, seconds: float):
    """What drive() calls to stop the controller's process for `seconds` wall seconds once the
    simulation reaches `at` simulated seconds (once), spinning the simulator meanwhile; and a list
    that then holds the number of ticks the simulation made while the controller was stopped and,
    second, the number of scans it passed over meanwhile."""
    stepped = []

    def maybe_stop():
        if stepped or sim.sim.time < at:
            return
        ticks, passed = sim.scans, sim.passed_over
        os.killpg(proc.pid, signal.SIGSTOP)
        try:
            until = time.monotonic() + seconds
            while time.monotonic() < until:
                executor.spin_once(timeout_sec=0.05)
        finally:
            os.killpg(proc.pid, signal.SIGCONT)
        stepped.extend([sim.scans - ticks, sim.passed_over - passed])
    return maybe_stop, stepped


@pytest.fixture(scope="module")
def undisturbed(tmp_path_factory):
    """The pose after SECONDS of the controller that was never stopped (the run to compare with)."""
    from course_lib.ros import rosenv

    with rosenv.reserve_domain_id() as reservation, lock_step(reservation.domain_id) as (sim, _, executor):
        drive(sim, executor)
        assert sim.failure is None and sim.passed_over == 0
        return sim.sim.pose()


def test_a_stopped_controller_is_waited_for_and_drives_exactly_as_an_undisturbed_one(domain_id, undisturbed):
    with lock_step(domain_id) as (sim, proc, executor):
        maybe_stop, stepped = stop_for(proc, sim, executor, at=1.0, seconds=6.0)
        drive(sim, executor, at_each_spin=maybe_stop)
        # An answer the controller sent just before SIGSTOP may still arrive and step once; none after it.
        assert stepped[0] <= 1, f"{stepped[0]} scans stepped while the controller had no processor"
        assert sim.failure is None and sim.passed_over == 0
        assert sim.sim.pose() == undisturbed


def test_the_plain_simulators_wall_clock_timeout_would_step_past_it(domain_id, undisturbed):
    """What the judged simulator prevents (and that the stop above is long enough to matter):
    with a wall-clock timeout the stopped controller's scans are passed over, counted, and the
    robot drives otherwise."""
    with lock_step(domain_id, judged=False, reply_timeout=1.0) as (sim, proc, executor):
        maybe_stop, stepped = stop_for(proc, sim, executor, at=1.0, seconds=3.0)
        drive(sim, executor, at_each_spin=maybe_stop)
        # Every step during the stop passed a scan over, but one: the answer sent just before SIGSTOP
        # may still arrive. (A busy machine passes scans over outside the stop too: that is the flaw.)
        during, passed = stepped
        assert passed >= 1 and passed <= during <= passed + 1 and sim.passed_over >= passed
        assert sim.sim.pose() != undisturbed


def test_a_controller_that_sleeps_before_one_answer_drives_as_an_undisturbed_one(domain_id, undisturbed):
    """A sleep is a slow answer, not a missing one: it lasts as long under load as idle, and the
    backstop (30 s idle) is far beyond it."""
    with lock_step(domain_id, "--sleep-at", "10", "--sleep", "3") as (sim, _, executor):
        drive(sim, executor)
        assert sim.failure is None and sim.sim.pose() == undisturbed


def test_a_controller_that_stops_answering_fails_with_a_clear_reason_at_the_backstop(domain_id):
    with lock_step(domain_id, "--silent-from", "20", backstop=3.0) as (sim, _, executor):
        started = time.monotonic()
        drive(sim, executor)
        assert time.monotonic() - started < 3.0 + 20.0
    assert sim.failure is not None and sim.halted == sim.failure
    assert sim.failure.startswith("the controller did not answer the scan at 0.95 simulated s (scan 20) within 3 s")
    assert "it waits instead of answering" in sim.failure
    assert sim.scans == 20 and sim.sim.time == pytest.approx(0.95)


def test_a_controller_that_computes_endlessly_fails_on_processor_time_not_the_wall_clock(domain_id):
    with lock_step(domain_id, "--loop-at", "5", reply_cpu_seconds=1.0, backstop=RUN_BOUND) as (sim, _, executor):
        drive(sim, executor)
    assert sim.failure == ("the controller did not answer the scan at 0.20 simulated s (scan 5) within 1 s of "
                           "processor time (an endless loop, or far too much work per scan?)")


def test_drive_until_drives_exactly_as_an_executors_spin_and_feeds_its_listeners(domain_id, undisturbed):
    """drive_until waits on the /cmd_vel subscription, the timers and the check's listeners only
    (no executor): the same pose after SECONDS, and a listener's callback gets every message."""
    with lock_step(domain_id) as (sim, _, _):
        listener = rclpy.create_node("lock_step_listener", context=sim.context)
        scans = []
        subscription = listener.create_subscription(LaserScan, "scan", scans.append, 1000)
        try:
            wait_matched(sim, scan_subscribers=2)
            assert sim.drive_until(lambda: sim.sim.time >= SECONDS - 1e-9 or sim.halted is not None, RUN_BOUND,
                                   listeners=[subscription])
            assert sim.failure is None and sim.sim.pose() == undisturbed
            # The scans reach the listener through DDS's transport, on a busy machine some way
            # behind: the rest arrive while the drive goes on. A first scan the controller had not
            # answered within FIRST_SCAN_RESEND s (a busy machine's start) went out twice.
            ticks, resent = sim.scans, int(sim.resent)
            published = ticks + resent
            assert sim.drive_until(lambda: len(scans) >= published, RUN_BOUND, listeners=[subscription])
            stamps = [round(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9, 2) for m in scans[:published]]
            assert stamps == [0.0] * resent + [round(i * 0.05, 2) for i in range(ticks)]
        finally:
            listener.destroy_node()


def test_drive_until_serves_the_lock_step_timer_that_judges_a_missing_answer(domain_id):
    with lock_step(domain_id, "--silent-from", "20", backstop=3.0) as (sim, _, _):
        assert sim.drive_until(lambda: sim.halted is not None, RUN_BOUND)
    assert sim.failure.startswith("the controller did not answer the scan at 0.95 simulated s (scan 20) within 3 s")
    assert sim.scans == 20 and sim.sim.time == pytest.approx(0.95)


def test_drive_until_keeps_the_pace_of_max_real_time_factor_and_drives_the_same(domain_id, undisturbed):
    """A capped pace holds a tick back with a timer of its own, which drive_until serves too: never
    faster than the cap (a one-sided bound, which a busy machine cannot break)."""
    with lock_step(domain_id, parameters={"max_real_time_factor": 2.0}) as (sim, _, _):
        started = time.monotonic()
        assert sim.drive_until(lambda: sim.sim.time >= SECONDS - 1e-9 or sim.halted is not None, RUN_BOUND)
        assert time.monotonic() - started >= SECONDS / 2.0 - 0.05
        assert sim.failure is None and sim.sim.pose() == undisturbed


def test_odom_goes_out_only_to_a_subscriber_which_then_gets_every_tick_and_the_drive_is_the_same(domain_id,
                                                                                                  undisturbed):
    """/clock and /odom, which nothing in lock-step waits for, are published only while someone
    subscribes: a student's node that reads /odom gets each tick's, stamped in order."""
    from nav_msgs.msg import Odometry

    with lock_step(domain_id) as (sim, _, _):
        assert not sim.heard(sim.odom_pub) and not sim.heard(sim.clock_pub)
        listener = rclpy.create_node("odom_listener", context=sim.context)
        odom = []
        subscription = listener.create_subscription(Odometry, "odom", odom.append, 1000)
        try:
            wait_matched(sim, scan_subscribers=1)
            deadline = time.monotonic() + RUN_BOUND
            while not sim.heard(sim.odom_pub):
                assert time.monotonic() < deadline, "the simulator never saw the /odom subscription"
                time.sleep(0.01)
            assert not sim.heard(sim.clock_pub)
            assert sim.drive_until(lambda: sim.sim.time >= SECONDS - 1e-9 or sim.halted is not None, RUN_BOUND,
                                   listeners=[subscription])
            assert sim.failure is None and sim.sim.pose() == undisturbed
            published = sim.scans
            assert sim.drive_until(lambda: len(odom) >= published, RUN_BOUND, listeners=[subscription])
            stamps = [round(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9, 2) for m in odom[:published]]
            assert stamps == [round(i * 0.05, 2) for i in range(published)]
        finally:
            listener.destroy_node()
