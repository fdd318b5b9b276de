"""What a check found (:class:`Result`), and how its verdict reads as text and as HTML."""

from __future__ import annotations

import dataclasses
from decimal import ROUND_HALF_UP, Decimal

from course_lib import contract
from course_lib.checks.registry import get_check


@dataclasses.dataclass
class Result:
    """What a check found: its items, the points earned, and pictures to show."""

    assignment: str
    name: str
    points: float
    max_points: float
    seed: int
    items: list[dict] = dataclasses.field(default_factory=list)
    notes: list[str] = dataclasses.field(default_factory=list)
    images: list[dict] = dataclasses.field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0
    seeded: bool = True  # False: the check drew nothing from its seed (the verdict does not show it)

    def verdict_lines(self) -> list[str]:
        """The points, then what failed (each cause followed by its consequences), then what passed."""
        lines = [f"{self.name}: {points_text(self.points)} of {points_text(self.max_points)} points"]
        for item in self.items:
            if not item["ok"] and not item.get("consequence"):
                lines.append("  ✘ " + item["message"])
        for item in self.items:
            if item.get("consequence"):
                lines.append("    ↳ ✘ " + item["message"])
        for item in self.items:
            if item["ok"]:
                lines.append("  ✔ " + item["message"])
        lines.extend("  · " + note for note in self.notes)
        if self.error:
            lines.append("  ! " + self.error)
        return lines


def round_points(value: float) -> float:
    """Points as the grader gives them: contract.POINT_DECIMALS decimals, rounded half up (6.125 -> 6.13)."""
    step = Decimal(1).scaleb(-contract.POINT_DECIMALS)
    return float(Decimal(repr(float(value))).quantize(step, rounding=ROUND_HALF_UP))


def earned_points(points: float, items: list[dict], failed: bool) -> float:
    """What a check earns: its `points` × the weight of its passed items / the weight of all, rounded
    by round_points; 0 when it `failed` (ended with an error) before any item passed."""
    total = sum(item["weight"] for item in items)
    if not total or (failed and not any(item["ok"] for item in items)):
        return 0.0
    return round_points(points * sum(item["weight"] for item in items if item["ok"]) / total)


def points_text(value: float) -> str:
    """Points as a verdict writes them, rounded as the grader gives them: 4, 2.5, 6.13."""
    return f"{round_points(value):g}"


def verdict_text(result: Result, graded: bool) -> str:
    """What a check cell shows: the seed (when the check drew from it), the check's description, and
    what passed and failed."""
    kind = "graded" if graded else "self-check"
    tag = f"{kind} · seed {result.seed}" if result.seeded else kind
    lines = [f"[{tag}] {get_check(result.assignment, result.name).description}", *result.verdict_lines()]
    if graded and result.seeded:
        lines.append(f"  (reproduce with AUTOGRADER_SEED={result.seed})")
    return "\n".join(lines)



def images_html(result: Result) -> str:
    """The check's pictures as one HTML block ("" when it has none)."""
    cells = "".join(
        f"<figure style='display:inline-block;margin:4px'><img src='data:image/png;base64,{image['png']}'/>"
        f"<figcaption style='font-size:small'>{_escape(image['label'])}</figcaption></figure>"
        for image in result.images if "png" in image)
    return f"<div class='autograder-images'>{cells}</div>" if cells else ""



def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
