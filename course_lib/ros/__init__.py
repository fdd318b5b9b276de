"""ROS plumbing: what the ``ros2`` command, ``colcon`` and a notebook's rclpy code rest on.

- the notebook's ROS session and what runs on its tool node: ``session``, ``node_logs``,
  ``discovery``, ``graph``, ``rates``, ``parameters``, ``message_yaml``, ``interfaces``;
  ``teardown`` (a node destroyed with its action clients and servers, so it leaves the graph);
- node processes (``processes``: a supervised process that is a ROS node in its own domain);
- the environment of every ROS process and the pip install's repairs: ``rosenv`` (with
  ``fastdds_large_data.xml``), ``underlay``, ``wheelfix``;
- packages and workspaces: ``ament``, ``pkg_create``, ``package_files``, ``colcon``, ``workspace``;
- rosbag2 bags: ``bag_files``, ``bag_metadata``.
"""
