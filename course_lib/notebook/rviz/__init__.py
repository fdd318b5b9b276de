"""RViz in a JupyterLab cell: displays of ROS 2 topics drawn in 3D in a fixed frame, through TF.

``RViz`` (``view``) is the view and what a notebook calls; ``displays`` holds what each display
keeps and draws; ``geometry``, ``markers``, ``clouds`` and ``transforms`` are the plain numpy
underneath (messages to points, lines, shapes and texts in the fixed frame), tested apart from the
widget; ``config`` reads and writes configuration files (the course's YAML, RViz2's ``.rviz``).
``js/rviz.js`` is the browser's side, bundled with three.js into ``static/rviz.js`` by ``make setup``.
"""

from course_lib.notebook.rviz.view import RViz, stop_all

__all__ = ["RViz", "stop_all"]
