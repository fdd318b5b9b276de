"""The course's mobile robot: a differential-drive robot of a Husky's size with a 2D laser scanner,
simulated by MuJoCo (``simulation``, no ROS; ``husky``: its sizes and limits; the worlds in
``robot_sim/worlds/``), its ROS 2 node (``simulator_node``), tf2's buffer for the pip install (``tf_buffer``),
the stand-ins of tools PyPI lacks (``static_transform_publisher``, ``tf2_echo``, ``view_frames`` with
``frame_graph``, ``teleop_keyboard``), the notebook's keyboard pad (``teleop_widget``) and what
``make setup`` installs for it (``install``: tf2_msgs, robot_sim and the stand-ins' packages)."""
