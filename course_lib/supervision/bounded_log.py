"""A log of a stream that keeps its head and its tail: bounded on disk, never growing in memory.

The supervisor (course_lib.supervision.supervisor) writes a node's output with :class:`BoundedLog`; the
caller (course_lib.ros.processes) reads it back with :func:`read_log`. Standard library only: the
supervisor runs without site-packages.
"""

from __future__ import annotations

import os
from pathlib import Path

#: Bytes of a node's output kept from its start and from its end; the middle is dropped.
LOG_HEAD_BYTES = 64 * 1024
LOG_TAIL_BYTES = 256 * 1024


class BoundedLog:
    """Write a stream to `head` (its first head_bytes) and to numbered `tail.N` chunk files of
    tail_bytes/2 each, deleting all but the newest two chunks: bounded disk, no memory growth."""

    def __init__(self, directory: str, head_bytes: int, tail_bytes: int):
        self.directory = directory
        self.head = open(os.path.join(directory, "head"), "wb", buffering=0)
        self.head_left = head_bytes
        self.chunk = max(1, tail_bytes // 2)
        self.index = -1
        self.tail = None
        self.tail_left = 0

    def write(self, data: bytes) -> None:
        if self.head_left:
            piece = data[:self.head_left]
            self.head.write(piece)
            self.head_left -= len(piece)
            data = data[len(piece):]
        while data:
            if self.tail_left == 0:
                self._next_chunk()
            piece = data[:self.tail_left]
            self.tail.write(piece)
            self.tail_left -= len(piece)
            data = data[len(piece):]

    def _next_chunk(self) -> None:
        if self.tail is not None:
            self.tail.close()
        self.index += 1
        self.tail = open(os.path.join(self.directory, f"tail.{self.index:012d}"), "wb", buffering=0)
        self.tail_left = self.chunk
        if self.index >= 2:
            try:
                os.remove(os.path.join(self.directory, f"tail.{self.index - 2:012d}"))
            except FileNotFoundError:
                pass

    def close(self) -> None:
        self.head.close()
        if self.tail is not None:
            self.tail.close()



def read_log(directory: Path, chunk: int) -> bytes:
    """Join the head and the newest tail chunks the supervisor wrote (see BoundedLog)."""
    for _attempt in range(5):
        try:
            head = (directory / "head").read_bytes() if (directory / "head").exists() else b""
            tails = sorted(directory.glob("tail.*"))[-2:]
            if not tails:
                return head
            first = int(tails[0].suffix[1:])
            data = b"".join(path.read_bytes() for path in tails)
        except FileNotFoundError:  # rotated while we read: read again
            continue
        omitted = first * chunk
        marker = f"\n[... {omitted} bytes of output omitted ...]\n".encode() if omitted else b""
        return head + marker + data
    return b""
