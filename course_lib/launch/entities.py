"""Read an XML or YAML launch file into a tree of entities that know their file and line.

Both formats describe the same tags (ROS 2's launch_xml and launch_yaml front ends): in XML a
tag is an element with attributes and nested elements; in YAML it is a one-key mapping whose
value holds the attributes, and nested tags are lists under a key (``param: [...]``,
``children: [...]``) or the value itself (``launch: [...]``, ``group: [...]``). The parser
(parser.py) reads attributes through an Entity, which remembers what was read, so anything
left unread is reported as unsupported instead of being ignored.
"""

from __future__ import annotations

import difflib
from pathlib import Path
from xml.parsers import expat

import yaml

#: File name endings of the two formats, as the real ``ros2 launch`` recognises them.
XML_ENDINGS = (".launch.xml", ".xml")
YAML_ENDINGS = (".launch.yaml", ".launch.yml", ".yaml", ".yml")


class LaunchFileError(Exception):
    """A launch file that cannot be run as written: the message names the file and line."""

    def __init__(self, message: str, file=None, line: int | None = None):
        self.message, self.file, self.line = message, file, line
        where = f"{file}:{line}: " if file is not None and line else (f"{file}: " if file is not None else "")
        super().__init__(where + message)


def did_you_mean(name: str, choices) -> str:
    """' (did you mean 'x'?)' for a near miss among choices, else ''."""
    close = difflib.get_close_matches(name, list(choices), n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


class Entity:
    """One tag of a launch file: its kind, attributes, nested tags, file and line.

    Attributes:
        kind: the tag name ("node", "param", ...).
        file: the launch file it comes from.
        line: the line of the tag (1-based).
        typed: True for YAML, whose values keep their YAML types; XML values are strings.
    """

    def __init__(self, kind: str, file: Path, line: int, attributes: dict, nested: list | None,
                 *, typed: bool, attribute_lines: dict | None = None):
        self.kind, self.file, self.line, self.typed = kind, file, line, typed
        self._attributes = attributes
        self._attribute_lines = attribute_lines or {}
        self._nested = nested  # XML: child elements; YAML: the list of children, if any
        self._read: set[str] = set()

    def __repr__(self) -> str:
        return f"<{self.kind} at {self.file}:{self.line}>"

    def error(self, message: str, attribute: str | None = None) -> LaunchFileError:
        """A LaunchFileError pointing at this tag (or at one of its YAML attributes)."""
        return LaunchFileError(message, self.file, self._attribute_lines.get(attribute, self.line))

    def has(self, name: str) -> bool:
        return name in self._attributes

    def get(self, name: str, *, required: bool = False):
        """An attribute's value (str in XML, any YAML value in YAML), or None when absent.

        XML's ``name-sep`` companion attribute splits the value into a list, like launch_xml.

        Raises:
            LaunchFileError: a required attribute is missing.
        """
        if name not in self._attributes:
            if required:
                raise self.error(f"<{self.kind}> needs the attribute '{name}'")
            return None
        self._read.add(name)
        value = self._attributes[name]
        separator = f"{name}-sep"
        if not self.typed and separator in self._attributes:
            self._read.add(separator)
            value = value.split(self._attributes[separator])
        return value

    def get_text(self, name: str, *, required: bool = False) -> str | None:
        """An attribute that must be text (YAML numbers and booleans are written as YAML would)."""
        value = self.get(name, required=required)
        if value is None or isinstance(value, str):
            return value
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, (int, float)):
            return str(value)
        raise self.error(f"<{self.kind}> attribute '{name}' must be text, not {type(value).__name__}", name)

    def get_bool(self, name: str) -> bool | None:
        """A true/false attribute ("true", "false", "1", "0" in XML; a YAML boolean in YAML)."""
        value = self.get(name)
        if value is None or isinstance(value, bool):
            return value
        if isinstance(value, str) and value.strip().lower() in ("true", "1", "false", "0"):
            return value.strip().lower() in ("true", "1")
        raise self.error(f"<{self.kind}> attribute '{name}' must be true or false, not {value!r}", name)

    def nested(self, kind: str) -> list[Entity]:
        """The nested tags of one kind: XML child elements ``<kind .../>``, or YAML's list under
        the key ``kind`` (``param: [{name: ..., value: ...}, ...]``)."""
        if not self.typed:
            self._read.add(f"<{kind}>")
            return [child for child in self._nested or [] if child.kind == kind]
        value = self.get(kind)
        if value is None:
            return []
        if not isinstance(value, list) or not all(isinstance(item, dict) for item in value):
            raise self.error(f"'{kind}' of <{self.kind}> must be a list of mappings, like "
                             f"{kind}: [{{name: ..., ...}}]", kind)
        line = self._attribute_lines.get(kind, self.line)
        return [_yaml_entity(kind, item, self.file, line) for item in value]

    def children(self) -> list[Entity]:
        """The nested action tags of <launch> or <group>, in order."""
        if not self.typed:
            self._read.update(f"<{child.kind}>" for child in self._nested or [])
            return list(self._nested or [])
        items = self._nested
        self._read.add("<children>")
        if items is None:
            items = self.get("children")
            if items is None:
                raise self.error(f"<{self.kind}> needs its tags as a list: {self.kind}: [...] or "
                                 f"{self.kind}: {{children: [...]}}")
        if not isinstance(items, list):
            raise self.error(f"the children of <{self.kind}> must be a list of one-key mappings like - node: {{...}}")
        line = self._attribute_lines.get("children", self.line)
        return [_yaml_child(item, self.file, line) for item in items]

    def check_all_read(self, supported: str, known=frozenset()) -> None:
        """Raise for any attribute or nested tag the parser did not read.

        One that the full ROS 2 launch does not know either gets its words (launch_xml's and
        launch_yaml's entity.py): ``Unexpected attribute(s) found in `arg`: {'whats_this'}``,
        ``Unexpected nested tag(s) found in `arg`: {'whats_this'}`` (XML), ``Unexpected key(s)
        found in `arg`: {'whats_this'}`` (YAML). One that it knows and this one does not run is
        said to be not supported here, with what is.

        Args:
            supported: what this tag supports, for the message (e.g. "pkg, exec, name").
            known: the attributes and nested tags the full ROS 2 launch reads on this tag.
        """
        unread = [name for name in self._attributes if name not in self._read]
        if not self.typed:
            children = [child for child in self._nested or []
                        if f"<{child.kind}>" not in self._read and child.kind not in known]
            if children:
                strange = {child.kind for child in children}
                raise children[0].error(f"Unexpected nested tag(s) found in `{self.kind}`: {strange}"
                                        f"{did_you_mean(children[0].kind, known)}")
        strange = [name for name in unread if name not in known]
        if strange:
            words = "key(s)" if self.typed else "attribute(s)"
            raise self.error(f"Unexpected {words} found in `{self.kind}`: {set(strange)}"
                             f"{did_you_mean(strange[0], known)}", strange[0])
        if unread:
            name = unread[0]
            raise self.error(f"<{self.kind}> attribute '{name}' is not supported here"
                             f"{did_you_mean(name, supported.replace(',', ' ').split())}; "
                             f"<{self.kind}> supports: {supported}", name)
        if self.typed and self._nested is not None and "<children>" not in self._read:
            raise self.error(f"<{self.kind}> takes attributes (a mapping), not a list of tags; "
                             f"<{self.kind}> supports: {supported}")
        if not self.typed:
            for child in self._nested or []:
                if f"<{child.kind}>" not in self._read:
                    raise child.error(f"<{child.kind}> is not supported inside <{self.kind}>; "
                                      f"<{self.kind}> supports: {supported}")


# --- XML ------------------------------------------------------------------------------------

def load_xml(path: Path, text: str) -> Entity:
    """The root entity of an XML launch file, every element with its line number."""
    parser = expat.ParserCreate()
    stack: list[Entity] = []
    roots: list[Entity] = []

    def start(tag, attributes):
        entity = Entity(tag, path, parser.CurrentLineNumber, dict(attributes), [], typed=False)
        (stack[-1]._nested if stack else roots).append(entity)
        stack.append(entity)

    parser.StartElementHandler = start
    parser.EndElementHandler = lambda tag: stack.pop()
    try:
        parser.Parse(text, True)
    except expat.ExpatError as error:
        raise LaunchFileError(f"not well-formed XML: {expat.errors.messages[error.code]} "
                              f"(column {error.offset + 1})", path, error.lineno) from None
    return roots[0]


# --- YAML -----------------------------------------------------------------------------------

class _Mapping(dict):
    """A YAML mapping that remembers its line and the line of each key."""

    line = 0
    key_lines: dict


class _LineLoader(yaml.SafeLoader):
    """PyYAML's safe loader, with line numbers kept on mappings."""


def _construct_mapping(loader: _LineLoader, node: yaml.MappingNode):
    mapping = _Mapping()
    mapping.line, mapping.key_lines = node.start_mark.line + 1, {}
    yield mapping
    loader.flatten_mapping(node)
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        mapping[key] = loader.construct_object(value_node, deep=True)
        mapping.key_lines[key] = key_node.start_mark.line + 1


_LineLoader.add_constructor("tag:yaml.org,2002:map", _construct_mapping)


def _yaml_entity(kind: str, value, file: Path, line: int, *, tag_line: bool = False) -> Entity:
    """An entity from the value of a YAML tag: a mapping of attributes, or a list of children.
    Its line is the mapping's own, or with tag_line the given one (the line of ``- node:``)."""
    if isinstance(value, dict):
        return Entity(kind, file, line if tag_line else getattr(value, "line", line), dict(value), None, typed=True,
                      attribute_lines=getattr(value, "key_lines", {}))
    if isinstance(value, list):
        return Entity(kind, file, line, {}, value, typed=True)
    if value is None:
        return Entity(kind, file, line, {}, None, typed=True)
    raise LaunchFileError(f"'{kind}' must hold a mapping of attributes (or a list of tags), "
                          f"not {value!r}", file, line)


def _yaml_child(item, file: Path, line: int) -> Entity:
    """A child tag written as a one-key mapping, ``- node: {...}``."""
    if not isinstance(item, dict) or len(item) != 1:
        where = getattr(item, "line", line)
        raise LaunchFileError("each tag in a list must be a mapping with one key, the tag name "
                              f"(like - node: {{pkg: ..., exec: ...}}), not {item!r}", file, where)
    (kind, value), = item.items()
    return _yaml_entity(kind, value, file, getattr(item, "key_lines", {}).get(kind, line), tag_line=True)


def load_yaml(path: Path, text: str) -> Entity:
    """The root entity of a YAML launch file (``launch:`` and its list of tags)."""
    try:
        tree = yaml.load(text, Loader=_LineLoader)  # noqa: S506 (a SafeLoader subclass)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        raise LaunchFileError(f"not valid YAML: {getattr(error, 'problem', None) or error}",
                              path, mark.line + 1 if mark else None) from None
    if not isinstance(tree, dict) or len(tree) != 1:
        raise LaunchFileError("a YAML launch file has one top-level key, launch: followed by its tags",
                              path, 1)
    return _yaml_child(tree, path, 1)


# --- either ---------------------------------------------------------------------------------

def load(path) -> Entity:
    """The root entity of a launch file, read as XML or YAML by its name (like ``ros2 launch``:
    a name it does not recognise is tried as XML, then as YAML).

    Raises:
        LaunchFileError: the file is missing, a Python launch file, or not valid XML/YAML.
    """
    path = Path(path)
    name = path.name
    if name.endswith(".py"):
        raise LaunchFileError("Python launch files are not supported by the course's ros2 launch (a full "
                              "ROS 2 install runs them); write it as an XML or YAML launch file, "
                              "which support the same tags", path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise LaunchFileError("no such launch file", path) from None
    except (IsADirectoryError, UnicodeDecodeError) as error:
        raise LaunchFileError(f"cannot read it as a launch file: {error}", path) from None
    if name.endswith(XML_ENDINGS):
        return load_xml(path, text)
    if name.endswith(YAML_ENDINGS):
        return load_yaml(path, text)
    errors = []
    for loader in (load_xml, load_yaml):
        try:
            return loader(path, text)
        except LaunchFileError as error:
            errors.append(error.message)
    raise LaunchFileError(f"neither XML ({errors[0]}) nor YAML ({errors[1]}); name XML launch files "
                          "*.launch.xml and YAML ones *.launch.yaml", path)
