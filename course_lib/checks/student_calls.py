"""The checker's side of calling a student's function in a student process: requests written
to the process's inbox, answers read back from its outbox (plain JSON and arrays, nothing
pickled; course_lib.checks.student is the other side, course_lib.checks.student_server the process)."""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path


@dataclasses.dataclass
class Outcome:
    """What one call of a student's function gave: a value, or the error that prevented one.

    Attributes:
        value: the returned value (numpy arrays, Python scalars of the returned type, dicts).
        pytype: the name of the returned value's type ("int", "float", "ndarray", ...).
        error: None, or how the call failed ("NotImplementedError: ...", "the process was killed ...").
    """

    value: object = None
    pytype: str = "NoneType"
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None



def write_request(inbox: Path, number: int, request: dict, arrays: dict | None = None) -> None:
    """Write request `number` for the student's process: its arrays as INBOX/<n>.npz first, then
    INBOX/<n>.json (renamed into place: the student's process never reads half a request)."""
    import numpy as np

    if arrays:
        np.savez(inbox / f"{number}.tmp.npz", **{key: np.asarray(value) for key, value in arrays.items()})
        os.replace(inbox / f"{number}.tmp.npz", inbox / f"{number}.npz")
    (inbox / f"{number}.json.tmp").write_text(json.dumps(request))
    os.replace(inbox / f"{number}.json.tmp", inbox / f"{number}.json")


def call_request(module: str, function: str, args, kwargs: dict) -> tuple[dict, dict]:
    """(request, arrays) of one call of `function` of `module`: args may hold numpy arrays,
    kwargs plain JSON values."""
    arrays = {f"a{position}": arg for position, arg in enumerate(args)}
    return {"kind": "call", "module": module, "function": function, "args": list(arrays), "kwargs": kwargs}, arrays


def read_answer(outbox: Path, number: int) -> dict | None:
    """The student process's answer to request `number` ({"value"|"error"|"endpoints": ...}), its
    arrays decoded; None while there is none."""
    import numpy as np

    meta_path = outbox / f"{number}.json"
    if not meta_path.exists():
        return None
    try:
        meta = json.loads(meta_path.read_text())
        if "value" in meta:
            npz = outbox / f"{number}.npz"
            arrays = np.load(npz, allow_pickle=False) if npz.exists() else {}
            meta["pytype"] = meta["value"].get("pytype", "?")
            meta["value"] = _decode(meta["value"], arrays)
        return meta
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        return {"error": f"its result could not be read back ({error})"}


def _decode(encoded: dict, arrays):
    kind = encoded["type"]
    if kind == "array":
        return arrays[encoded["key"]]
    if kind == "scalar":
        return encoded["value"]
    if kind == "dict":
        return {key: _decode(value, arrays) for key, value in encoded["items"].items()}
    if kind == "none":
        return None
    return encoded.get("repr")


def last_lines(text: str, lines: int) -> str:
    """The last `lines` lines of a process's output, or "(no output)"."""
    text = text.strip()
    return "\n".join(text.splitlines()[-lines:]) if text else "(no output)"
