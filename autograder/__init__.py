"""The course's grader (instructor side; never installed in students' environments).

- ``python -m autograder roster|release|collect|grade|feedback|export COURSE_DIR``: the
  instructor's commands (``autograder.roster``, ``autograder.release``, ``autograder.collect``,
  ``autograder.grading``, ``autograder.feedback``, ``autograder.export``);
  ``autograder.gradebook`` writes the grades into nbgrader's gradebook as nbgrader's autograde
  would, ``autograder.late`` holds due dates and late penalties, ``autograder.guard`` makes
  nbgrader's own autograde refuse outside the grader; ``record-answers``: record the
  self-checks' answers from the answer keys (``autograder.record``).
- ``autograder.answers.<assignment>``: the answer keys the graded checks compare with.
- ``autograder.reference``: the reference solutions as the source notebooks hold them.
- ``autograder.config``, ``autograder.kernel``: nbgrader's configuration and the sandboxed kernel.
- Grading: ``autograder.release`` (course root, release), ``autograder.nbgrader_cli``,
  ``autograder.submissions`` (what was handed in, its digest), ``autograder.sandbox`` and
  ``autograder/sandbox_entry.py`` (isolation), ``autograder.staging`` (private copies),
  ``autograder.pipeline`` (one submission, step by step), ``autograder.work_folders`` (its work
  folder, and those of gradings cut short), ``autograder.hidden_checks`` (the hidden checks and
  their verdicts), ``autograder.outputs`` (autograded notebooks, logs),
  ``autograder.result``, ``autograder.store`` (recorded results, cache), ``autograder.grading``
  (the whole class, in parallel).
- ``python -m autograder grade-lab``: a student alone grades what they submitted in `make lab`'s exchange
  and gets its feedback there (``autograder.lab_grading``).
- Grading on submission (the hub's service, coursehub.grading_service): ``autograder.submit_queue``
  (its durable queue), ``autograder.scores_only`` (feedback without the verdicts before the due
  date); the rules per assignment are ``autograder.config.GradeOnSubmit``.

The checks themselves are shared with the students' self-checks: ``course_lib.checks``.
"""
