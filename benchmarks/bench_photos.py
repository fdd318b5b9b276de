"""Pictures recovered when the board holds photographs, by the detector alone and by the reference.

Not a test: it prints recovery rates and processor time per frame on large seeded sets
(tests/course_lib/imaging/test_photos.py asserts the bounds on small ones). The scenes are
render_scene(seed, board=photo_board(seed, corners)): photograph-like pictures whose corners
are nearly black ("dark"), of every kind ("any"), or all eight of one kind (near_black, brown,
navy, mid_dark, grey, gradient, texture, light); the drawn cat and dog board is measured too.
Hard scenes are drawn only for seeds whose pose can frame a whole picture.

A second table measures held-out boards of other layouts (course_lib.imaging.board_layouts:
other picture sizes and aspect ratios, marker sizes, margins, the dog below the cat) with
photographs whose corners are of every kind, on three tables (wood with clutter, a dark weave, a
busy print), per layout and per table.

    .venv/bin/python benchmarks/bench_photos.py [--easy 40] [--hard 400] [--kinds 150] [--layouts 150]
                                                [--before REV | --before-file PATH] [--only-layouts]

Columns: "detector alone" is readmarker's crop_pictures with the detector's markers only
(second_look=False); "reference" with find_board_markers' second look; with --before, also the
reference of an earlier commit (readmarker/crop.py as it was at REV, run on the same frames), or
with --before-file that of a copy of crop.py.
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

from tests.support import photo as photo_support  # noqa: E402
from tests.support.photo import READMARKER, photo_scenes, recovery, reference_crop  # noqa: E402


def crop_at(revision: str):
    """readmarker.crop as it was at a git revision, imported as a module of its own."""
    path = (READMARKER / "readmarker" / "crop.py").relative_to(ROOT)
    text = subprocess.run(["git", "-C", str(ROOT), "show", f"{revision}:{path.as_posix()}"], check=True,
                          capture_output=True, text=True).stdout
    folder = Path(tempfile.mkdtemp(prefix="bench-photos-"))
    (folder / "crop_before.py").write_text(text)
    return crop_from_file(str(folder / "crop_before.py"))


def crop_from_file(path: str):
    """A copy of readmarker/crop.py at `path`, imported as a module of its own."""
    spec = importlib.util.spec_from_file_location("crop_before", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--easy", type=int, default=40, help="easy scenes per board (seeds 0..N-1)")
    parser.add_argument("--hard", type=int, default=400, help="hard seeds per board (0..N-1; those framing a picture)")
    parser.add_argument("--kinds", type=int, default=150, help="hard seeds per single-kind board (0..N-1)")
    parser.add_argument("--layouts", type=int, default=150, help="hard seeds per held-out layout (0: none)")
    parser.add_argument("--before", help="also run the reference crop.py of this git revision")
    parser.add_argument("--before-file", help="also run this copy of the reference crop.py")
    parser.add_argument("--only-layouts", action="store_true", help="measure the held-out layouts only")
    args = parser.parse_args(argv)

    crop = reference_crop()
    functions = {"detector alone": lambda frame: crop.crop_pictures(frame, second_look=False),
                 "reference": crop.crop_pictures}
    if args.before:
        functions[f"reference at {args.before}"] = crop_at(args.before).crop_pictures
    if args.before_file:
        functions["reference before"] = crop_from_file(args.before_file).crop_pictures
    print(f"Python {platform.python_version()}, {platform.machine()}; easy seeds 0-{args.easy - 1}, hard seeds "
          f"0-{args.hard - 1}, single-kind boards hard seeds 0-{args.kinds - 1}", file=sys.stderr)
    if not args.only_layouts:
        board_table(functions, args)
    if args.layouts:
        layout_table(functions, args.layouts)
    return 0


def board_table(functions, args) -> None:
    """The course's board with photographs of each corner kind, and with the drawn cat and dog."""
    from course_lib.imaging import photos

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


def layout_table(functions, count: int) -> None:
    """Held-out boards of other layouts on three tables: per layout, then per table."""
    from course_lib.imaging import board_layouts

    names = list(functions)
    print(f"\nHeld-out layouts, hard seeds 0-{count - 1} (tables by seed: {', '.join(board_layouts.TABLES)})\n")
    print("| layout | table | scenes | fully framed | " + " | ".join(f"{name}: recovered" for name in names)
          + " | false pictures |")
    print("|---|---|---|---:|" + "---:|" * len(names) + "---:|")
    by_table = {table: [photo_support.Recovery() for _ in names] for table in board_layouts.TABLES}
    for label, layout in board_layouts.LAYOUTS.items():
        rendered = list(photo_support.layout_scenes(range(count), layout))
        results = [recovery(function, rendered) for function in functions.values()]
        _layout_row(label, "all", len(rendered), results)
        for table in board_layouts.TABLES:
            on_table = [scene for scene in rendered if board_layouts.TABLES[scene.seed % 3] == table]
            for total, part in zip(by_table[table], (recovery(f, on_table) for f in functions.values()), strict=True):
                _add(total, part)
        for name, result in zip(names, results, strict=True):
            if result.missed and name != "detector alone":
                print(f"  {label}: {name} missed: {result.missed}", file=sys.stderr)
    for table, results in by_table.items():
        _layout_row("all layouts", table, results[0].scenes, results)


def _layout_row(label, table, scenes, results) -> None:
    print(f"| {label} | {table} | {scenes} | {results[0].framed} | "
          + " | ".join(f"{r.recovered} ({r.rate:.1%})" for r in results) + " | "
          + " / ".join(str(r.false) for r in results) + " |", flush=True)


def _add(total, part) -> None:
    for field in ("framed", "recovered", "false", "seconds", "scenes"):
        setattr(total, field, getattr(total, field) + getattr(part, field))


if __name__ == "__main__":
    sys.exit(main())
