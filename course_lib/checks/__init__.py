"""The assignments' checks, shared by the students' self-checks and the grader.

- ``course_lib.checks.<assignment>``: the checks of one assignment (``brightness``, ``pubsub``,
  ``catdog_warp``). A notebook imports one as ``checks`` and calls ``checks.selfcheck("values")``.
  ``brightness_throughput``: the brightness node's throughput, judged against a yardstick node.
- ``registry`` (what a check is), ``runner`` (how it runs: its own process, ``check_process``),
  ``context`` (what a check gets), ``student_server``/``student_calls``/``student_processes`` (the
  student's code in another process, one per module serving many calls), ``probe`` (the checker's
  ROS node), ``result`` (the verdict).
- ``answers``: where a check's expected answers come from: the grader's answer key when graded
  (instructor side: the folder the grader hands over, contract.ANSWER_KEYS_ENV), answers
  recorded from it in a self-check.
- ``student``: runs the student's code for a check; ``validate``: the cell timeouts of Validate.

No reference solution and no answer key is in this package: students have it.
"""
