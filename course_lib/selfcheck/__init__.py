"""Instant self-checks for the lesson tasks (the graded assignments have their own checks).

Each check returns a Verdict, which a notebook shows as one line (✔ or ✘ and what to do) and
which is true only when the answer is right. A check never raises on a wrong answer, so "Run
All" goes on to the end of a lesson. A stub left as it is gets "not done yet" and a hint; a
wrong answer gets what is wrong.

A lesson calls them as ``selfcheck.<name>``; they live by kind of answer:

- :mod:`.tasks`: a value or a plain function (tasks 1-4, lesson 03's picture corners);
- :mod:`.node_exercises`: a node class run in the notebook's session (lessons 01 and 01b);
- :mod:`.launch_exercise`: a YAML launch file (lesson 02b);
- :mod:`.brightness_package`: a package built and run as ``ros2 run`` (lesson 02);
- :mod:`.action_exercise`: an action client, against an action server of the check's (lesson 04);
- :mod:`.bag_exercise`: a function that reads a recorded bag (lesson 05);
- :mod:`.mobile_robot`: a function of a laser scan, on the simulated robot's scans (lesson 06);
- :mod:`.lesson_quiz`: the short quiz at the end of each lesson (``show_quiz``, ``check_quiz``),
  with course_lib.checks.multiple_choice (a question and a well-formed answer), which the graded
  quiz shares;
- :mod:`.verdicts`: the :class:`Verdict` they return and the helpers they share.
"""

from course_lib.selfcheck.action_exercise import find_pictures_exercise
from course_lib.selfcheck.bag_exercise import read_topic_exercise
from course_lib.selfcheck.brightness_package import (
                                                     BRIGHTNESS_ENTRY_POINT,
                                                     BRIGHTNESS_EXECUTABLE,
                                                     BRIGHTNESS_PACKAGE,
                                                     CHECK_CAMERA_TOPIC,
                                                     PYTHON_DEPENDENCIES,
                                                     brightness_package_exercise,
)
from course_lib.selfcheck.launch_exercise import task_launch_yaml
from course_lib.selfcheck.lesson_quiz import check_quiz, show_quiz
from course_lib.selfcheck.mobile_robot import nearest_obstacle_exercise
from course_lib.selfcheck.node_exercises import publisher_exercise, subscriber_exercise
from course_lib.selfcheck.tasks import (
                                                     task1_node_name,
                                                     task2_echo,
                                                     task3_brightness_on_change,
                                                     task4_order_corners,
                                                     task_picture_corners,
)
from course_lib.selfcheck.verdicts import PLACEHOLDERS, Verdict

__all__ = ["BRIGHTNESS_ENTRY_POINT", "BRIGHTNESS_EXECUTABLE", "BRIGHTNESS_PACKAGE", "CHECK_CAMERA_TOPIC",
           "PLACEHOLDERS", "PYTHON_DEPENDENCIES", "Verdict", "brightness_package_exercise", "check_quiz",
           "find_pictures_exercise", "nearest_obstacle_exercise", "publisher_exercise", "read_topic_exercise",
           "show_quiz", "subscriber_exercise", "task1_node_name", "task2_echo", "task3_brightness_on_change",
           "task4_order_corners", "task_launch_yaml", "task_picture_corners"]
