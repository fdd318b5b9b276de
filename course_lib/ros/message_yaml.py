"""Messages as text: type names to classes, messages to YAML as ``ros2 topic echo`` prints them, and
YAML values into messages as ``ros2 topic pub`` reads them.
"""

from __future__ import annotations

import array
import functools
import importlib
import sys

# --- message types ----------------------------------------------------------------------

def message_class(type_name: str, kind: str = "msg"):
    """The Python class of a message type name (or of a service or action type).

    Args:
        type_name: "std_msgs/msg/String" (the form the graph reports) or "std_msgs/String".
        kind: what a two-part name leaves out: "msg", or "srv"/"action" ("std_srvs/SetBool").

    Returns:
        The message class, e.g. ``std_msgs.msg.String``.

    Raises:
        ValueError: the name is malformed, or its package is not installed (the message says
            which pip package provides it).
    """
    parts = type_name.split("/")
    if len(parts) == 2:
        parts = [parts[0], kind, parts[1]]
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"Message type {type_name!r} is not of the form 'package/msg/Type', "
                         "e.g. 'std_msgs/msg/String'")
    package, kind, name = parts
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ModuleNotFoundError:
        raise ValueError(f"Cannot import the message type {type_name}: its package {package} is "
                         f"not installed; install ros-jazzy-{package.replace('_', '-')} "
                         "(pip) or build it in your colcon workspace and source it") from None
    try:
        return getattr(module, name)
    except AttributeError:
        raise ValueError(f"Package {package} has no {kind} type {name!r}; check the spelling "
                         f"(`ros2 topic list -t` or graph.topic_list(types=True) shows the types in use)") from None



def message_to_dict(msg, truncate_length: int | None = 128, no_arr: bool = False,
                    no_str: bool = False):
    """A message as plain dicts, lists and numbers (for printing, JSON or comparisons).

    Converts the way ``ros2 topic echo`` does before it prints YAML.

    Args:
        msg: a ROS message (nested messages and arrays are converted too).
        truncate_length: arrays and strings longer than this keep their first elements and
            end with "..." (ros2 topic echo's default is 128); None keeps everything.
        no_arr: show each array field as its type and length only (echo's ``--no-arr``).
        no_str: show each string field as its length only (echo's ``--no-str``).

    Returns:
        A dict in field order, or the plain value when ``msg`` is not a message.
    """
    if hasattr(msg, "get_fields_and_field_types"):
        return {field: _field_to_plain(getattr(msg, field), slot_type, truncate_length, no_arr, no_str)
                for field, slot_type in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES, strict=True)}
    if isinstance(msg, (bytes, bytearray)):
        text = "".join(chr(byte) for byte in msg[:truncate_length])
        return text + "..." if truncate_length is not None and len(msg) > truncate_length else text
    if isinstance(msg, str):
        if no_str:
            return f"<string length: <{len(msg)}>>"
        cut = truncate_length is not None and len(msg) > truncate_length
        return msg[:truncate_length] + "..." if cut else msg
    if isinstance(msg, array.array) or _is_numpy(msg, "ndarray"):
        msg = msg.tolist()
    if isinstance(msg, (list, tuple)):
        items = list(msg)
        cut = truncate_length is not None and len(items) > truncate_length
        items = [message_to_dict(item, truncate_length, no_arr, no_str)
                 for item in (items[:truncate_length] if cut else items)]
        return items + ["..."] if cut else items
    if _is_numpy(msg, "generic"):
        return msg.item()
    return msg


def _is_numpy(value, kind: str) -> bool:
    """Whether value is a numpy ``kind`` ("ndarray", "generic"). Only a process that has imported
    numpy has numpy values (message classes with array fields import it), and a ``ros2`` command
    that handles none spares the import, a fifth of its processor time."""
    numpy = sys.modules.get("numpy")
    return numpy is not None and isinstance(value, getattr(numpy, kind))


def _field_to_plain(value, slot_type, truncate_length, no_arr, no_str):
    from rosidl_parser import definition

    if no_arr and isinstance(slot_type, definition.AbstractNestedType):
        element = slot_type.value_type
        element = ("string" if isinstance(element, definition.AbstractString) else
                   "/".join(element.namespaced_name()) if isinstance(element, definition.NamespacedType)
                   else getattr(element, "typename", "unknown"))
        if isinstance(slot_type, definition.Array):
            return f"<array type: {element}[{slot_type.size}]>"
        if isinstance(slot_type, definition.BoundedSequence):
            return f"<sequence type: {element}[{slot_type.maximum_size}], length: {len(value)}>"
        return f"<sequence type: {element}, length: {len(value)}>"
    return message_to_dict(value, truncate_length, no_arr, no_str)


def format_message(msg, truncate_length: int | None = 128, no_arr: bool = False,
                   no_str: bool = False) -> str:
    """One message as YAML, the way ``ros2 topic echo`` prints it (without the "---")."""
    import yaml

    return yaml.safe_dump(message_to_dict(msg, truncate_length, no_arr, no_str), sort_keys=False,
                          default_flow_style=False, allow_unicode=True, width=1 << 30)


def format_messages(messages, truncate_length: int | None = 128) -> str:
    """Messages as ``ros2 topic echo`` prints them: YAML, each followed by a "---" line."""
    return "".join(format_message(msg, truncate_length) + "---\n" for msg in messages)


def fill_message(msg, values) -> list:
    """Set a message's fields from plain values, the way ``ros2 topic pub`` reads its YAML.

    Args:
        msg: the message to fill; it is changed in place.
        values: ``{field: value}``; a nested message takes a dict, an array a list. As in
            ``ros2 topic pub``, ``header: auto`` (a std_msgs/Header) and ``stamp: now`` (a
            builtin_interfaces/Time) mean "the time of each publish".

    Returns:
        One setter per field marked auto/now: call each with a builtin_interfaces/Time
        (``node.get_clock().now().to_msg()``) before publishing.

    Raises:
        ValueError: a field the message does not have, or a value that does not fit its field
            (the message names the field and its type).
    """
    setters: list = []
    _fill(msg, values, setters, "")
    return setters


def _type_name(msg) -> str:
    module = type(msg).__module__.split(".")
    return f"{module[0]}/{module[1]}/{type(msg).__name__}"


def _fill(msg, values, setters: list, path: str) -> None:
    from rosidl_parser import definition

    fields = msg.get_fields_and_field_types()
    if not isinstance(values, dict):
        raise ValueError(f"{path.rstrip('.') or 'The message'} is a {_type_name(msg)} and needs a "
                         f"dictionary of its fields ({', '.join(fields)}), not {values!r}")
    slots = dict(zip(fields, msg.SLOT_TYPES, strict=True))
    for field, value in values.items():
        where = path + str(field)
        if field not in fields:
            raise ValueError(f"{_type_name(msg)} has no field {field!r}"
                             f"{' (in ' + path.rstrip('.') + ')' if path else ''}; its fields are: "
                             f"{', '.join(fields)}")
        current = getattr(msg, field)
        slot = slots[field]
        if hasattr(current, "get_fields_and_field_types"):
            kind = _type_name(current)
            if value == "auto" and kind == "std_msgs/msg/Header":
                setters.append(functools.partial(setattr, current, "stamp"))
            elif value == "now" and kind == "builtin_interfaces/msg/Time":
                setters.append(functools.partial(setattr, msg, field))
            else:
                _fill(current, value, setters, where + ".")
            continue
        if isinstance(slot, definition.AbstractNestedType) and \
                isinstance(slot.value_type, definition.NamespacedType):
            element = getattr(importlib.import_module(".".join(slot.value_type.namespaces)),
                              slot.value_type.name)
            if not isinstance(value, list):
                raise ValueError(f"{where} ({fields[field]}) needs a list, not {value!r}")
            items = []
            for index, item in enumerate(value):
                items.append(element())
                _fill(items[-1], item, setters, f"{where}[{index}].")
            value = items
        elif isinstance(current, array.array):
            value = _converted(functools.partial(array.array, current.typecode), where, fields[field], value)
        elif _is_numpy(current, "ndarray"):
            value = _converted(functools.partial(sys.modules["numpy"].array, dtype=current.dtype), where,
                               fields[field], value)
        elif not isinstance(current, list) and type(value) is not type(current):
            value = _converted(type(current), where, fields[field], value)
        _converted(functools.partial(setattr, msg, field), where, fields[field], value)


def _converted(convert, where: str, field_type: str, value):
    """convert(value), or a ValueError that names the field, its type and the value."""
    try:
        return convert(value)
    except (AssertionError, TypeError, ValueError, OverflowError) as error:
        raise ValueError(f"{where} is a {field_type} and cannot take {value!r}"
                         f"{': ' + str(error) if str(error) else ''}") from None
