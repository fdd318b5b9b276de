"""Processor time per simulated camera frame: this checkout against an earlier commit, in one run.

Not a test: it prints milliseconds of CPU per frame, side by side, and how far the two commits'
frames are apart. Each side runs in a process of its own (its own course_lib, extracted from git
for the earlier commit), alternating, and the fastest of --repeat rounds counts.

    .venv/bin/python benchmarks/bench_camera.py [--before HEAD~1] [--repeat 3]

Rows:

- webcam frame: scenes.CameraPath.scene_at, what ``ros2 run webcam image_publisher`` renders 30
  times a second (640x480, no supersampling);
- easy scene, hard scene: scenes.render_scene, what the catdog_warp checks and lessons render
  (640x480 drawn at twice the size, a new table per seed).

The last lines compare the frames of the two commits for the same seeds: the largest difference
in grey levels and the share of pixels that differ at all (JPEG, in the scenes' looks, turns a
one-level difference into a changed 8x8 block).
"""

from __future__ import annotations

import argparse
import io
import json
import platform
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: Runs in the measured process: prints {"row": ms per frame} and saves the frames to compare.
MEASURE = r"""
import json, sys, time
import numpy as np
from course_lib import scenes
frames_file = sys.argv[1]
path = scenes.CameraPath(0, size=(640, 480))
path.scene_at(0.0)
scenes.render_scene(0)

def cpu_ms(render, count):
    start = time.process_time()
    for index in range(count):
        render(index)
    return (time.process_time() - start) / count * 1000

rows = {"webcam frame": cpu_ms(lambda i: path.scene_at(i / 30), 90),
        "easy scene": cpu_ms(lambda i: scenes.render_scene(i + 1), 15),
        "hard scene": cpu_ms(lambda i: scenes.render_scene(i + 1, difficulty="hard"), 15)}
frames = [path.scene_at(t).frame for t in (0.0, 0.5, 7.25)]
frames += [scenes.render_scene(seed, difficulty=d).frame for seed in range(6) for d in ("easy", "hard")]
np.save(frames_file, np.stack(frames))
print(json.dumps(rows))
"""


def extract(commit: str, into: Path) -> Path:
    """course_lib of `commit`, extracted into `into`; returns the folder to put on sys.path."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", commit, "course_lib"], check=True,
                             capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(into)
    return into


def measure(source: Path, frames_file: Path) -> dict:
    done = subprocess.run([sys.executable, "-c", MEASURE, str(frames_file)], capture_output=True, text=True,
                          cwd=source, env={"PYTHONPATH": str(source), "PATH": "/usr/bin:/bin"}, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default="HEAD~1", help="the earlier commit (default HEAD~1)")
    parser.add_argument("--repeat", type=int, default=3, help="rounds; the fastest of each side counts")
    args = parser.parse_args(argv)

    import numpy as np

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sides = {"before": extract(args.before, tmp / "before"), "after": REPO}
        best: dict[str, dict] = {}
        for _ in range(args.repeat):
            for side, source in sides.items():
                rows = measure(source, tmp / f"{side}.npy")
                best[side] = {row: min(ms, best.get(side, {}).get(row, ms)) for row, ms in rows.items()}
        before, after = np.load(tmp / "before.npy").astype(int), np.load(tmp / "after.npy").astype(int)

    print(f"CPU milliseconds per 640x480 frame, fastest of {args.repeat} "
          f"({platform.processor() or platform.machine()}, before = {args.before})")
    print(f"{'':14} {'before':>8} {'after':>8} {'after/before':>13}")
    for row in best["before"]:
        b, a = best["before"][row], best["after"][row]
        print(f"{row:14} {b:8.1f} {a:8.1f} {a / b:13.2f}")
    difference = np.abs(before - after)
    print(f"frames compared: {len(before)}; largest difference {difference.max()} grey levels; "
          f"pixels that differ: {(difference > 0).mean():.3%}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
