"""The course's autograder: graded checks, nbgrader configuration, sandboxed parallel grading, feedback.

- ``autograder.checks.<assignment>``: the checks of one assignment. Students call them from the
  notebook (``checks.selfcheck("values")``) and nbgrader's hidden test cells call them at grading
  time (``checks.grade("values")``): one piece of code for both.
- ``autograder.harness``: what a check is (points, timeout, one-line description) and how it
  runs: in a separate process, with the student's code in yet another process.
- ``python -m autograder roster|release|collect|grade|feedback|export COURSE_DIR``: the
  instructor's commands (``autograder.roster``, ``autograder.grading``, ``autograder.collect``,
  ``autograder.feedback``, ``autograder.export``); ``autograder.gradebook`` writes the grades into
  nbgrader's gradebook as nbgrader's autograde would, ``autograder.late`` holds due dates and late
  penalties, ``autograder.guard`` makes nbgrader's own autograde refuse outside the grader.
"""

__all__ = ["harness", "checks"]
