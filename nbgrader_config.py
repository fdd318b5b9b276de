# nbgrader settings of a student's lab (`make lab` serves this directory, and nbgrader's
# Validate button reads nbgrader_config.py from the server's working directory): the course's
# cell timeouts, so that Validate gives a self-check the time grading gives it.
from course_lib.checks.validate import apply_student

c = get_config()  # noqa: F821 (provided by nbgrader)
apply_student(c)
