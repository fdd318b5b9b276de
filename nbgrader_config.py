# nbgrader settings of a student's lab (`make lab` serves this directory, and nbgrader's
# Validate button and Assignments panel read nbgrader_config.py from the server's working
# directory): the course's cell timeouts, so that Validate gives a self-check the time grading
# gives it; the course id and the lab's own exchange, .lab/exchange here, into which `make lab`
# releases the assignments (course_lib.notebook.student_lab.exchange).
from pathlib import Path

from course_lib.checks.validate import apply_student
from course_lib.notebook.student_lab.exchange import use_local_exchange

c = get_config()  # noqa: F821 (provided by nbgrader)
apply_student(c)
use_local_exchange(c, Path(__file__).resolve().parent)
