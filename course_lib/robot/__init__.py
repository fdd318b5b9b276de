"""The course's mobile robot: a differential-drive robot of a Husky's size with a 2D laser scanner,
simulated by MuJoCo (``simulation``, no ROS; ``husky``: its sizes and limits; the worlds in
``worlds/``), its ROS 2 node (``simulator_node``), tf2's buffer for the pip install (``tf_buffer``)
and what ``make setup`` installs for it (``install``: tf2_msgs and the ROS package robot_sim)."""
