"""What runs inside a student's namespaces, as the student: the doors of the namespace (forward),
the course's ROS environment, then JupyterHub's single-user server (``jupyterhub-singleuser``).

Started by the spawner as ``python -m coursehub.singleuser [server args]`` with
COURSEHUB_SERVER_SOCKET and COURSEHUB_HUB_SOCKET set. The doors run in a thread of the server's
own process, so they live exactly as long as the server.
"""

from __future__ import annotations

import asyncio
import os
import sys
import threading
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


def main() -> int:
    ready, failed = threading.Event(), []
    threading.Thread(target=_open_doors, args=(ready, failed), name="coursehub-doors", daemon=True).start()
    ready.wait(30)
    if failed or not ready.is_set():
        print(f"coursehub.singleuser: could not open the namespace's sockets: {failed}", file=sys.stderr)
        return 1
    from course_lib import rosenv

    # Kernels, terminals and `!` commands inherit these, as under `make lab`.
    rosenv.prepare_current_process()
    from jupyterhub.singleuser import main as singleuser_main

    sys.argv[0] = "jupyterhub-singleuser"
    return singleuser_main()


if __name__ == "__main__":
    sys.exit(main())
