"""Keep the memory of freed frames in the process for the next frame (glibc's malloc).

Drawing a scene or a webcam frame allocates arrays of a few MB (the frame at twice its size, its
float32 copy, the sensor noise) and frees them when the frame is done. glibc's malloc gives each
block of 128 kB or more back to the system when it is freed (until a freed block of that size has
raised its threshold), so the next frame's arrays are fresh pages that the system must fault in
and zero: about 4 of a scene's 40 ms, and 2.5 of a webcam frame's 6 ms.
:func:`keep_freed_frames` raises those thresholds, so that the blocks are reused instead. The
processes that draw many frames call it: the webcam node and the grader's checks.
"""

from __future__ import annotations

import ctypes

#: Blocks below this size come from the heap and go back to it (a 1280x960 float32 frame is
#: 14.7 MB; glibc allows at most 32 MB here) ...
MMAP_THRESHOLD = 32 * 1024 * 1024
#: ... and the heap keeps this much free memory at its top before it gives any back.
TRIM_THRESHOLD = 128 * 1024 * 1024
#: The same settings for a process about to start (glibc reads them there): the checks give them
#: to every student process (course_lib.checks.student_processes).
ENVIRONMENT = {"MALLOC_MMAP_THRESHOLD_": str(MMAP_THRESHOLD), "MALLOC_TRIM_THRESHOLD_": str(TRIM_THRESHOLD)}
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def keep_freed_frames() -> bool:
    """Give this running process the settings of ENVIRONMENT; True when the C library took them
    (glibc's mallopt; elsewhere nothing changes)."""
    mallopt = getattr(ctypes.CDLL(None), "mallopt", None)
    if mallopt is None:
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
