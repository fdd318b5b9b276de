"""The course's grader (instructor side; never installed in students' environments).

- ``python -m autograder roster|release|collect|grade|feedback|export COURSE_DIR``: the
  instructor's commands (``autograder.term.roster``, ``autograder.term.release``, ``autograder.term.collect``,
  ``autograder.term.grade``, ``autograder.term.feedback``, ``autograder.term.export``);
  ``autograder.results.gradebook`` writes the grades into nbgrader's gradebook as nbgrader's autograde
  would, ``autograder.term.late`` holds due dates and late penalties, ``autograder.sandbox.guard`` makes
  nbgrader's own autograde refuse outside the grader; ``record-answers``: record the
  self-checks' answers from the answer keys (``autograder.term.record_answers``).
- ``autograder.answers.<assignment>``: the answer keys the graded checks compare with.
- ``autograder.builds.reference``: the reference solutions as the source notebooks hold them.
- ``autograder.config``, ``autograder.sandbox.kernel``: nbgrader's configuration and the sandboxed kernel.
- Grading: ``autograder.term.release`` (course root, release), ``autograder.nbgrader_cli``,
  ``autograder.results.submissions`` (what was handed in, its digest), ``autograder.sandbox.namespaces`` and
  ``autograder/sandbox/sandbox_entry.py`` (isolation), ``autograder.grading.staging`` (private copies),
  ``autograder.grading.pipeline`` (one submission, step by step), ``autograder.grading.work_folders`` (its work
  folder, and those of gradings cut short), ``autograder.grading.hidden_checks`` (the hidden checks and
  their verdicts), ``autograder.grading.outputs`` (autograded notebooks, logs),
  ``autograder.results.grade_result``, ``autograder.results.store`` (recorded results, cache), ``autograder.term.grade``
  (the whole class, in parallel).
- ``python -m autograder grade-lab``: a student alone grades what they submitted in `make lab`'s exchange
  and gets its feedback there (``autograder.term.lab_grading``).
- Grading on submission (the hub's service, coursehub.grading_service): ``coursehub.submit_queue``
  (its durable queue), ``autograder.term.scores_only`` (feedback without the verdicts before the due
  date); the rules per assignment are ``autograder.config.GradeOnSubmit``.

The checks themselves are shared with the students' self-checks: ``course_lib.checks``.
"""
