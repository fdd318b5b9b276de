"""A view's configuration as a file: the course's own YAML ("course_lib rviz view", version 1) to save
and load, and RViz2's ``.rviz`` files read for what the view can show. Plain YAML, no widget here.

A ``.rviz`` file (RViz2's File > Save Config) holds under ``Visualization Manager``: ``Global Options``
(``Fixed Frame``), ``Displays`` (each with ``Class: rviz_default_plugins/LaserScan``, ``Name``,
``Enabled``, its ``Topic`` as ``{Value: /scan, ...}`` or, in older files, a plain string; groups of
class ``rviz_common/Group`` nest more ``Displays``) and ``Views`` (``Current``: an Orbit or a
TopDownOrtho camera). What the view cannot show is named in the plan's ``unsupported`` list, never
dropped without a word.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import yaml

FORMAT = "course_lib rviz view"
VERSION = 1

#: RViz2's display classes and the view's kinds for them.
RVIZ_CLASSES = {f"rviz_default_plugins/{name}": kind for name, kind in [
    ("Grid", "Grid"), ("TF", "TF"), ("LaserScan", "LaserScan"), ("PointCloud2", "PointCloud2"),
    ("Marker", "Marker"), ("MarkerArray", "MarkerArray"), ("Odometry", "Odometry"), ("Path", "Path"),
    ("Pose", "PoseStamped"), ("Image", "Image"), ("RobotModel", "RobotModel")]}
#: Display properties the view takes, per RViz2 property name: (the view's option, a converter).
RVIZ_OPTIONS = {"Size (m)": ("size", float), "Keep": ("keep", int), "Cell Size": ("cell_size", float),
                "Plane Cell Count": ("cells", int)}


@dataclasses.dataclass
class Plan:
    """What a configuration file asks of a view: its fixed frame, camera and displays, and what of
    the file the view cannot show (each entry says what and why)."""

    fixed_frame: str | None = None
    camera: dict | None = None
    displays: list[dict] = dataclasses.field(default_factory=list)  # {kind, name, topic, options}
    unsupported: list[str] = dataclasses.field(default_factory=list)


def save(path, fixed_frame: str, camera: dict, displays: list[dict]) -> Path:
    """Write a view's configuration (the course's YAML format) to path; returns the path."""
    path = Path(path)
    document = {"format": FORMAT, "version": VERSION, "fixed_frame": fixed_frame, "camera": camera,
                "displays": displays}
    path.write_text(yaml.safe_dump(document, sort_keys=False))
    return path


def load(path) -> Plan:
    """Read a configuration file: a ``.rviz`` file of RViz2, or the course's own YAML.

    Raises:
        ValueError: the file is neither (its first lines say what it is not).
    """
    path = Path(path)
    document = yaml.safe_load(path.read_text()) or {}
    if isinstance(document, dict) and "Visualization Manager" in document:
        return from_rviz(document)
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise ValueError(f"{path} is neither an RViz2 .rviz file (no 'Visualization Manager:') nor a view "
                         f"saved by view.save_config (format: {FORMAT!r})")
    if document.get("version") != VERSION:
        raise ValueError(f"{path} is version {document.get('version')} of {FORMAT!r}; this course reads {VERSION}")
    return Plan(document.get("fixed_frame"), document.get("camera"), list(document.get("displays") or []))


def from_rviz(document: dict) -> Plan:
    """The plan of an RViz2 configuration (the YAML of a ``.rviz`` file, read)."""
    manager = document.get("Visualization Manager") or {}
    plan = Plan(fixed_frame=(manager.get("Global Options") or {}).get("Fixed Frame"))
    _take_displays(manager.get("Displays") or [], plan, "")
    plan.camera = _camera((manager.get("Views") or {}).get("Current") or {}, plan)
    for panel in (document.get("Panels") or []):
        if panel.get("Class") not in (None, "rviz_common/Displays", "rviz_common/Views",
                                      "rviz_common/Selection", "rviz_common/Time", "rviz_common/Tool Properties"):
            plan.unsupported.append(f"panel {panel.get('Name') or panel.get('Class')} ({panel.get('Class')})")
    return plan


def _take_displays(displays: list, plan: Plan, group: str) -> None:
    for display in displays:
        cls, name = display.get("Class", "?"), display.get("Name") or display.get("Class", "?")
        label = f"{group}{name}"
        if cls == "rviz_common/Group":
            if display.get("Enabled", True):
                _take_displays(display.get("Displays") or [], plan, f"{label}/")
            else:
                plan.unsupported.append(f"{label} (a group, disabled in the file: not shown)")
            continue
        if cls not in RVIZ_CLASSES:
            plan.unsupported.append(f"{label} ({cls}: no such display in this view)")
            continue
        if not display.get("Enabled", True):
            plan.unsupported.append(f"{label} ({cls}, disabled in the file: not shown)")
            continue
        topic = display.get("Topic")
        if isinstance(topic, dict):
            topic = topic.get("Value")
        options = {}
        for prop, (option, convert) in RVIZ_OPTIONS.items():
            if prop in display:
                try:
                    options[option] = convert(display[prop])
                except (TypeError, ValueError):
                    plan.unsupported.append(f"{label}: {prop} {display[prop]!r} is not a number")
        frame = display.get("Reference Frame")
        if cls.endswith("/Grid") and frame and frame != "<Fixed Frame>":
            options["frame"] = frame
        if cls.endswith("/RobotModel"):
            plan.unsupported.append(f"{label}: drawn as the Husky's box; the robot description is not read")
        plan.displays.append({"kind": RVIZ_CLASSES[cls], "name": label, "topic": topic or None, "options": options})


def _camera(current: dict, plan: Plan) -> dict | None:
    cls = current.get("Class")
    if cls == "rviz_default_plugins/Orbit":
        focal = current.get("Focal Point") or {}
        return {"mode": "orbit", "target": [float(focal.get(axis, 0.0)) for axis in "XYZ"],
                "distance": float(current.get("Distance", 10.0)), "yaw": float(current.get("Yaw", 0.785)),
                "pitch": float(current.get("Pitch", 0.785))}
    if cls == "rviz_default_plugins/TopDownOrtho":
        return {"mode": "top", "target": [float(current.get("X", 0.0)), float(current.get("Y", 0.0)), 0.0],
                "scale": float(current.get("Scale", 10.0))}
    if cls:
        plan.unsupported.append(f"view {current.get('Name') or cls} ({cls}): the view keeps its own camera")
    return None
