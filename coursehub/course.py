"""The course's settings on this server (``<hub dir>/course.json``) and where everything lives.

One hub directory (mode 0711: nobody else lists it) holds what the hub keeps: course.json and the
initial passwords (0600), what JupyterHub writes (``private/``, 0700: its database with SQLite's
journal beside it, the cookie secret, its and the proxy's pid files), the nbgrader settings and
Submit rules every server reads (``jupyter/``, readable by all) and ``run/``, which students
traverse to reach their server's socket.

What students must not read of the repository the hub runs from is closed to the course's group on
the real filesystem too (coursehub.closed_repository).
"""

from __future__ import annotations

import dataclasses
import json
import pwd
from pathlib import Path

DEFAULT_HUB_DIR = Path("/srv/ros2cv-hub")
#: The hub directory, in the environment of the hub and its services (set by ``python -m coursehub start``).
HUB_DIR_ENV = "COURSEHUB_HUB_DIR"
DEFAULT_EXCHANGE = Path("/srv/nbgrader/exchange")  # nbgrader's documented default place
#: The hub's grading service (coursehub.grading_service): its name, and its page's path on the hub.
GRADING_SERVICE = "grading"
GRADING_PAGE = f"services/{GRADING_SERVICE}/"


@dataclasses.dataclass
class Course:
    hub_dir: Path
    course_id: str
    group: str             # Linux group of the course's accounts; the hub lets in its members only
    instructor: str
    students: list[str]
    exchange: Path
    port: int = 8000       # the proxy's public port (the URL students open)
    hub_port: int = 8081   # the hub's API, on 127.0.0.1 (and, through hub.sock, in every namespace)
    ip: str = "127.0.0.1"  # the proxy's public address; 0.0.0.0 behind a TLS-terminating front end

    @property
    def grading_port(self) -> int:
        """The hub's grading service (coursehub.grading_service) on 127.0.0.1: the port after the hub's."""
        return self.hub_port + 1

    @property
    def run_dir(self) -> Path:
        return self.hub_dir / "run"

    @property
    def hub_socket(self) -> Path:
        return self.run_dir / "hub.sock"

    def server_socket(self, user: str) -> Path:
        return self.run_dir / user / "server.sock"

    @property
    def jupyter_config_dir(self) -> Path:
        return self.hub_dir / "jupyter"

    @property
    def submit_rules(self) -> Path:
        """The attempts and due dates the grading service publishes for the students' Submit
        (coursehub.limited_submit), readable by all."""
        return self.jupyter_config_dir / "submit_rules.json"

    @property
    def course_dir(self) -> Path:
        """The nbgrader course root (source/ release/ submitted/ ... gradebook.db), the instructor's."""
        return Path(pwd.getpwnam(self.instructor).pw_dir) / "course"

    @property
    def private_dir(self) -> Path:
        """What JupyterHub writes (its database, cookie secret and pid files), in a folder only root
        enters, whatever modes the files get (SQLite's journal takes the database's)."""
        return self.hub_dir / "private"

    @property
    def passwords(self) -> Path:
        return self.hub_dir / "passwords.csv"

    def save(self) -> Path:
        path = self.hub_dir / "course.json"
        data = {k: str(v) if isinstance(v, Path) else v for k, v in dataclasses.asdict(self).items()}
        path.write_text(json.dumps(data, indent=2) + "\n")
        path.chmod(0o600)
        return path


def load(hub_dir=DEFAULT_HUB_DIR) -> Course:
    """The course of a hub directory.

    Raises:
        FileNotFoundError: there is none yet; the message names the command that creates it.
    """
    path = Path(hub_dir) / "course.json"
    if not path.is_file():
        raise FileNotFoundError(f"no course in {hub_dir} (no course.json): create it first with "
                                f"`python -m coursehub create-course ROSTER.csv --instructor NAME --hub-dir {hub_dir}`")
    data = json.loads(path.read_text())
    data["hub_dir"], data["exchange"] = Path(data["hub_dir"]), Path(data["exchange"])
    return Course(**data)

