"""The grader's answer keys: one module per assignment, a function per question of its contract.

A check asks ``ctx.expected("<function>", *inputs)`` (course_lib.checks.answers); when graded,
the answer is the function of that name here, called with the generated inputs. These are
reference computations, so they live only on the instructor's side: the student package
(course_lib) never holds them, the grader's sandbox hides this folder from students' processes,
and self-checks use the answers recorded from them (``python -m autograder record-answers``).
Assignments whose checks need no computed answer (the expected crops of catdog_warp come from
the scene's ground truth) have no module here.
"""
