"""The checker's side of calling a student's function in a student process: the calls written
to a job folder, the outcomes read back (plain JSON and arrays, nothing pickled; course_lib.checks.student
is the other side)."""

from __future__ import annotations

import dataclasses
import json
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



def write_calls(job: Path, calls: list[tuple]) -> None:
    """Write the calls, (args, kwargs) each, as JOB/calls.json and their arrays as JOB/inputs.npz."""
    import numpy as np

    arrays, manifest = {}, []
    for index, (args, kwargs) in enumerate(calls):
        entry = []
        for position, arg in enumerate(args):
            key = f"c{index}_a{position}"
            arrays[key] = np.asarray(arg)
            entry.append(key)
        manifest.append({"args": entry, "kwargs": kwargs})
    np.savez(job / "inputs.npz", **arrays)
    (job / "calls.json").write_text(json.dumps(manifest))


def read_outcomes(job: Path, count: int, proc, timeout: float) -> list[Outcome]:
    """One Outcome per call, read from JOB/<i>.json and .npz; calls without a result say why (the
    process `proc` ended or ran out of its `timeout` seconds)."""
    import numpy as np

    outcomes = []
    for index in range(count):
        meta_path = job / f"{index}.json"
        if not meta_path.exists():
            if proc.exit_reason == "wall_seconds" or proc.returncode is None or proc.exit_reason == "stopped":
                why = f"did not return within {timeout:.0f} s (an endless loop?)"
            else:
                why = f"ended the process ({proc.describe_exit()}) before returning"
            log = last_lines(proc.log, 4)
            outcomes.append(Outcome(error=f"the call {why}. Last output:\n{log}"))
            outcomes.extend(Outcome(error="not run: an earlier call did not return") for _ in range(count - index - 1))
            break
        try:
            meta = json.loads(meta_path.read_text())
            arrays = np.load(job / f"{index}.npz", allow_pickle=False) if (job / f"{index}.npz").exists() else {}
            outcomes.append(Outcome(value=_decode(meta["value"], arrays), pytype=meta["value"].get("pytype", "?"),
                                    error=meta.get("error")))
        except (OSError, ValueError, KeyError, TypeError) as error:
            outcomes.append(Outcome(error=f"its result could not be read back ({error})"))
    return outcomes


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
