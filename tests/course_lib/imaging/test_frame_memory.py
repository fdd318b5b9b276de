"""Tests for course_lib.imaging.frame_memory: freed frames' memory is reused, not faulted in again."""

import subprocess
import sys

import pytest

FAULTS = """
import resource, sys
import numpy as np
from course_lib.imaging import frame_memory
if sys.argv[1] == "keep":
    assert frame_memory.keep_freed_frames()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for index in range(20):  # a board's box differs from scene to scene: each a little larger here
    frame = np.ones((480 + index, 640, 3), np.float32)  # 3.7 MB, written through: every page touched
    del frame
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc")
def test_a_freed_frame_is_reused_rather_than_faulted_in_again():
    """20 frames of about 3.7 MB (900 pages), each a little larger than the last, fault in about
    18,000 pages with glibc's default (each is a fresh mapping) and about one frame's worth once
    freed frames are kept."""
    faults = {how: int(subprocess.run([sys.executable, "-c", FAULTS, how], capture_output=True, text=True,
                                      check=True).stdout) for how in ("keep", "default")}
    assert faults["default"] > 10 * 900, faults
    assert faults["keep"] < 3 * 900, faults
