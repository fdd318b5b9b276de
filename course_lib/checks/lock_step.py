"""The simulated robot in lock-step as the checks run it: it waits for each scan's /cmd_vel as
long as the controller's process computes, and never passes a scan over.

The simulator node itself (course_lib.robot.simulator_node) passes over a scan nobody answers
within a wall-clock timeout; on a busy machine that could step past a correct controller that was
merely slow to get a processor, and a verdict would depend on the load. Here the wait for an
answer is bounded by the controller's processor time (its whole process tree), which the load does
not change: a controller that spends REPLY_CPU_SECONDS on one scan without answering has failed,
however long that took. A controller that is starved, or stopped (SIGSTOP), uses no processor
time and is waited for. One that waits instead of answering (it never publishes for that scan,
or sleeps) uses none either; a sleep lasts as long on a busy machine as on an idle one, so the
wall-clock backstop REPLY_BACKSTOP (idle seconds, times the load factor) judges it the same under
any load: a short sleep is a slow answer, an endless wait fails there. Either way the simulation
halts, ``failure`` says why, in words for the student, and the scans before it stand. (A
controller still computing at the backstop, on a machine too busy to let it use its processor
time, is told so: that one is not its fault.) The first scan is sent again once when the
controller waits FIRST_SCAN_RESEND s without answering it; a controller that sleeps that long in
its first callback then answers it twice, the same way under any load.
"""

from __future__ import annotations

import time

from course_lib.checks.context import scaled
from course_lib.checks.student_server import ProcessorTime
from course_lib.robot.simulator_node import RobotSimulator

#: Processor seconds the controller may use on one scan without answering it (a P-controller
#: needs milliseconds; its first answer, with lazy imports, a few hundred).
REPLY_CPU_SECONDS = 2.0
#: Wall seconds (on an idle machine: scaled) one scan waits at most: the backstop for a
#: controller that waits rather than computes.
REPLY_BACKSTOP = 30.0
#: After this many wall seconds of the controller waiting (next to no processor time) without
#: answering the first scan, that scan is sent again (once): it may have gone out while DDS was
#: still matching the controller's endpoints, and been lost. Later scans go over matched endpoints.
FIRST_SCAN_RESEND = 2.0
#: Wall seconds between two looks at the caller's condition while nothing arrives (drive_until).
POLL = 0.05
#: A controller that used less than this share of its processor time per scan by the backstop
#: was waiting; one that used more was computing on a machine too busy to let it finish.
WAITING_SHARE = 0.25


class JudgedSimulator(RobotSimulator):
    """RobotSimulator in lock-step that judges a scan's missing answer by the processor time of
    `controller` (a NodeProcess, or anything with cpu_seconds()); `failure` says why it halted.

    Args:
        controller: the controller's process.
        reply_cpu_seconds: processor seconds a scan's answer may take (REPLY_CPU_SECONDS).
        backstop: wall seconds a scan waits at most (default: REPLY_BACKSTOP, scaled).
        **options: for the Node (context, parameter_overrides, cli_args); lock_step is set here.
    """

    def __init__(self, controller, reply_cpu_seconds: float = REPLY_CPU_SECONDS, backstop: float | None = None,
                 **options):
        from rclpy.parameter import Parameter

        self.controller = controller
        self.reply_cpu_seconds = reply_cpu_seconds
        self.backstop = scaled(REPLY_BACKSTOP) if backstop is None else backstop
        self.failure: str | None = None
        self._spent: ProcessorTime | None = None  # the controller's processor time on the waiting scan
        self.resent = False  # the first scan was sent again (see FIRST_SCAN_RESEND)
        # Nobody sets its parameters or asks for its types while a check runs: seven services fewer
        # for every spin to look at.
        overrides = [*options.pop("parameter_overrides", []), Parameter("lock_step", value=True),
                     Parameter("start_type_description_service", value=False)]
        super().__init__(parameter_overrides=overrides, start_parameter_services=False, **options)

    # Nobody reads the simulator's warnings of an incompatible QoS (the student's node is judged by
    # what arrives): without the two event handlers rclpy gives every endpoint by default, each of
    # the drive's spins (one or two per scan) looks at 12 handlers fewer.
    def create_publisher(self, *args, **kwargs):
        from rclpy.event_handler import PublisherEventCallbacks

        kwargs.setdefault("event_callbacks", PublisherEventCallbacks(use_default_callbacks=False))
        return super().create_publisher(*args, **kwargs)

    def create_subscription(self, *args, **kwargs):
        from rclpy.event_handler import SubscriptionEventCallbacks

        kwargs.setdefault("event_callbacks", SubscriptionEventCallbacks(use_default_callbacks=False))
        return super().create_subscription(*args, **kwargs)

    def heard(self, publisher) -> bool:
        """/clock and /odom only while someone subscribes (a student's node may read /odom): a
        message published with no subscription matched reaches nobody, even one that subscribes
        later (the QoS is volatile), and nothing in lock-step waits for either."""
        return publisher.get_subscription_count() > 0

    def publish_state(self) -> None:
        super().publish_state()
        self._spent = None  # measured from the first look at the waiting scan (on_unanswered)

    def on_unanswered(self, waited: float) -> None:
        if self._spent is None:
            self._spent = ProcessorTime(self.controller, self.reply_cpu_seconds)
            return
        spent = self._spent
        scan = f"the scan at {self.now:.2f} simulated s (scan {self.scans})"
        if spent.used_up():
            self.fail(f"the controller did not answer {scan} within {self.reply_cpu_seconds:g} s of processor "
                      "time (an endless loop, or far too much work per scan?)")
        elif self.scans == 1 and not self.resent and spent.waits_after(FIRST_SCAN_RESEND):
            self.resent = True
            self.scan_pub.publish(self.last_scan)
        elif waited > self.backstop:
            used = self.controller.cpu_seconds() - spent.start
            why = ("it waits instead of answering (answer every scan with one /cmd_vel; no sleep() in the callback)"
                   if used < WAITING_SHARE * self.reply_cpu_seconds else  # else the machine was too busy to tell
                   f"it was still computing, short of the {self.reply_cpu_seconds:g} s it may use: the machine was "
                   "too busy to tell (not your node's fault: ask your instructor to grade it again)")
            self.fail(f"the controller did not answer {scan} within {self.backstop:.0f} s, using {used:.2f} s of "
                      f"processor time meanwhile: {why}")

    def fail(self, reason: str) -> None:
        self.failure = reason
        self.halt(reason)

    def drive_until(self, condition, timeout: float, listeners=()) -> bool:
        """Run the lock-step drive until condition() holds or `timeout` wall seconds pass; returns
        condition(). It waits on exactly what a tick needs: the /cmd_vel subscription, the node's
        timers (the lock-step timer: the start, the waiting scan's judge) and `listeners` (the
        check's own subscriptions, e.g. of the markers), and takes each message straight from its
        subscription, calling its callback and then looking at condition() again: the same
        callbacks in the same order as an executor's spin, without its per-spin work (a wait set
        built anew from every node's entities, a timer for its timeout, a task per callback),
        which cost more than a tick's 25 MuJoCo steps and four messages."""
        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

        subscriptions = [self.cmd_sub, *listeners]
        end = time.monotonic() + timeout
        wait_sets = {}  # by the number of timers (a tick the pace holds back has one more)
        while not condition():
            left = end - time.monotonic()
            if left <= 0:
                return bool(condition())
            timers = [timer for timer in self.timers if not timer.is_canceled()]
            if len(timers) not in wait_sets:
                wait_sets[len(timers)] = _rclpy.WaitSet(len(subscriptions), 0, len(timers), 0, 0, 0,
                                                        self.context.handle)
            wait_set = wait_sets[len(timers)]
            wait_set.clear_entities()
            for subscription in subscriptions:
                wait_set.add_subscription(subscription.handle)
            for timer in timers:
                wait_set.add_timer(timer.handle)
            wait_set.wait(round(min(POLL, left) * 1e9))
            for index, timer in enumerate(timers):  # a callback before may have destroyed a pace timer
                if wait_set.is_ready("timer", index) and timer in self.timers and not timer.is_canceled():
                    timer.handle.call_timer()
                    timer.callback()
                    if condition():
                        return True
            for index, subscription in enumerate(subscriptions):
                if not wait_set.is_ready("subscription", index):
                    continue
                while (taken := subscription.handle.take_message(subscription.msg_type, subscription.raw)) is not None:
                    subscription.callback(taken[0])
                    if condition():
                        return True
        return True
