"""What a student sees in JupyterLab besides the lesson's own cells.

``live`` (live image views and plots), ``rqt_graph`` (the graph drawn), ``progress`` (a line under
a long-running cell), ``doctor`` (the environment check), and ``student_lab`` (the lab's
configuration and Jupyter server extension: nbgrader's student side, the lab's exchange, its
terminal).
"""
