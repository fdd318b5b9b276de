"""The course's grader (instructor side; never installed in students' environments).

Its modules by job, one line each; a group imports only what is listed above it (tests/test_repository.py
holds this list to the files and to their imports). The checks themselves are shared with the students'
self-checks: ``course_lib.checks``.

``sandbox/``: what keeps a submission's code from the grader, the course and other students.
- ``sandbox/namespaces.py``: the sandbox every process of a submission (and every hub server) runs in: ``unshare``
- ``sandbox/sandbox_entry.py``: what runs first inside its namespaces (``python -I -S``): loopback, mounts
- ``sandbox/run_as.py``: a command run as a student's uid (a script of the standard library only)
- ``sandbox/student_uid.py``: the checks' student processes, started as the worker's student uid
- ``sandbox/kernel.py``: the graded notebook's kernel, as that uid (``python -m autograder.sandbox.kernel``)
- ``sandbox/cell_watch.py``: nbgrader's Execute that stops a cell by its processor time, whatever the load
- ``sandbox/untrusted.py``: a student's folder, copied by root without following anything out of it
- ``sandbox/guard.py``: nbgrader's own autograde refuses (it would run the hidden checks in the student's kernel)

``results/``: what was handed in and what its grading recorded.
- ``results/submissions.py``: the submissions in submitted/ and the digest that says when to grade one again
- ``results/grade_result.py``: one submission's result (GradeResult), as recorded and reported
- ``results/store.py``: the recorded results (autograder.json), the gradebook's copy, the cache of unchanged ones
- ``results/gradebook.py``: the write-back into nbgrader's gradebook, as nbgrader's own autograde leaves it
- ``results/report.py``: COURSE_DIR/grading_report.csv: how each submission was graded, for the instructor

``builds/``: a submission's ROS 2 workspace, and the reference solutions.
- ``builds/notebook_writes.py``: the files a notebook writes (``%%writefile``, ``!mkdir -p``), without running it
- ``builds/workspace_build.py``: a submission's workspace built with colcon, in its sandbox, as the student's uid
- ``builds/caches.py``: the course's caches of built interface packages and of whole workspace builds
- ``builds/reference.py``: the reference solutions (assignments/reference_ws) as the source notebooks hold them

``answers/``: the answer keys the graded checks compare with.
- ``answers/<assignment>.py``: one per assignment with a key, a function per question of its contract

The course's nbgrader, at the top.
- ``config.py``: nbgrader's configuration of the course (each course's nbgrader_config.py loads it by this name)
- ``nbgrader_cli.py``: nbgrader's commands run in this process with the course's configuration

``grading/``: one submission, step by step.
- ``grading/pipeline.py``: the steps of one submission's grading (STEPS), each in the sandbox
- ``grading/intake.py``: is a submission gradable as handed in? Reasons that name the fix
- ``grading/staging.py``: private copies: the grader itself and the submitted files
- ``grading/work_folders.py``: the gradings' work folders, and the sweep of those whose process ended
- ``grading/early_checks.py``: the submission built and checked while nbgrader runs its notebook
- ``grading/hidden_checks.py``: the hidden checks, run outside the student's kernel, and their verdicts
- ``grading/hidden_checks_process.py``: their process (``python -m autograder.grading.hidden_checks_process``)
- ``grading/sandboxed_autograde.py``: the notebook's run in the sandbox (nbgrader's Autograde, in that process)
- ``grading/fork_server.py``: the warm process the notebook's run and the checks process are forked from
- ``grading/fork_client.py``: what stands for a run of the fork server inside the sandbox (standard library only)
- ``grading/outputs.py``: what a grading leaves in the course: the autograded notebooks, the grader's log

``term/``: the term's commands (``python -m autograder COMMAND``) and what they share.
- ``term/roster.py``: ``roster``: students from a roster CSV into the gradebook
- ``term/release.py``: ``release``: the course root, the student versions in release/, the exchange
- ``term/late.py``: due dates and late penalties (nbgrader's AssignLatePenalties plugin)
- ``term/collect.py``: ``collect``: an LMS download into submitted/ (nbgrader's zip_collect)
- ``term/grade.py``: ``grade``: the class graded in parallel, then the grading report and grades.csv
- ``term/feedback.py``: ``feedback``: per-student HTML feedback and its index page
- ``term/scores_only.py``: feedback with the hidden checks' scores, not their reasons (the hub, before the due date)
- ``term/export.py``: ``export``: COURSE_DIR/grades.csv for the LMS (also nbgrader's export plugin)
- ``term/record_answers.py``: ``record-answers``: the self-checks' answers, recorded from the answer keys
- ``term/lab_grading.py``: ``release-lab``, ``grade-lab``: graded feedback for a student alone (``make lab``)

The command line.
- ``__main__.py``: ``python -m autograder roster|release|release-lab|grade-lab|collect|grade|feedback|export|...``

Grading on submission is the hub's service (coursehub.grading_service, its queue coursehub.submit_queue); its
rules per assignment are ``autograder.config.GradeOnSubmit``.
"""
