"""What the lessons state and teach agrees with the code and the assignments' contracts.

(nbmake runs every lesson top to bottom; these tests check single facts of them, fast.)
"""

import ast
import re
from pathlib import Path

import nbformat
from rclpy.qos import ReliabilityPolicy

from course_lib import scenes, session

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
LESSON_02 = NOTEBOOKS / "02_images_and_brightness.ipynb"


def _cells(path: Path, kind: str) -> list[str]:
    return [cell.source for cell in nbformat.read(path, as_version=4).cells if cell.cell_type == kind]


def _classes_and_functions(sources: list[str]) -> str:
    """The class and function definitions of these cells (without the cells' other statements)."""
    kept = []
    for source in sources:
        source = "\n".join(line for line in source.splitlines() if not line.startswith(("%", "!")))
        tree = ast.parse(source)
        kept += [ast.get_source_segment(source, node) for node in tree.body
                 if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.Import, ast.ImportFrom))]
    return "\n\n".join(kept)


def test_lesson_02_publishes_brightness_with_the_sensor_data_qos_as_the_assignment_asks(domain_id):
    """A student who copies lesson 02's meter into the brightness assignment keeps the publisher
    QoS points: both meters publish (and subscribe) best effort, the sensor-data QoS."""
    session.start(domain_id=domain_id)
    try:
        space: dict = {}
        exec(_classes_and_functions(_cells(LESSON_02, "code")), space)  # noqa: S102 (the lesson's own code)
        space["should_publish"] = lambda *args: True
        for meter in (space["BrightnessMeter"](), space["ChangeMeter"]()):
            publisher = next(p for p in meter.publishers if p.topic_name.startswith("/brightness"))
            assert publisher.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT, meter.get_name()
            assert all(s.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT for s in meter.subscriptions)
            meter.destroy_node()
    finally:
        session.stop()


def test_lesson_02_states_the_light_period_of_its_camera():
    """'about 21 s for this camera, seed 0' is the period of the virtual camera's light."""
    text = "\n".join(_cells(LESSON_02, "markdown"))
    stated = int(re.search(r"about (\d+) s for this camera, seed 0", text).group(1))
    _, period, _ = scenes.CameraPath(seed=0)._waves["gain"]
    assert stated == round(period)
    low, high = map(int, re.search(r"period of (\d+) to (\d+) seconds", text).groups())
    assert low <= period <= high
