"""Child processes that never outlive the notebook, without ROS.

``supervised_process`` starts a program under ``supervisor`` (run by path, without course_lib's
imports), which keeps its log in bounded space (``bounded_log``), applies resource limits
(``process_limits``) and stops its whole process tree (``process_tree``); ``process_registry``
notes which named processes run on the machine. :mod:`course_lib.ros.processes` adds the ROS side.
"""
