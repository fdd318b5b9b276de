"""Zoo submissions of the pubsub assignment: mistakes in the packages, not in the code.

Few submissions, several mistakes each (every submission costs a whole grading run): each entry
has edits of the reference packages (see tests/support/zoo/__init__.py), the expected points per check
(a number or a (low, high) range) and phrases the feedback page must show.
"""

from __future__ import annotations


def entries(course_dir: str = "") -> dict[str, dict]:
    return {
        # A package.xml without the message package, and a setup.py that installs the subscriber
        # under another name: the build succeeds; each mistake costs its items, and the feedback
        # names each. (A message field of another type is judged from the .msg file, without a
        # build, in tests/course_lib/checks/test_check_packages.py: here it made the grader build the interface
        # package again, CMake and C compilers, a third of the zoo's processor time.)
        "pubsub_packaging": dict(
            edits=[("  <depend>tutorial_interfaces</depend>\n", ""),
                   ("'topic_subscriber = pubsub.topic_subscriber:main'",
                    "'subscriber = pubsub.topic_subscriber:main'")],
            scores={"publisher": (3, 4.5), "subscriber": 0, "together": 0},
            reasons=["add &lt;depend&gt;tutorial_interfaces&lt;/depend&gt;",
                     "has no executable 'topic_subscriber'"]),
        # setup.py does not run: nothing builds, every check that runs a node gives 0 and quotes
        # the error.
        "pubsub_build_error": dict(
            edits=[("package_name = 'pubsub'", "package_name = 'pubsub'(")],
            scores={"publisher": 0, "subscriber": 0, "together": 0},
            reasons=["your workspace did not build", "colcon build failed in package 'pubsub'"]),
    }
