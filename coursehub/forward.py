"""Byte forwarding between a TCP port and a unix socket (asyncio), the only ways in and out of a
student's network namespace.

A unix socket is a file, so a process in another network namespace reaches it through the
shared file system while the namespace has no network interface but loopback. Each student's
namespace has two such doors: the hub and the proxy reach the student's server through
``<run dir>/<user>/server.sock``, and the server reaches the hub's API through ``hub.sock``.
"""

from __future__ import annotations

import asyncio
import os
import stat

CHUNK = 256 * 1024


async def _pipe(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    try:
        while data := await reader.read(CHUNK):
            writer.write(data)
            await writer.drain()
        if writer.can_write_eof():
            writer.write_eof()  # a half-close reaches the other end, as on a direct connection
    except (ConnectionError, OSError):
        writer.close()


async def _join(reader, writer, open_target) -> None:
    try:
        target_reader, target_writer = await open_target()
    except OSError:  # nothing listens yet (a server still starting), or a refused socket
        writer.close()
        return
    try:
        await asyncio.gather(_pipe(reader, target_writer), _pipe(target_reader, writer))
    except asyncio.CancelledError:
        pass  # the door closes (its loop ends): both connections close below
    finally:
        writer.close()
        target_writer.close()


async def tcp_to_unix(host: str, port: int, path: str, owner: int | None = None) -> asyncio.Server:
    """Listen on host:port; each connection is joined to a new connection to the unix socket `path`.

    With `owner`, only a socket of that uid is connected to (not a symlink, not another user's
    socket): the folder of server.sock belongs to the student, who could otherwise point the
    hub's door at someone else's socket.
    """
    def connect():
        if owner is not None:
            found = os.lstat(path)
            if not stat.S_ISSOCK(found.st_mode) or found.st_uid != owner:
                raise ConnectionRefusedError(f"{path} is not a socket of uid {owner}")
        return asyncio.open_unix_connection(path)

    return await asyncio.start_server(lambda r, w: _join(r, w, connect), host, port)


async def unix_to_tcp(path: str, host: str, port: int, mode: int = 0o600) -> asyncio.Server:
    """Listen on the unix socket `path` (file mode `mode`; an old socket file is replaced); each
    connection is joined to a new connection to host:port."""
    if os.path.exists(path):
        os.unlink(path)
    server = await asyncio.start_unix_server(
        lambda r, w: _join(r, w, lambda: asyncio.open_connection(host, port)), path)
    os.chmod(path, mode)
    return server
