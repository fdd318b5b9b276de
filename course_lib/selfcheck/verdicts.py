"""What every self-check returns (:class:`Verdict`), and the helpers they share: a stub left
as it is (:func:`_not_done`), a call of a student's function that may raise (:func:`_call`).
"""

from __future__ import annotations

import dataclasses

from course_lib.checks.multiple_choice import PLACEHOLDERS


@dataclasses.dataclass(frozen=True)
class Verdict:
    ok: bool
    text: str

    def __bool__(self) -> bool:
        return self.ok

    def __str__(self) -> str:
        return ("✔ " if self.ok else "✘ ") + self.text

    def _repr_pretty_(self, printer, cycle):  # how IPython shows it as a cell's result
        printer.text(str(self))


def _verdict(ok: bool, text: str) -> Verdict:
    return Verdict(ok, text)


def _not_done(answer, hint: str) -> Verdict | None:
    if any(answer is p or (isinstance(answer, str) and answer == p) for p in PLACEHOLDERS):
        return _verdict(False, "Not done yet. " + hint)
    return None


def _not_a_function(function, name: str, hint: str) -> Verdict | None:
    """A Verdict when the answer to a function task is a stub ("not done yet" and `hint`) or no
    function (the function `name` called, say); None when it is a function."""
    if (result := _not_done(function, hint)) is not None:
        return result
    if not callable(function):
        return _verdict(False, f"Pass the function itself ({name}, without brackets), not a {type(function).__name__}.")
    return None


def _call(function, *args):
    """(result, None) or (None, a Verdict naming the exception) for one call of a student's function."""
    import warnings

    import numpy as np

    try:
        # Overflow warnings would only repeat what the verdict explains.
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            return function(*args), None
    except NotImplementedError:
        return None, _verdict(False, "Not done yet: replace the raise NotImplementedError with your code.")
    except Exception as error:  # a check never raises on a wrong answer
        shown = ", ".join(repr(a.tolist() if hasattr(a, "tolist") and getattr(a, "ndim", 0) else a) for a in args)
        return None, _verdict(False, f"Calling it with ({shown}) raised {type(error).__name__}: {error}")
