"""Pictures recovered when the board's markers touch dark picture corners, before and after the fix.

Not a test: it prints counts and timings side by side (tests/test_photos.py asserts the
recovery on a small fixed set). The scenes are render_scene(seed, board=photo_board(seed, "dark")):
photograph-like pictures whose corners are nearly black, so every board marker touches a dark
corner, which can merge with it in the detector's threshold image.

    .venv/bin/python benchmarks/bench_photos.py [--easy 40] [--hard 120]

Columns: "before" is readmarker's crop_pictures with the detector's markers only
(second_look=False), "after" with find_board_markers' second look. A picture counts as
recovered when it is fully framed (scene.fully_framed) and its crop scores at least
SAME_CROP_THRESHOLD against the expected crop; a false picture is one returned although one of
its markers is out of view, or whose crop scores below the threshold. The drawn cat and dog
board is measured too, to show the fix changes nothing there.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

READMARKER = Path(__file__).resolve().parents[1] / "assignments" / "reference_ws" / "src" / "readmarker"


def score(crop_pictures, scenes_list) -> dict:
    """Counts of framed, recovered and false pictures, and seconds per frame, of one crop function."""
    from course_lib import marker_board

    framed = recovered = false = 0
    seconds = 0.0
    for scene in scenes_list:
        started = time.perf_counter()
        crops = crop_pictures(scene.frame)
        seconds += time.perf_counter() - started
        expected = scene.expected_crops()
        visible = set(scene.visible_ids)
        for name, markers in marker_board.PICTURES.items():
            good = name in crops and marker_board.crop_similarity(crops[name], expected[name]) >= marker_board.SAME_CROP_THRESHOLD
            if name in scene.fully_framed:
                framed += 1
                recovered += good
            if name in crops and (not good or not visible.issuperset(markers)):
                false += 1
    return {"framed": framed, "recovered": recovered, "false": false, "seconds": seconds / max(1, len(scenes_list))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--easy", type=int, default=40, help="easy scenes (seeds 0..N-1)")
    parser.add_argument("--hard", type=int, default=120, help="hard scenes (seeds 0..N-1)")
    args = parser.parse_args(argv)

    sys.path.insert(0, str(READMARKER))
    from readmarker.crop import crop_pictures

    from course_lib import photos, scenes

    def before(frame):
        return crop_pictures(frame, second_look=False)

    print(f"Python {platform.python_version()}, {platform.machine()}; easy seeds 0-{args.easy - 1}, "
          f"hard seeds 0-{args.hard - 1}", file=sys.stderr)
    print("| board | scenes | fully framed pictures | recovered before | recovered after | false before / after "
          "| ms per frame before / after |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for board_name, make_board in (("dark corners (photo_board(seed, \"dark\"))", lambda seed: photos.photo_board(seed, "dark")),
                                   ("drawn cat and dog", lambda seed: None)):
        for difficulty, count in (("easy", args.easy), ("hard", args.hard)):
            rendered = [scenes.render_scene(seed, difficulty=difficulty, board=make_board(seed))
                        for seed in range(count)]
            old, new = score(before, rendered), score(crop_pictures, rendered)
            framed = old["framed"]
            print(f"| {board_name} | {difficulty} | {framed} | {old['recovered']} ({old['recovered'] / max(1, framed):.1%}) "
                  f"| {new['recovered']} ({new['recovered'] / max(1, framed):.1%}) | {old['false']} / {new['false']} "
                  f"| {1000 * old['seconds']:.1f} / {1000 * new['seconds']:.1f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
