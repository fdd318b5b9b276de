"""``python -m course_lib.launch ...``: the same as ``ros2 launch ...``."""

import sys

from course_lib.launch import main

sys.exit(main())
