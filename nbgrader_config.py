# nbgrader settings of a student's lab (`make lab` serves this directory, and nbgrader's
# Validate button reads nbgrader_config.py from the server's working directory): the course's
# cell timeouts, so that Validate gives a self-check the time grading gives it.
from course_lib.checks.validate import apply_student

c = get_config()  # noqa: F821 (provided by nbgrader)
apply_student(c)

# Validate on a lesson (no graded cells) stops with a message that points at its self-checks,
# instead of nbgrader's "Success! Your notebook passes all the tests." (course_lib.student_lab).
from course_lib.student_lab import refuse_lessons  # noqa: E402

c.Execute.on_notebook_start = refuse_lessons
