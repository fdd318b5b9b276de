"""course_lib: the helper package of the ROS 2 Jazzy + OpenCV course.

Notebooks open with one import cell, for example::

    from course_lib import doctor, session, graph, images

The modules live in subpackages named after their job (``ros``, ``supervision``, ``imaging``,
``notebook``; ``launch``, ``ros2cli``, ``checks`` and ``selfcheck`` are subpackages of their own).
A notebook reaches each module by its short name, as before the grouping: ``course_lib.session``
is :mod:`course_lib.ros.session`, ``course_lib.vision`` is :mod:`course_lib.imaging.drawing`.
The course's own code imports the full paths. Modules are imported lazily, so ``import
course_lib`` stays fast and does not start ROS.
"""

import importlib

__version__ = "0.1.0"

from course_lib.ros import rosenv as _rosenv

_rosenv.prepare_current_process()

#: A notebook's short name of each module -> where it lives in course_lib.
SHORT_NAMES = {
    **{name: f"ros.{name}" for name in (
        "ament", "bag_files", "bag_metadata", "colcon", "discovery", "graph", "interfaces", "message_yaml",
        "node_logs", "package_files", "parameters", "pkg_create", "processes", "rates", "rosenv", "session", "sigterm",
        "underlay", "wheelfix", "workspace")},
    **{name: f"supervision.{name}" for name in (
        "bounded_log", "process_limits", "process_registry", "process_tree", "supervised_process", "supervisor")},
    **{name: f"imaging.{name}" for name in (
        "boards", "camera", "camera_views", "images", "marker_board", "pan_camera", "photos", "pictures", "scenes",
        "table")},
    "vision": "imaging.drawing",
    **{name: f"notebook.{name}" for name in ("doctor", "live", "rqt_graph", "student_lab")},
    **{name: name for name in ("launch", "progress", "selfcheck", "waiting")},
}


def __getattr__(name):
    if name in SHORT_NAMES:
        module = importlib.import_module(f"{__name__}.{SHORT_NAMES[name]}")
        globals()[name] = module  # the next lookup is a plain attribute
        return module
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(SHORT_NAMES))
