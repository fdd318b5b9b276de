"""What runs inside a student's namespaces, as the student: the doors of the namespace (forward),
the course's ROS environment, then JupyterHub's single-user server (``jupyterhub-singleuser``).

Started by the spawner as ``python -m coursehub.singleuser [server args]`` with
COURSEHUB_SERVER_SOCKET and COURSEHUB_HUB_SOCKET set. The doors run in a thread of the server's
own process, so they live exactly as long as the server; so does the sweep of the namespace's
/dev/shm (the Fast DDS segments of killed kernels).
"""

from __future__ import annotations

import asyncio
import os
import sys
import threading
import time
from urllib.parse import urlparse

from coursehub import forward


def _open_doors(ready: threading.Event, failed: list) -> None:
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    server_url = urlparse(os.environ["JUPYTERHUB_SERVICE_URL"])
    hub_url = urlparse(os.environ["JUPYTERHUB_API_URL"])

    async def serve():
        # The hub's side connects to server.sock: only this user (and root) may (mode 0600).
        await forward.unix_to_tcp(os.environ["COURSEHUB_SERVER_SOCKET"], "127.0.0.1", server_url.port)
        # The server calls the hub's API at the same address as outside; here it is this door.
        await forward.tcp_to_unix("127.0.0.1", hub_url.port, os.environ["COURSEHUB_HUB_SOCKET"])

    try:
        loop.run_until_complete(serve())
    except Exception as error:  # noqa: BLE001 - reported by the main thread
        failed.append(error)
    ready.set()
    if not failed:
        loop.run_forever()


#: Seconds between two sweeps of the server's /dev/shm.
SWEEP_SECONDS = 60.0


def _sweep_shared_memory(interval: float = SWEEP_SECONDS) -> None:
    """A kernel killed with a ROS session open (restarted while stuck in a call, or out of memory)
    cannot close its Fast DDS segments: up to 32 MB each stay in the namespace's private /dev/shm
    until the server stops. Remove them every `interval` seconds (course_lib.notebook.doctor)."""
    from course_lib.notebook import doctor

    while True:
        time.sleep(interval)
        try:
            doctor.remove_stale_segments()
        except Exception as error:  # noqa: BLE001 - a missed sweep costs memory, not the server
            print(f"coursehub.singleuser: could not remove stale Fast DDS segments: {error}", file=sys.stderr)


def main() -> int:
    ready, failed = threading.Event(), []
    threading.Thread(target=_open_doors, args=(ready, failed), name="coursehub-doors", daemon=True).start()
    ready.wait(30)
    if failed or not ready.is_set():
        print(f"coursehub.singleuser: could not open the namespace's sockets: {failed}", file=sys.stderr)
        return 1
    from course_lib.ros import rosenv

    # Kernels, terminals and `!` commands inherit these, as under `make lab`.
    rosenv.prepare_current_process()
    threading.Thread(target=_sweep_shared_memory, name="coursehub-shm-sweep", daemon=True).start()
    from jupyterhub.singleuser import main as singleuser_main

    sys.argv[0] = "jupyterhub-singleuser"
    return singleuser_main()


if __name__ == "__main__":
    sys.exit(main())
