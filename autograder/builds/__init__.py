"""A submission's ROS 2 workspace: predicted from the notebook, built with colcon, its builds kept;
and the reference solutions the grader builds beside it."""
