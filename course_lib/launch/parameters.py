"""Node parameters in launch files: their types, nested names, and the files a node reads them from.

As in launch_ros, a ``<param name=... value=.../>`` value gets its type by YAML's rules: "5" is
an integer, "5.0" a float, "true" a boolean, "[1, 2]" a list of integers, anything else text.
In a YAML launch file the value keeps the type YAML gave it (``value: "5"`` stays text). A value
with substitutions is typed the same way once they are performed. Nested ``<param>`` tags make
dotted names (``camera.width``). Each ``<param>`` tag reaches the node as a parameter file of
its own (``--params-file``), written when the node starts; ``<param from="file.yaml"/>`` passes
that file as it is.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import yaml

from course_lib.launch import substitutions
from course_lib.launch.entities import LaunchFileError

_SCALARS = (bool, int, float, str)


@dataclass
class Deferred:
    """A parameter value with substitutions: performed, then typed by YAML's rules, at run time."""

    parts: list


@dataclass
class ParamFile:
    """``<param from="..."/>``: a YAML parameter file passed to the node as it is (or, with
    allow_substs, after substituting ``$(...)`` in its text)."""

    path: list
    allow_substs: bool
    file: Path
    line: int


@dataclass
class ParamGroup:
    """The parameters of one ``<param name=...>`` tag: {name parts: value or nested ParamGroup}."""

    values: list  # [(name parts, value | Deferred | list | ParamGroup)]
    file: Path
    line: int


def _uniform(items: list) -> bool:
    """True for a list whose items share one type (text items with substitutions aside)."""
    kinds = {type(item) for item in items if not isinstance(item, (str, Deferred))}
    return len(kinds) <= 1 and all(isinstance(item, _SCALARS + (Deferred,)) for item in items)


def _with_substitutions(text: str, file, line):
    parts = substitutions.parse(text, file, line)
    return Deferred(parts) if substitutions.has_substitutions(parts) else "".join(parts)


def typed_by_yaml(text: str):
    """A text typed by YAML's rules, as launch does for XML attributes (None if YAML cannot
    read it, which keeps it text)."""
    if not text:
        return text
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError:
        return None


def value_of(entity):
    """The value of a ``<param>`` tag's value attribute, typed as launch_xml / launch_yaml type it.

    Raises:
        LaunchFileError: a value that is not a number, boolean, text, or a list of one of those.
    """
    raw = entity.get("value")
    if not entity.typed:
        items = raw if isinstance(raw, list) else [raw]
        typed = []
        for item in items:
            value = typed_by_yaml(item)
            typed.append(item if value is None else value)
        raw = typed if isinstance(raw, list) else typed[0]
    if isinstance(raw, list):
        value = [_with_substitutions(item, entity.file, entity.line) if isinstance(item, str) else item
                 for item in raw]
        if not _uniform(value):
            raise entity.error(f"<param> value {raw!r} mixes types; a list parameter holds items of one "
                               "type (all integers, all floats, all booleans or all text)", "value")
        return value
    if isinstance(raw, str):
        return _with_substitutions(raw, entity.file, entity.line)
    if isinstance(raw, _SCALARS):
        return raw
    raise entity.error(f"<param> value {raw!r} is not a parameter value: use a number, true/false, text or "
                       "a list of one of those", "value")


def _evaluate(value, context, name: str, file, line):
    if isinstance(value, list):
        items = [_evaluate(item, context, name, file, line) for item in value]
        if len({type(item) for item in items}) > 1:
            raise LaunchFileError(f"parameter '{name}' became the list {items!r}, which mixes types; "
                                  "a list parameter holds items of one type", file, line)
        return items
    if not isinstance(value, Deferred):
        return value
    text = substitutions.perform(value.parts, context)
    if not text:
        return text
    try:
        typed = yaml.safe_load(text)
    except yaml.YAMLError:
        raise LaunchFileError(f"parameter '{name}' is {text!r} after substitution, which YAML cannot read; "
                              "quote it to make it text", file, line) from None
    if isinstance(typed, _SCALARS) or (isinstance(typed, list) and typed and _uniform(typed)):
        return typed
    raise LaunchFileError(f"parameter '{name}' is {text!r} after substitution: not a number, boolean, text "
                          "or list of one type", file, line)


def evaluate_group(group: ParamGroup, context, prefix: str = "") -> dict:
    """{dotted name: value} of a ParamGroup, with substitutions performed and values typed."""
    values = {}
    for name_parts, value in group.values:
        name = prefix + substitutions.perform(name_parts, context)
        if isinstance(value, ParamGroup):
            values.update(evaluate_group(value, context, prefix=name + "."))
        else:
            values[name] = _evaluate(value, context, name, group.file, group.line)
    return values


def write_params_file(values: dict, node_key: str, directory: Path) -> Path:
    """Write ``{node_key: {ros__parameters: values}}`` to a new file in `directory`, the way
    launch_ros hands a node its inline parameters."""
    handle, path = tempfile.mkstemp(prefix="launch_params_", dir=directory)
    with os.fdopen(handle, "w") as stream:
        yaml.dump({node_key: {"ros__parameters": values}}, stream, default_flow_style=False)
    return Path(path)


def resolve_file(param: ParamFile, context, directory: Path) -> Path | None:
    """The path to pass for ``<param from=...>`` (None when it is not a file, which launch_ros
    reports as a warning and skips)."""
    path = Path(os.path.abspath(substitutions.perform(param.path, context)))
    if not path.is_file():
        return None
    if not param.allow_substs:
        return path
    text = substitutions.perform(substitutions.parse(path.read_text(), path, None), context)
    try:
        yaml.safe_load(text)
    except yaml.YAMLError:
        raise LaunchFileError("the parameter file is not valid YAML after substitution", path) from None
    handle, substituted = tempfile.mkstemp(prefix="launch_params_", dir=directory)
    with os.fdopen(handle, "w") as stream:
        stream.write(text)
    return Path(substituted)
