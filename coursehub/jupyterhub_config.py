"""The hub's configuration: JupyterHub reads this file (``python -m coursehub start`` passes it),
and it reads the course from ``course.json`` in the hub directory that ``course.HUB_DIR_ENV`` names."""

import json
import os
import sys
from pathlib import Path

from course_lib.notebook.student_lab import terminal
from coursehub import course as course_settings

c = get_config()  # noqa: F821 (provided by JupyterHub)
course = course_settings.load(os.environ[course_settings.HUB_DIR_ENV])

c.JupyterHub.ip = course.ip
c.JupyterHub.port = course.port
c.JupyterHub.hub_ip = "127.0.0.1"
c.JupyterHub.hub_port = course.hub_port
c.ConfigurableHTTPProxy.api_url = f"http://127.0.0.1:{course.port + 1}"
c.ConfigurableHTTPProxy.command = [str(Path(sys.prefix) / "chp" / "node_modules" / ".bin" / "configurable-http-proxy")]
# All that JupyterHub writes, in a folder only root enters: the database holds every user's name and
# last activity, cookie ids, hashed tokens and OAuth codes, and SQLite gives its journal the database's mode.
c.JupyterHub.db_url = f"sqlite:///{course.private_dir / 'jupyterhub.sqlite'}"
c.JupyterHub.cookie_secret_file = str(course.private_dir / "jupyterhub_cookie_secret")
c.JupyterHub.pid_file = str(course.private_dir / "jupyterhub.pid")
c.ConfigurableHTTPProxy.pid_file = str(course.private_dir / "jupyterhub-proxy.pid")
c.JupyterHub.cleanup_servers = True
c.JupyterHub.cleanup_proxy = True

# PAM: the course's Linux accounts are the logins (coursehub.accounts); only its group gets in.
c.JupyterHub.authenticator_class = "pam"
c.PAMAuthenticator.allowed_groups = {course.group}

c.JupyterHub.spawner_class = "coursehub.spawner.IsolatedSpawner"
c.IsolatedSpawner.hub_dir = str(course.hub_dir)
c.Spawner.default_url = "/lab"
# bash with the course's rc file: ~/.bashrc, then the course's environment first again.
c.Spawner.args = ["--ServerApp.terminado_settings="
                  + json.dumps({"shell_command": terminal.shell_command("/bin/bash")})]
# Ten students logging in at once on two cores start in about a minute (docs/instructors.md: Capacity).
c.Spawner.start_timeout = 180
c.Spawner.http_timeout = 180

# Graded feedback minutes after Submit (coursehub.grading_service), as root (the grader's sandbox
# needs it); the hub restarts it when it dies. Students reach its page behind the hub's login.
c.JupyterHub.services = [{
    "name": course_settings.GRADING_SERVICE, "url": f"http://127.0.0.1:{course.grading_port}", "display": True,
    "oauth_no_confirm": True,
    "command": [sys.executable, "-m", "coursehub.grading_service"],
    "environment": {course_settings.HUB_DIR_ENV: str(course.hub_dir)},
}]
c.JupyterHub.load_roles = [{"name": "user",
                            "scopes": ["self", f"access:services!service={course_settings.GRADING_SERVICE}"]}]
