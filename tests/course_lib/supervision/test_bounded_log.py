"""Tests for course_lib.supervision.bounded_log: a node's log keeps its head and its tail, in bounded space."""

import sys

from course_lib.ros.processes import NodeProcess
from course_lib.supervision import bounded_log


def test_loud_child_does_not_block_and_its_log_is_bounded():
    """64 MB of output: the child finishes, the log keeps head and tail, memory stays small."""
    code = ("import sys\nsys.stdout.write('first line\\n')\nline = 'x' * 1023 + '\\n'\n"
            "for _ in range(64 * 1024):\n    sys.stdout.write(line)\nsys.stdout.write('last line\\n')\n")
    process = NodeProcess([sys.executable, "-c", code]).start()
    assert process.wait(timeout=120) == 0
    log = process.log
    assert log.startswith("first line\n") and log.endswith("last line\n")
    assert "bytes of output omitted" in log
    assert len(log) <= bounded_log.LOG_HEAD_BYTES + bounded_log.LOG_TAIL_BYTES + 100
    assert process.usage["supervisor_max_rss_kb"] < 100 * 1024  # it streamed, it did not buffer


def test_a_long_stream_keeps_its_head_and_newest_tail_and_says_what_was_left_out(tmp_path):
    log = bounded_log.BoundedLog(str(tmp_path), head_bytes=10, tail_bytes=20)
    data = bytes(range(65, 91)) * 10  # 260 bytes, A..Z repeated
    for start in range(0, len(data), 7):  # written in pieces, as a pipe delivers them
        log.write(data[start:start + 7])
    log.close()
    assert len(list(tmp_path.glob("tail.*"))) == 2  # older chunks were deleted: bounded on disk
    kept = bounded_log.read_log(tmp_path, chunk=10)
    head, marker, tail = kept.split(b"\n", 2)
    assert head == data[:10]
    omitted = int(marker.split()[1])
    assert data.endswith(tail) and omitted + 10 + len(tail) == len(data)
    assert marker == f"[... {omitted} bytes of output omitted ...]".encode()


def test_a_short_stream_is_kept_whole(tmp_path):
    log = bounded_log.BoundedLog(str(tmp_path), head_bytes=10, tail_bytes=20)
    log.write(b"0123456789abcdef")
    log.close()
    assert bounded_log.read_log(tmp_path, chunk=10) == b"0123456789abcdef"
