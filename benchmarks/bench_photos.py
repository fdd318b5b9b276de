"""Pictures recovered when the board holds photographs, by the detector alone and by the reference.

Not a test: it prints recovery rates and processor time per frame on large seeded sets
(tests/course_lib/imaging/test_photos.py asserts the bounds on small ones). The scenes are
render_scene(seed, board=photo_board(seed, corners)): photograph-like pictures whose corners
are nearly black ("dark"), of every kind ("any"), or all eight of one kind (near_black, brown,
navy, mid_dark, grey, gradient, texture, light); the drawn cat and dog board is measured too.
Hard scenes are drawn only for seeds whose pose can frame a whole picture.

    .venv/bin/python benchmarks/bench_photos.py [--easy 40] [--hard 400] [--kinds 150] [--before REV]

Columns: "detector alone" is readmarker's crop_pictures with the detector's markers only
(second_look=False); "reference" with find_board_markers' second look; with --before, also the
reference of an earlier commit (readmarker/crop.py as it was at REV, run on the same frames).
A picture counts as recovered when it is fully framed and its crop scores at least
SAME_CROP_THRESHOLD against the expected crop; a false picture is one returned although one of
its markers is out of view, or whose crop scores below the threshold. Times are processor
seconds of crop_pictures alone (OpenCV's default threads).
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # tests.support runs from the repository

from tests.support.photo import READMARKER, photo_scenes, recovery, reference_crop  # noqa: E402


def crop_at(revision: str):
    """readmarker.crop as it was at a git revision, imported as a module of its own."""
    path = (READMARKER / "readmarker" / "crop.py").relative_to(ROOT)
    text = subprocess.run(["git", "-C", str(ROOT), "show", f"{revision}:{path.as_posix()}"], check=True,
                          capture_output=True, text=True).stdout
    folder = Path(tempfile.mkdtemp(prefix="bench-photos-"))
    (folder / "crop_before.py").write_text(text)
    spec = importlib.util.spec_from_file_location("crop_before", folder / "crop_before.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--easy", type=int, default=40, help="easy scenes per board (seeds 0..N-1)")
    parser.add_argument("--hard", type=int, default=400, help="hard seeds per board (0..N-1; those framing a picture)")
    parser.add_argument("--kinds", type=int, default=150, help="hard seeds per single-kind board (0..N-1)")
    parser.add_argument("--before", help="also run the reference crop.py of this git revision")
    args = parser.parse_args(argv)

    from course_lib.imaging import photos

    crop = reference_crop()
    functions = {"detector alone": lambda frame: crop.crop_pictures(frame, second_look=False),
                 "reference": crop.crop_pictures}
    if args.before:
        functions[f"reference at {args.before}"] = crop_at(args.before).crop_pictures
    print(f"Python {platform.python_version()}, {platform.machine()}; easy seeds 0-{args.easy - 1}, hard seeds "
          f"0-{args.hard - 1}, single-kind boards hard seeds 0-{args.kinds - 1}", file=sys.stderr)
    names = list(functions)
    print("| board | scenes | fully framed | " + " | ".join(f"{name}: recovered" for name in names)
          + " | false pictures | ms per frame |")
    print("|---|---|---:|" + "---:|" * len(names) + "---:|---:|")
    cases = [("any", "any", "easy", args.easy), ("any", "any", "hard", args.hard),
             ("dark", "dark", "easy", args.easy), ("dark", "dark", "hard", args.hard),
             *((f"all {kind}", [kind] * 4, "hard", args.kinds) for kind in photos.CORNER_KINDS),
             ("drawn cat and dog", None, "easy", args.easy), ("drawn cat and dog", None, "hard", args.hard)]
    for label, corners, difficulty, count in cases:
        rendered = list(photo_scenes(range(count), corners, difficulty))
        results = [recovery(function, rendered) for function in functions.values()]
        framed = results[0].framed
        print(f"| {label} | {difficulty} ({len(rendered)}) | {framed} | "
              + " | ".join(f"{r.recovered} ({r.rate:.1%})" for r in results) + " | "
              + " / ".join(str(r.false) for r in results) + " | "
              + " / ".join(f"{1000 * r.seconds / max(1, r.scenes):.1f}" for r in results) + " |", flush=True)
        for name, result in zip(names, results, strict=True):
            if result.missed and name != "detector alone":
                print(f"  {name} missed: {result.missed}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
