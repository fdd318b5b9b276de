#!/bin/sh
# A student's server in the pod: the ROS variables a notebook gets from `import course_lib` (the
# Fast DDS set-up for camera frames, the discovery range), as `make lab` gives them, so that
# terminals and `!` commands have them too; then JupyterHub's single-user server.
set -e
eval "$(python -m course_lib env)"
[ -d "$HOME/notebooks" ] || cp -r /opt/course/notebooks "$HOME/notebooks"
exec jupyterhub-singleuser "$@"
