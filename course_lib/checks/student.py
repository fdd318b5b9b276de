"""Runs a student's code in a process of its own, for a check (course_lib.checks.context.Context).

``python -m course_lib.checks.student call MODULE FUNCTION JOB`` calls a function;
``python -m course_lib.checks.student endpoints MODULE CLASS JOB`` constructs a node class and reports
the QoS of its publishers and subscriptions (what DDS discovery does not tell another process,
such as the queue depth).

The check that starts it (Context.call) wrote JOB/calls.json and JOB/inputs.npz. This
process imports the student's module from its working directory, touches JOB/imported, then for
call i writes JOB/i.json (how the value was encoded, or the error) and JOB/i.npz (its arrays)
as soon as the call returns, so results of earlier calls survive a later hang or crash.
Nothing is pickled: the checker reads plain JSON and arrays only.
"""

from __future__ import annotations

import importlib
import json
import os
import sys
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
        items = {str(key): _encode(item, arrays, f"{prefix}_{index}") for index, (key, item) in enumerate(value.items())}
        return {"type": "dict", "pytype": pytype, "items": items}
    return {"type": "other", "pytype": pytype, "repr": repr(value)[:200]}


def _plain(value):
    return tuple(value) if isinstance(value, list) else value


def _import_student(module: str, job: Path):
    """Import the student's module from the working directory; JOB/imported tells the check it did."""
    sys.path.insert(0, os.getcwd())
    mod = importlib.import_module(module)
    (job / "imported").touch()
    return mod


def call(module: str, function: str, job: Path) -> int:
    import numpy as np

    mod = _import_student(module, job)
    target = getattr(mod, function, None)
    calls = json.loads((job / "calls.json").read_text())
    inputs = np.load(job / "inputs.npz", allow_pickle=False)
    for index, spec in enumerate(calls):
        args = [inputs[key] for key in spec["args"]]
        kwargs = {key: _plain(value) for key, value in spec["kwargs"].items()}
        arrays: dict = {}
        if target is None:
            meta = {"value": {"type": "none"}, "error": f"{module}.py has no function {function}()"}
        else:
            try:
                value = target(*args, **kwargs)
                meta = {"value": _encode(value, arrays, f"r{index}")}
            except BaseException as error:  # SystemExit and KeyboardInterrupt are the student's too
                lines = traceback.format_exception(type(error), error, error.__traceback__)
                meta = {"value": {"type": "none"}, "error": f"{type(error).__name__}: {error}".strip(),
                        "traceback": "".join(lines[-3:])}
        if arrays:
            np.savez(job / f"{index}.npz", **arrays)
        (job / f"{index}.json.tmp").write_text(json.dumps(meta))
        os.replace(job / f"{index}.json.tmp", job / f"{index}.json")
    return 0


def endpoints(module: str, class_name: str, job: Path) -> int:
    """Construct node class `class_name` without arguments (not spun) and write JOB/endpoints.json:
    {"publishers"|"subscriptions": [{"topic", "type", "depth", "history", "reliability", "durability"}]}."""
    import rclpy

    mod = _import_student(module, job)
    rclpy.init()
    try:
        node = getattr(mod, class_name)()
        report = {}
        for kind, endpoints_of_kind in (("publishers", node.publishers), ("subscriptions", node.subscriptions)):
            report[kind] = [{"topic": e.topic_name, "type": f"{e.msg_type.__module__}.{e.msg_type.__name__}",
                             "depth": e.qos_profile.depth, "history": e.qos_profile.history.name,
                             "reliability": e.qos_profile.reliability.name,
                             "durability": e.qos_profile.durability.name}
                            for e in endpoints_of_kind if not e.topic_name.startswith(("/rosout", "/parameter_events"))]
        node.destroy_node()
    finally:
        rclpy.try_shutdown()
    (job / "endpoints.json").write_text(json.dumps(report))
    return 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    commands = {"call": call, "endpoints": endpoints}
    if len(argv) != 4 or argv[0] not in commands:
        print("usage: python -m course_lib.checks.student call MODULE FUNCTION JOB_DIR\n"
              "       python -m course_lib.checks.student endpoints MODULE CLASS JOB_DIR", file=sys.stderr)
        return 2
    return commands[argv[0]](argv[1], argv[2], Path(argv[3]))


if __name__ == "__main__":
    sys.exit(main())
