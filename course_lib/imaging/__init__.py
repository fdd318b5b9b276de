"""Camera pictures and the marker board: what the vision lessons and the virtual camera show.

- ``images``: ``sensor_msgs/Image`` and ``CompressedImage`` to numpy and back;
- the board: ``marker_board`` (the marker convention, written once), ``boards`` (the printed
  board; ``drawn_cache`` keeps the default board's drawing on disk), ``pictures`` and ``photos``
  (the pictures on it);
- the world the camera sees: ``camera_views`` (poses), ``table`` (the cluttered table),
  ``scenes`` (seeded scenes with ground truth, the camera's path), ``camera`` (the webcam node);
- ``drawing``: markers, image grids and plots drawn for the lessons (``from course_lib import
  vision`` in a notebook);
- ``frame_memory``: processes that draw many frames (the webcam node, the grader's checks) reuse
  the memory of freed frames.
"""
