"""The course's grader (instructor side; never installed in students' environments).

- ``python -m autograder release|grade|feedback COURSE_DIR``: the instructor's commands
  (``autograder.grading``, ``autograder.feedback``); ``record-answers``: record the self-checks'
  answers from the answer keys (``autograder.record``).
- ``autograder.answers.<assignment>``: the answer keys the graded checks compare with.
- ``autograder.reference``: the reference solutions as the source notebooks hold them.
- ``autograder.config``, ``autograder.kernel``: nbgrader's configuration and the sandboxed kernel.

The checks themselves are shared with the students' self-checks: ``course_lib.checks``.
"""
