"""Node parameters in launch files: their types, nested names, and the files a node reads them from.

As in launch_ros, a ``<param name=... value=.../>`` value in XML gets its type by YAML's rules:
"5" is an integer, "5.0" a float, "true" a boolean, "[1, 2]" a list of integers, anything else
text; ``value-sep=","`` splits the text into a list first (``value="1,2,3" value-sep=","`` is
[1, 2, 3]), and ``type=`` (str, int, float, bool, list_of_int, ..., yaml) names the type to
take instead (coercion.py has launch's rules). In a YAML launch file the value keeps the type
YAML gave it (``value: "5"`` stays text) and ``type:`` only checks it. A value with
substitutions is typed once they are performed. Nested ``<param>`` tags make dotted names
(``camera.width``). Each ``<param>`` tag reaches the node as a parameter file of its own
(``--params-file``), written when the node starts; ``<param from="file.yaml"/>`` passes that
file as it is."""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import yaml

from course_lib.launch import coercion, substitutions
from course_lib.launch.entities import LaunchFileError


@dataclass
class Deferred:
    """A parameter value with substitutions: performed, then typed (by YAML's rules when
    data_type is None) when the node starts."""

    parts: list
    data_type: coercion.DataType | None = None


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


def value_of(entity):
    """The value of a ``<param>`` tag's value attribute, read as launch_ros reads it.

    XML text is typed by YAML's rules, or as ``type=`` says; ``value-sep=","`` splits it into a
    list first. YAML values keep their YAML types and must already be of ``type=``. Text with
    substitutions is typed when the node starts (see evaluate_group).

    Raises:
        LaunchFileError: a value that is not of its type, or a list of mixed types (launch's words).
    """
    type_name = entity.get("type")
    try:
        data_type = None if type_name is None else coercion.data_type_named(str(type_name))
        if not entity.typed:
            raw = _read_text(entity.get("value"), data_type)
        else:
            if entity.has("value-sep"):  # launch_yaml never reads it, so launch reports it so
                raise ValueError("Unexpected key(s) found in `param`: {'value-sep'}")
            raw = entity.get("value")
            if not coercion.is_instance(raw, data_type, can_be_str=True):
                raise ValueError(f"Attribute 'value' of Entity 'param' expected to be of type '{data_type}', "
                                 f"got '{type(raw)}'")
        return _normalized(_with_substitutions(raw, entity), data_type)
    except (TypeError, ValueError) as error:
        raise entity.error(str(error), "value") from None


def _read_text(raw, data_type):
    """An XML value (a text, or a list of texts with value-sep) typed as launch_xml's get_attr
    types it: text that cannot be converted stays text (it may hold substitutions)."""
    try:
        if not isinstance(raw, list):
            return coercion.coerce(raw, data_type, can_be_str=True)
        if data_type is not None and not data_type.is_list:
            raise TypeError(f"Cannot convert input '{raw}' of type '{type(raw)}' to '{data_type.scalar}'")
        item_type = None if data_type is None else coercion.DataType(data_type.scalar)
        items = [coercion.coerce(item, item_type, can_be_str=True) for item in raw]
        if not coercion.is_valid_value(items, can_be_str=True):
            raise ValueError(f"cannot convert value to {item_type}. Got value=`{raw}`")
        return items
    except ValueError:
        raise ValueError(f"Attribute 'value' of Entity 'param' expected to be of type '{data_type}'."
                         f"'{raw}' can not be converted to one of those types") from None


def _with_substitutions(raw, entity):
    """Text with substitutions becomes Deferred, other text stays text (launch's
    parse_if_substitutions); a list must not mix types."""
    def parsed(value):
        if not isinstance(value, str):
            return value
        parts = substitutions.parse(value, entity.file, entity.line)
        return Deferred(parts) if substitutions.has_substitutions(parts) else "".join(parts)

    if not isinstance(raw, list):
        return parsed(raw)
    items = [parsed(item) for item in raw]
    if len({type(item) for item in items if not isinstance(item, Deferred)}) > 1:
        raise ValueError("The result is a non-uniform list")
    return items


def _normalized(value, data_type):
    """A value checked against its type, as launch_ros's ParameterValue does before the launch
    runs (launch's normalize_typed_substitution); Deferred parts learn the type to take."""
    if isinstance(value, Deferred):
        return Deferred(value.parts, data_type)
    if not isinstance(value, list):
        if not coercion.is_instance(value, data_type):
            raise TypeError(f"value='{value}' is not an instance of {_scalar_text(data_type)}")
        return value
    if data_type is not None and not data_type.is_list:
        raise TypeError("The provided value resolves to a list, though the required type is a scalar. "
                        f"Got value='{value}', data_type='{data_type.scalar}'.")
    scalar = None if data_type is None else data_type.scalar
    kinds = {type(item) for item in value if not isinstance(item, Deferred)}
    for allowed, wanted in (({str}, str), ({bool}, bool), ({int}, int), ({int, float}, float)):
        if kinds <= allowed:
            if scalar not in (None, wanted) and kinds:
                raise TypeError(f"Got a list of '{wanted}', expected a list of '{scalar}'. value='{value}'")
            item_type = None if scalar is None else coercion.DataType(scalar)
            return [Deferred(item.parts, item_type) if isinstance(item, Deferred)
                    else float(item) if wanted is float else item for item in value]
    raise TypeError(f"Input value is not an acceptable 'SomeValueType'.Got value='{value}'")


def _scalar_text(data_type) -> str:
    if data_type is None:
        return "None"
    return str(data_type) if data_type.is_list else str(data_type.scalar)


def _evaluate(value, context, file, line):
    """A parameter's value with its substitutions performed and typed (launch's
    perform_typed_substitution)."""
    if isinstance(value, list):
        items = [_evaluate(item, context, file, line) for item in value]
        if not coercion.is_valid_value(items):
            raise LaunchFileError("The output list is not uniform", file, line)
        return items
    if not isinstance(value, Deferred):
        return value
    try:
        return coercion.coerce(substitutions.perform(value.parts, context), value.data_type)
    except ValueError as error:
        raise LaunchFileError(str(error), file, line) from None


def evaluate_group(group: ParamGroup, context, prefix: str = "") -> dict:
    """{dotted name: value} of a ParamGroup, with substitutions performed and values typed."""
    values = {}
    for name_parts, value in group.values:
        name = prefix + substitutions.perform(name_parts, context)
        if isinstance(value, ParamGroup):
            values.update(evaluate_group(value, context, prefix=name + "."))
        else:
            values[name] = _evaluate(value, context, group.file, group.line)
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
