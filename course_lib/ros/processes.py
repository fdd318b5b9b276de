"""Run ROS nodes (or any command) as child processes that never outlive the notebook or script.

There is no ``ros2 launch`` in the pip-installed ROS 2, so lessons start their nodes with this
module, and the autograder runs student code through it with resource limits::

    from course_lib import processes

    with processes.python_node("demo_nodes.talker:main", name="talker") as talker:
        talker.wait_for_node("talker")
        ...                      # talk to it
    print(talker.log)            # everything it printed, rclpy log lines included

How children are kept from outliving their caller, and how their output is bounded: see
course_lib.supervision.supervised_process (what NodeProcess is without ROS) and course_lib.supervision.supervisor, the
small process each NodeProcess starts as the node's direct parent.
"""

from __future__ import annotations

import itertools
import os
import sys
import time
from collections.abc import Callable

from course_lib import waiting
from course_lib.ros import rosenv
from course_lib.supervision.supervised_process import (  # noqa: F401 (Limits, stop_all, ...: course_lib.ros.processes' names)
    START_TIMEOUT,
    Limits,
    SupervisedProcess,
    TreeMember,
    running_processes,
    stop_all,
    stop_together,
)

_WATCHER_IDS = itertools.count()


class NodeProcess(SupervisedProcess):
    """One node (or any command) running as a child process in its own process group, in a ROS
    domain (course_lib.supervision.supervised_process.SupervisedProcess, and the ROS graph around it).

    Args:
        command: the program and its arguments, e.g. ``[sys.executable, "-m", "pkg.node"]``.
        name: a label for messages. When given explicitly, starting a NodeProcess stops a
            running one of the same name first, so re-running a notebook cell replaces its node;
            and when another program (a notebook whose kernel still runs) runs one of that name
            in the same domain, start() prints a plain warning that names it
            (course_lib.supervision.process_registry).
        domain_id: ROS_DOMAIN_ID of the child; None keeps the caller's.
        env: variables to set for the child on top of the caller's environment (a value of
            None removes a variable).
        cwd, limits, on_output, private_dirs: as SupervisedProcess (working directory, resource
            bounds, a callback for each piece of output, folders removed when the child has ended).

    Attributes:
        pid: the child's process id (it also leads the child's process group) once started.
        domain_id: the child's ROS_DOMAIN_ID, where wait_for_node looks.
        exit_reason: None while running, then "exited" (on its own), "stopped" (stop()),
            "wall_seconds" (Limits), "parent_exited" or "supervisor_died".
        usage: after the end, {"max_rss_kb", "cpu_seconds"} of the child (the peak memory
            includes the ~20 MB of the supervisor it was forked from) and the supervisor's own
            "supervisor_max_rss_kb".
    """

    def __init__(self, command: list[str], *, name: str | None = None, domain_id: int | None = None,
                 env: dict | None = None, cwd=None, limits: Limits | None = None,
                 on_output: Callable[[str, bytes], None] | None = None, private_dirs=()):
        base = dict(os.environ)
        for key, value in (env or {}).items():
            if value is None:
                base.pop(key, None)
            else:
                base[key] = str(value)
        super().__init__(command, name=name, env=rosenv.ros_environment(domain_id=domain_id, base=base), cwd=cwd,
                         limits=limits, on_output=on_output, private_dirs=private_dirs)
        self._explicit_name = name is not None
        self.domain_id = int(self.env["ROS_DOMAIN_ID"])
        self.warned_duplicate = False  # start() said that another program runs one of this name
        self._nodes_before: dict[str, str] = {}  # the session's nodes when start() began, by /rosout gid

    def _before_start(self) -> None:
        """A named process replaces a running one of the same name (a re-run cell); the session's
        nodes are noted, to tell a node of the same name that ran before from this one."""
        if self._explicit_name:
            for other in running_processes():
                if other is not self and getattr(other, "_explicit_name", False) and other.name == self.name:
                    other.stop()
        self._nodes_before = _session_nodes(self.domain_id)

    def _after_start(self) -> None:
        if self._explicit_name:
            self._note_running()

    def _after_end(self) -> None:
        if self._explicit_name:
            from course_lib.supervision import process_registry

            process_registry.forget(self.pid)

    def wait_for_node(self, node_name: str, timeout: float = 10.0, namespace: str | None = None) -> None:
        """Wait until a node of this name is in the ROS graph of the child's domain.

        Args:
            node_name: "talker", or a fully qualified "/ns/talker".
            timeout: seconds to wait; discovery alone takes about a second.
            namespace: only accept the node in this namespace; None accepts any.

        Raises:
            RuntimeError: the child exited first (the message has its exit code and last output).
            TimeoutError: the node did not appear (the message has the child's last output).
        """
        import rclpy
        from rclpy.context import Context

        self._require_started()
        if node_name.startswith("/"):
            namespace, _, node_name = node_name.rpartition("/")
            namespace = namespace or "/"
        elif namespace is not None:
            namespace = "/" + namespace.strip("/")
        wanted = node_name if namespace is None else f"{namespace.rstrip('/')}/{node_name}"
        already_running = {gid: full for gid, full in self._nodes_before.items()
                           if full.rsplit("/", 1)[-1] == node_name and (namespace is None or full == wanted)}
        context = Context()
        rclpy.init(context=context, domain_id=self.domain_id)
        watcher = None
        try:
            watcher = rclpy.create_node(f"_course_lib_wait_{os.getpid()}_{next(_WATCHER_IDS)}",
                                        context=context, enable_rosout=False,
                                        start_parameter_services=False)
            def appeared() -> bool:
                # The graph is filled in by DDS discovery threads; no spinning needed to read it.
                return any(name == node_name and namespace in (None, ns)
                           for name, ns in watcher.get_node_names_and_namespaces())

            if waiting.spin_until(lambda: appeared() or not self.running(), timeout) and appeared():
                if already_running and not self.warned_duplicate:
                    _warn_if_still_running(already_running, self)
                return
            if not self.running():
                raise RuntimeError(f"{self.name} ended ({self.describe_exit()}) before node {wanted!r} "
                                   f"appeared. Last output:\n{self.log_tail()}")
            raise TimeoutError(
                f"Node {wanted!r} did not appear in ROS domain {self.domain_id} within {timeout} s, "
                f"although {self.name} still runs: check the node name it passes to Node() and "
                f"that it calls rclpy.init(). Last output:\n{self.log_tail()}")
        finally:
            if watcher is not None:
                watcher.destroy_node()
            context.try_shutdown()

    def _note_running(self) -> None:
        """Record this named process machine-wide, and warn plainly when another program (a
        notebook whose kernel still runs) runs one of the same name in the same domain."""
        from course_lib.supervision import process_registry

        others = process_registry.started_elsewhere(self.name, self.domain_id)
        process_registry.record(self.name, self.domain_id, self.pid)
        if others:
            self.warned_duplicate = True
            print(f"Warning: another node process named {self.name!r} runs in ROS domain {self.domain_id}, "
                  f"started by {process_registry.describe(others[0])}. Both publish on the same topics, so "
                  "subscribers get their messages mixed (two cameras: frames from both). Stop the other one: "
                  "run the clean-up cell of that notebook or shut its kernel down (Kernel > Shut Down Kernel, "
                  "or the Running Terminals and Kernels panel), then run this cell again.", flush=True)



#: Seconds a node of the same name that ran before a new node process started may take to
#: leave the graph (a re-run cell stopped it a moment ago) before wait_for_node warns.
DUPLICATE_GRACE = 2.0
#: Seconds start() waits at most for the session to see the nodes of every other ROS process on
#: this machine (on a busy machine, discovery of a process started a moment ago takes seconds).
EARLIER_NODES_WAIT = 2.0


def _session_nodes(domain_id: int) -> dict[str, str]:
    """The nodes the notebook's ROS session sees (none when no session runs on this domain), as
    {id of the node's /rosout publisher: full node name}, once every other ROS process on this
    machine has shown its nodes (a node started a moment ago, in a busy machine, may take seconds).
    Node names are not unique; the publisher id tells one node from another of the same name."""
    from course_lib.ros import discovery, graph, session

    if session.domain_id() != domain_id:
        return {}
    graph.node_list()  # the first query waits for discovery
    discovery.wait_for_every_process(EARLIER_NODES_WAIT)
    return {str(endpoint.endpoint_gid): full for endpoint, full in _rosout_publishers(session.tool_node())}


def _rosout_publishers(node):
    """(endpoint, full node name) of every /rosout publisher: one per node with a logger."""
    for endpoint in node.get_publishers_info_by_topic("/rosout"):
        yield endpoint, f"{endpoint.node_namespace.rstrip('/')}/{endpoint.node_name}"


def _warn_if_still_running(earlier: dict[str, str], process: NodeProcess) -> None:
    """Print a plain warning when a node of the same name ran before this process started and
    still runs next to its node, e.g. a camera that the previous lesson's kernel left running:
    two cameras on one topic mix their frames."""
    from course_lib.ros import session

    deadline = time.monotonic() + DUPLICATE_GRACE
    while True:
        still = {str(endpoint.endpoint_gid) for endpoint, _ in _rosout_publishers(session.tool_node())} & set(earlier)
        if not still:
            return  # it has left: a re-run cell replaced it a moment ago
        if time.monotonic() >= deadline:
            break
        time.sleep(0.1)
    full = earlier[next(iter(still))]
    print(f"Warning: another node named {full} runs in ROS domain {process.domain_id}: it was already running "
          f"before {process.name} started, from another program, most likely another notebook whose kernel "
          "still runs (an earlier lesson left without its clean-up cell) or a terminal. Both publish on the "
          "same topics, so subscribers get their messages mixed (two cameras: frames from both). Stop the "
          "other one: run the clean-up cell of that notebook or shut its kernel down (Kernel > Shut Down "
          "Kernel, or the Running Terminals and Kernels panel), then run this cell again.", flush=True)


def python_node(target: str, *args: str, **kwargs) -> NodeProcess:
    """Start a Python node with this interpreter (python_command) and return its running NodeProcess.

    Args:
        target, *args: as python_command.
        **kwargs: passed to NodeProcess (name, domain_id, env, cwd, limits).
    """
    process = NodeProcess(python_command(target, *args), **kwargs)
    if kwargs.get("name") is None:  # a label only: two nodes of one module may run side by side
        process.name = target.partition(":")[0].rsplit(".", 1)[-1]
    return process.start()


def python_command(target: str, *args: str) -> list[str]:
    """The command line that runs a Python node with this interpreter.

    Args:
        target: "package.module" (run like ``python -m package.module``) or
            "package.module:function" (import it and call ``function()``, like a setup.py
            console-script entry point such as ``talker = demo.talker:main``).
        *args: command-line arguments for the node (sys.argv[1:]), e.g. "--ros-args", "-r", ...

    Raises:
        ValueError: the target is not in one of the two forms.
    """
    module, colon, function = target.partition(":")
    parts = module.split(".") + (function.split(".") if colon else [])
    if not all(part.isidentifier() for part in parts):
        raise ValueError(f"python_node target {target!r} is not 'package.module' or 'package.module:function' "
                         "(dotted Python names, like a setup.py entry point 'demo.talker:main')")
    if colon:
        code = ("import importlib, sys; "
                f"sys.argv[0] = {target!r}; "
                f"entry = importlib.import_module({module!r}); "
                + "".join(f"entry = entry.{name}; " for name in function.split("."))
                + "sys.exit(entry())")
        command = [sys.executable, "-c", code, *args]
    else:
        command = [sys.executable, "-m", module, *args]
    return command


