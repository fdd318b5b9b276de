"""Launch's rules for turning text into typed values, with launch's own error words.

ros2/launch types a text in one of two ways (launch/utilities/type_utils.py, coerce_to_type):
by YAML's rules when no type is asked for ("5" is 5, "[1, 2]" a list of integers, "x" text), or
to a named type: ``str`` keeps the text, ``int`` and ``float`` convert it as Python does,
``bool`` takes "1"/"0" and YAML's true/false, and a list type reads a YAML list whose items
are all of that type. The boolean substitutions (``$(not)``, ``$(and)``, ...) and typed
``<param>`` values use these rules, so a wrong value gets the words launch prints.

A type is written as launch_ros's ``type=`` attribute names it: str, int, float, bool,
list_of_str, list_of_int, list_of_float, list_of_bool, or yaml (the same as none).
"""

from __future__ import annotations

from dataclasses import dataclass

import yaml

SCALARS = (int, float, bool, str)


@dataclass(frozen=True)
class DataType:
    """A scalar type, or a list of one (``List[int]``); printed as launch prints its type."""

    scalar: type
    is_list: bool = False

    def __str__(self) -> str:
        return f"typing.List[{self.scalar.__name__}]" if self.is_list else str(self.scalar)


#: launch_ros's ``<param type=...>`` names (launch/frontend/type_utils.py); "yaml" is no type.
TYPE_NAMES = {"str": DataType(str), "bool": DataType(bool), "float": DataType(float), "int": DataType(int),
              "list_of_str": DataType(str, True), "list_of_bool": DataType(bool, True),
              "list_of_float": DataType(float, True), "list_of_int": DataType(int, True), "yaml": None}


def data_type_named(name: str) -> DataType | None:
    """The type a ``type=`` attribute names.

    Raises:
        ValueError: a name launch_ros does not know (its words).
    """
    if name not in TYPE_NAMES:
        raise ValueError(f"Got invalid type identifier '{name}'")
    return TYPE_NAMES[name]


def is_valid_value(value, *, can_be_str: bool = False) -> bool:
    """True for a scalar, or a list whose items share one scalar type (with can_be_str, text
    items may sit among them)."""
    if isinstance(value, list):
        member = next((type(item) for item in value if type(item) is not str), str)
        if member not in SCALARS:
            return False
        allowed = (member, str) if can_be_str else member
        return all(isinstance(item, allowed) for item in value)
    return isinstance(value, SCALARS)


def is_instance(value, data_type: DataType | None, *, can_be_str: bool = False) -> bool:
    """True when value is of data_type (with can_be_str, text is also accepted)."""
    if data_type is None:
        return is_valid_value(value, can_be_str=can_be_str)
    allowed = (str, data_type.scalar) if can_be_str else data_type.scalar
    if not data_type.is_list:
        return isinstance(value, allowed)
    return isinstance(value, list) and all(isinstance(item, allowed) for item in value)


def coerce(text: str, data_type: DataType | None, *, can_be_str: bool = False):
    """A text as a value of data_type (None: by YAML's rules), as launch's coerce_to_type.

    Args:
        can_be_str: keep the text where it cannot be converted (the front ends read attributes
            so, because substitutions in it are performed later).

    Raises:
        ValueError: it cannot be converted (launch's words).
    """
    def by_yaml(message: str):
        if not text:
            return text
        try:
            output = yaml.safe_load(text)
        except yaml.YAMLError as error:
            if can_be_str:
                return text
            raise ValueError(f"{message}: yaml.safe_load() failed\n{error}") from None
        if not is_valid_value(output, can_be_str=can_be_str):
            raise ValueError(f"{message}: output type is not allowed, got {type(output)}")
        return output

    if data_type is None:
        return by_yaml(f"Failed to convert '{text}' using yaml rules")
    scalar = data_type.scalar
    allowed = (str, scalar) if can_be_str else scalar
    if data_type.is_list:
        shown = f"({str!r}, {scalar!r})" if can_be_str else repr(scalar)
        output = by_yaml(f"Cannot convert value '{text}' to a list of '{shown}'")
        if not isinstance(output, list):
            raise ValueError(f"Cannot convert value '{text}' to a list of '{shown}'")
        if not all(isinstance(item, allowed) for item in output):
            raise ValueError(f"Cannot convert value '{text}' to a list of '{shown}', got {output}")
        return output
    if scalar is str:
        return text
    if scalar in (int, float):
        try:
            return scalar(text)
        except ValueError:
            if can_be_str:
                return text
            raise
    if text in ("1", "0"):
        text = "true" if text == "1" else "false"
    output = by_yaml(f"Failed to convert '{text}' to '{scalar}'")
    if isinstance(output, allowed):
        return output
    raise ValueError(f"Cannot convert value '{text}' to '{scalar}'")


def to_bool(text: str) -> bool:
    """A text as a boolean, as launch's boolean substitutions read their arguments ("1", "0",
    and YAML's true/false, yes/no, on/off).

    Raises:
        ValueError: anything else (launch's words: ``Cannot convert value 'x' to '<class 'bool'>'``).
    """
    return coerce(text, DataType(bool))
