"""The course for a class: a JupyterHub on one server, the nbgrader exchange, one network and
shared-memory namespace per student (instructor side; runs from this repository, like autograder/).

- ``course``: the course's settings (``<hub dir>/course.json``) and where everything lives;
- ``accounts``: Linux accounts and the course's group from a roster;
- ``exchange``: nbgrader's exchange and the per-user nbgrader/JupyterLab settings;
- ``forward``: byte forwarding between a TCP port and a unix socket;
- ``spawner``: the JupyterHub spawner that starts each server in namespaces of its own;
- ``singleuser``: what runs inside those namespaces, as the user (the hub bridge, then the server);
- ``jupyterhub_config``: the hub's configuration, read from course.json;
- ``instructor``: the instructor's steps (release, collect, grade, feedback) as commands;
- ``grading_service``: the hub's service that grades each submission minutes after Submit, with
  ``inbound`` (the exchange's submissions), ``submit_queue`` (their durable queue), ``grading_job`` (one
  submission; the feedback), ``grading_status`` (the students' page) and ``limited_submit`` (Submit past the
  attempts refused);
- ``__main__``: ``python -m coursehub create-course|start|release|collect|grade|feedback|remove-course``.
"""
