"""How long a wait may last in this run mode: in a live notebook, under the test suite, under grading.

A lesson's loop that runs until interrupted (session.spin_for(), a node's spin) would hang a test
or a grading run: time_limit caps it there. The wait for the answer of a server that was found
ends on the answer, and its limit is only a backstop: answer_limit keeps it far from any answer's
time under the test suite, where a busy machine must not decide a test.
"""

from __future__ import annotations

from course_lib.ros import rosenv

#: Longest run, in seconds, of a wait that would last forever (or long) in a live notebook,
#: when the test suite or CI runs the notebook (rosenv.under_test()).
TEST_TIME_LIMIT = 2.0
#: The same limit while the autograder runs a submission (rosenv.under_grading()).
GRADING_TIME_LIMIT = 5.0
#: Seconds that a wait for the answer of a server that was found (a service's response, an
#: action goal's acceptance and result) may last at least under the test suite (answer_limit).
ANSWER_BACKSTOP = 60.0


def time_limit(seconds: float | None) -> float | None:
    """How long a lesson loop may run in this run mode.

    Args:
        seconds: the live duration; None means "until interrupted".

    Returns:
        ``seconds`` in a live notebook; at most TEST_TIME_LIMIT under test and at most
        GRADING_TIME_LIMIT under grading (the smaller one when both flags are set).
    """
    limits = []
    if rosenv.under_test():
        limits.append(TEST_TIME_LIMIT)
    if rosenv.under_grading():
        limits.append(GRADING_TIME_LIMIT)
    if not limits:
        return seconds
    if seconds is None:
        return min(limits)
    return min([seconds] + limits)


def answer_limit(seconds: float | None) -> float | None:
    """How long to wait for the answer of a server that was found, given the wait's ``seconds``
    otherwise (None: as long as it takes).

    The answer ends the wait, and comes unless the server is broken: the limit is only a
    backstop, so under the test suite it is at least ANSWER_BACKSTOP, far from any answer's time
    on a busy machine (a busy machine must not decide a test). Live and under grading (where a
    notebook's waits stay short) it is ``seconds``.
    """
    if rosenv.under_test() and not rosenv.under_grading():
        return ANSWER_BACKSTOP if seconds is None else max(seconds, ANSWER_BACKSTOP)
    return seconds
