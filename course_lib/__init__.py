"""course_lib: the helper package of the ROS 2 Jazzy + OpenCV course.

Notebooks open with one import cell, for example::

    from course_lib import doctor, session, graph, images

Modules are imported lazily, so ``import course_lib`` stays fast and does not start ROS.
"""

import importlib

__version__ = "0.1.0"

from course_lib import rosenv as _rosenv

_rosenv.prepare_current_process()

_MODULES = ("ament", "boards", "camera", "camera_views", "colcon", "discovery", "doctor", "graph",
            "images", "interfaces", "launch", "live", "marker_board", "message_yaml", "parameters", "photos",
            "pictures", "pkg_create", "processes", "rates", "rosenv", "rqt_graph", "scenes", "selfcheck", "session",
            "table", "vision", "waiting", "wheelfix", "workspace")


def __getattr__(name):
    if name in _MODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_MODULES))
