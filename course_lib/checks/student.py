"""Runs a student's code for the checks: one process that serves many calls, one at a time
(course_lib.checks.student_server is the checker's side).

``python -m course_lib.checks.student serve JOB`` waits for requests JOB/in/<n>.json (n = 0, 1,
2, ...; their arrays in JOB/in/<n>.npz), handles each in turn and writes its answer as
JOB/out/<n>.json (how the value was encoded, or the error) and JOB/out/<n>.npz (its arrays) as
soon as it is done, so that answers given before a later hang or crash survive. A request is

- ``{"kind": "import", "module": M}``: import the student's module M from the working directory;
- ``{"kind": "call", "module": M, "function": F, "args": [keys of in/<n>.npz], "kwargs": {...}}``:
  call M.F(*args, **kwargs);
- ``{"kind": "endpoints", "module": M, "class": C}``: construct node class C without arguments
  (not spun) and answer the QoS of its publishers and subscriptions, which DDS discovery does not
  tell another process (such as the queue depth).

Nothing is pickled: the checker reads plain JSON and arrays only. The checker writes JOB/in,
the student's process JOB/out (at grading they belong to different uids).
"""

from __future__ import annotations

import importlib
import json
import os
import sys
import time
import traceback
from pathlib import Path


def _encode(value, arrays: dict, prefix: str) -> dict:
    import numpy as np

    pytype = type(value).__name__
    if value is None:
        return {"type": "none", "pytype": pytype}
    if isinstance(value, (bool, int, float, np.integer, np.floating, np.bool_)):
        plain = value.item() if isinstance(value, np.generic) else value
        return {"type": "scalar", "pytype": pytype, "value": plain}
    if isinstance(value, np.ndarray):
        key = f"{prefix}"
        arrays[key] = value
        return {"type": "array", "pytype": pytype, "key": key}
    if isinstance(value, dict):
        items = {str(key): _encode(item, arrays, f"{prefix}_{index}")
                 for index, (key, item) in enumerate(value.items())}
        return {"type": "dict", "pytype": pytype, "items": items}
    return {"type": "other", "pytype": pytype, "repr": repr(value)[:200]}


def _plain(value):
    return tuple(value) if isinstance(value, list) else value


def _call(request: dict, inputs: Path, arrays: dict) -> dict:
    import numpy as np

    module = importlib.import_module(request["module"])
    target = getattr(module, request["function"], None)
    if target is None:
        return {"error": f"{request['module'].rsplit('.', 1)[-1]}.py has no function {request['function']}()"}
    args = []
    if request["args"]:
        with np.load(inputs, allow_pickle=False) as stored:
            args = [stored[key] for key in request["args"]]
    kwargs = {key: _plain(value) for key, value in request["kwargs"].items()}
    return {"value": _encode(target(*args, **kwargs), arrays, "r")}


def _endpoints(request: dict) -> dict:
    """{"endpoints": {"publishers"|"subscriptions": [{"topic", "type", "depth", "history",
    "reliability", "durability"}]}} of node class request["class"], constructed without arguments."""
    import rclpy

    from course_lib.ros import teardown

    module = importlib.import_module(request["module"])
    rclpy.init()
    try:
        node = getattr(module, request["class"])()
        report = {}
        for kind, endpoints_of_kind in (("publishers", node.publishers), ("subscriptions", node.subscriptions)):
            report[kind] = [{"topic": e.topic_name, "type": f"{e.msg_type.__module__}.{e.msg_type.__name__}",
                             "depth": e.qos_profile.depth, "history": e.qos_profile.history.name,
                             "reliability": e.qos_profile.reliability.name,
                             "durability": e.qos_profile.durability.name}
                            for e in endpoints_of_kind if not e.topic_name.startswith(("/rosout", "/parameter_events"))]
        teardown.destroy_node(node)  # with the action servers a node class makes in __init__
    finally:
        rclpy.try_shutdown()
    return {"endpoints": report}


def answer(request: dict, inputs: Path, arrays: dict) -> dict:
    """The answer to one request (see the module docstring); the student's exceptions become its error."""
    server = os.getpid()
    try:
        if request["kind"] == "import":
            importlib.import_module(request["module"])
            return {}
        if request["kind"] == "endpoints":
            return _endpoints(request)
        return _call(request, inputs, arrays)
    except BaseException as error:  # SystemExit and KeyboardInterrupt are the student's too
        lines = traceback.format_exception(type(error), error, error.__traceback__)
        return {"error": f"{type(error).__name__}: {error}".strip(), "traceback": "".join(lines[-3:])}
    finally:
        if os.getpid() != server:  # a process the student's code forked: only the server answers
            os._exit(0)


def serve(job: Path) -> int:
    """Answer the requests of JOB/in in turn, forever (the checker stops this process)."""
    import numpy as np

    sys.path.insert(0, os.getcwd())
    inbox, outbox = job / "in", job / "out"
    number = 0
    while True:
        request_path, pause = inbox / f"{number}.json", 0.001
        while not request_path.exists():  # polled: the checker and this process may be different uids
            time.sleep(pause)
            pause = min(pause * 2, 0.02)
        request = json.loads(request_path.read_text())
        arrays: dict = {}
        meta = answer(request, inbox / f"{number}.npz", arrays)
        if arrays:
            np.savez(outbox / f"{number}.npz", **arrays)
        (outbox / f"{number}.json.tmp").write_text(json.dumps(meta))
        os.replace(outbox / f"{number}.json.tmp", outbox / f"{number}.json")
        number += 1


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2 or argv[0] != "serve":
        print("usage: python -m course_lib.checks.student serve JOB_DIR", file=sys.stderr)
        return 2
    return serve(Path(argv[1]))


if __name__ == "__main__":
    sys.exit(main())
