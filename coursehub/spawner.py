"""The JupyterHub spawner of the course: each user's server in a network, mount and shared-memory
namespace of its own.

``IsolatedSpawner`` is JupyterHub's LocalProcessSpawner (a process per user, running as that
user) whose command is wrapped in the grader's sandbox (``autograder.sandbox.namespaces.sandbox_command``:
``unshare --net --mount``, loopback only, a private tmpfs on /dev/shm, the repository's
instructor folders hidden under empty mounts for students) and which drops to the user only
inside it (``setpriv``). A student's kernels, terminals and nodes inherit the namespaces: DDS
discovery (multicast and unicast) and Fast DDS's shared memory never leave them, whatever
ROS_DOMAIN_ID or discovery range the student sets.

The namespace has no network interface but loopback; the hub reaches the server through two
unix sockets joined to TCP ports on each side (coursehub.forward): the proxy sends to
127.0.0.1:<port> on the host, the hub's door there forwards to ``run/<user>/server.sock``, and
the door inside the namespace on to the server at 127.0.0.1:<port>; the server's calls to the
hub's API go the other way, through ``run/hub.sock``.
"""

from __future__ import annotations

import os
import pwd
import sys
from pathlib import Path

from jupyterhub.spawner import LocalProcessSpawner
from traitlets import Unicode

from course_lib.supervision import process_tree
from coursehub import course as course_settings
from coursehub import forward, netns, sandbox


class IsolatedSpawner(LocalProcessSpawner):
    hub_dir = Unicode(str(course_settings.DEFAULT_HUB_DIR), config=True,
                      help="The course's hub directory (course.json).")

    _hub_door = None  # one per hub process: hub.sock -> the hub's API
    _door = None
    #: The server's network namespace (coursehub.netns), pinned once the server runs in it.
    _namespace: netns.PinnedNamespace | None = None

    def make_preexec_fn(self, name):
        return None  # stays root until the namespaces exist; setpriv drops to the user inside them

    async def _open_hub_door(self, course) -> None:
        if IsolatedSpawner._hub_door is None:
            course.run_dir.mkdir(mode=0o711, parents=True, exist_ok=True)  # entered, never listed, by others
            os.chmod(course.run_dir, 0o711)
            # Anyone may connect: it leads to the hub's API, which the proxy serves to anyone too.
            IsolatedSpawner._hub_door = await forward.unix_to_tcp(
                str(course.hub_socket), "127.0.0.1", course.hub_port, mode=0o666)

    def get_env(self):
        course = course_settings.load(self.hub_dir)
        env = sandbox.user_environment(course, self.user.name, super().get_env())
        env.update(COURSEHUB_SERVER_SOCKET=str(course.server_socket(self.user.name)),
                   COURSEHUB_HUB_SOCKET=str(course.hub_socket))
        return env

    async def start(self):
        course = course_settings.load(self.hub_dir)
        await self._open_hub_door(course)
        account = pwd.getpwnam(self.user.name)
        folder = course.run_dir / self.user.name
        folder.mkdir(mode=0o700, exist_ok=True)  # not listable by others while it is still root's
        os.chown(folder, account.pw_uid, account.pw_gid)
        os.chmod(folder, 0o700)
        course.server_socket(self.user.name).unlink(missing_ok=True)
        # The instructor works in the course directory: nbgrader and the formgrader read its
        # nbgrader_config.py from the working directory.
        workdir = course.course_dir if self.user.name == course.instructor else Path(account.pw_dir)
        self.notebook_dir = str(workdir)
        self.popen_kwargs = {"cwd": str(workdir)}
        self.cmd = sandbox.as_user(course, self.user.name, [sys.executable, "-m", "coursehub.singleuser"])
        self._end_namespace()  # (a server that ended on its own, not yet polled)
        ip, port = await super().start()
        if self._door is not None:
            self._door.close()
        self._door = await forward.tcp_to_unix("127.0.0.1", port, str(course.server_socket(self.user.name)),
                                               owner=account.pw_uid)
        return ip, port

    async def poll(self):
        status = await super().poll()
        if status is None and self._namespace is None:
            self._namespace = netns.PinnedNamespace.of(self.pid)  # None until the server is in its own
        elif status is not None:  # it ended on its own (the hub calls stop() only for a running server)
            self._end_namespace()
        return status

    async def stop(self, now=False):
        await self.poll()  # pins the namespace while the server still runs
        await super().stop(now=now)
        if self._door is not None:
            self._door.close()
            self._door = None
        self._end_namespace()

    def _end_namespace(self) -> None:
        """Kill whatever the user left running in the server's namespace (a node started with
        nohup, say), then let the namespace go."""
        if self._namespace is None:
            return
        process_tree.kill_all(self._namespace.processes)
        self._namespace.close()
        self._namespace = None
