"""Substitutions in launch files: ``$(var rate)``, ``$(env HOME /tmp)``, ``$(find-pkg-share demo)/x``.

An attribute's text is split into plain text and substitutions, following the grammar of the
real launch front end (launch/frontend/grammar.lark): ``$(NAME ARG ARG ...)`` with arguments
separated by one space; an argument may hold further substitutions, or be quoted ('...' or
"...") to contain spaces; a backslash makes the next character literal (``\\$(`` is text).
Substitutions are performed when their action runs, against the launch context (its
arguments, environment and current file).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from course_lib.launch.entities import LaunchFileError, did_you_mean

#: The substitutions supported here: name -> (fewest arguments, most arguments, how to write it).
SUPPORTED = {
    "var": (1, 2, "$(var NAME [DEFAULT])"),
    "env": (1, 2, "$(env NAME [DEFAULT])"),
    "find-pkg-share": (1, 1, "$(find-pkg-share PACKAGE)"),
    "find-pkg-prefix": (1, 1, "$(find-pkg-prefix PACKAGE)"),
    "dirname": (0, 0, "$(dirname)"),
    "filename": (0, 0, "$(filename)"),
}

#: Substitutions of the full ROS 2 launch that this one does not do.
NOT_SUPPORTED = ("eval", "command", "anon", "not", "and", "or", "any", "all", "equals", "not-equals",
                 "if", "file-content", "find-exec", "exec-in-pkg", "param", "launch_log_dir", "log_dir")

#: What a missing launch configuration or environment variable is told, with the fix.
_MISSING = {
    "var": ("launch configuration '{name}' does not exist: declare it with <arg name=\"{name}\" default=\"...\"/> "
            "(or <let>) before it is used, or pass {name}:=VALUE"),
    "env": "environment variable '{name}' does not exist: set it, or give a default: $(env {name} DEFAULT)",
}

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
_ESCAPED = re.compile(r"\\(.)")


def supported_list() -> str:
    return ", ".join(form for _, _, form in SUPPORTED.values())


@dataclass
class Substitution:
    """One ``$(name args...)``; each argument is a list of text and substitutions."""

    name: str
    args: list
    file: Path | None = None
    line: int | None = None

    def error(self, message: str) -> LaunchFileError:
        return LaunchFileError(message, self.file, self.line)

    def perform(self, context) -> str:
        """The text this substitution stands for in `context` (configurations, environment,
        current_file).

        Raises:
            LaunchFileError: an argument or variable that does not exist, a missing package.
        """
        first = perform(self.args[0], context) if self.args else None
        if self.name in ("var", "env"):
            known = context.configurations if self.name == "var" else context.environment
            if first in known:
                return known[first]
            if len(self.args) == 2:  # the default is only performed when it is needed
                return perform(self.args[1], context)
            raise self.error(_MISSING[self.name].format(name=first))
        if self.name in ("find-pkg-share", "find-pkg-prefix"):
            from course_lib import ament

            try:
                found = ament.share(first) if self.name == "find-pkg-share" else ament.prefix(first)
            except LookupError as error:
                raise self.error(str(error)) from None
            return str(found)
        if self.name == "dirname":
            return str(context.current_file.parent)
        if self.name == "filename":
            return str(context.current_file)
        raise AssertionError(self.name)  # parse() only lets supported names through

    def describe(self) -> str:
        """How ``ros2 launch --show-args`` prints it, like the real tool's describe()."""
        inner = [describe(arg) for arg in self.args]
        names = {"var": "LaunchConfig({})", "env": "EnvVar({})", "find-pkg-share": "FindPackageShare(pkg={})",
                 "find-pkg-prefix": "FindPackagePrefix(pkg={})", "dirname": "ThisLaunchFileDir()",
                 "filename": "ThisLaunchFile()"}
        return names[self.name].format(inner[0] if inner else "")


def perform(parts, context) -> str:
    """The text of a parsed value: its text pieces and performed substitutions, joined."""
    return "".join(part if isinstance(part, str) else part.perform(context) for part in parts)


def describe(parts) -> str:
    return " + ".join(f"'{part}'" if isinstance(part, str) else part.describe() for part in parts)


def has_substitutions(parts) -> bool:
    return any(not isinstance(part, str) for part in parts)


def parse(text: str, file=None, line: int | None = None) -> list:
    """Split an attribute's text into text pieces and Substitutions.

    Raises:
        LaunchFileError: malformed ``$(...)``, or a substitution that is not supported here
            (the message lists those that are).
    """
    return _Parser(text, file, line).template()


class _Parser:
    """A recursive-descent reading of the front end's substitution grammar."""

    def __init__(self, text: str, file, line):
        self.text, self.file, self.line, self.i = text, file, line, 0

    def error(self, message: str) -> LaunchFileError:
        return LaunchFileError(f"{message} in {self.text!r} (at character {self.i + 1})", self.file, self.line)

    def escaped(self, i: int) -> bool:
        return i > 0 and self.text[i - 1] == "\\"

    def at_substitution(self) -> bool:
        return self.text.startswith("$(", self.i) and not self.escaped(self.i)

    def template(self) -> list:
        """Top level: text and substitutions; quotes are plain text here."""
        if not self.text:
            return [""]
        parts, start = [], 0
        while self.i < len(self.text):
            if self.at_substitution():
                _add_text(parts, self.text[start:self.i])
                parts.append(self.substitution(quote=None))
                start = self.i
            else:
                self.i += 1
        _add_text(parts, self.text[start:])
        return parts

    def substitution(self, quote: str | None) -> Substitution:
        self.i += 2  # "$("
        match = _IDENTIFIER.match(self.text, self.i)
        if not match:
            raise self.error("expected a substitution name after '$('")
        name, self.i = match.group(), match.end()
        args = []
        while True:
            if self.i >= len(self.text):
                raise self.error(f"$({name} ...) is not closed with ')'")
            if self.text[self.i] == ")":
                self.i += 1
                break
            if self.text[self.i] != " ":
                raise self.error(f"expected ' ' or ')' after $({name}")
            self.i += 1
            args.append(self.argument(quote))
        return self.checked(name, args)

    def checked(self, name: str, args: list) -> Substitution:
        if name not in SUPPORTED:
            kind = "is not supported here (a full ROS 2 install has it)" if name in NOT_SUPPORTED \
                else "is not a launch substitution"
            raise LaunchFileError(f"$({name}) {kind}{did_you_mean(name, SUPPORTED)}; supported: "
                                  f"{supported_list()}", self.file, self.line)
        fewest, most, form = SUPPORTED[name]
        if not fewest <= len(args) <= most:
            raise LaunchFileError(f"$({name}) takes {fewest if fewest == most else f'{fewest} or {most}'} "
                                  f"argument{'' if most == 1 else 's'}, got {len(args)} in {self.text!r}: "
                                  f"write {form}", self.file, self.line)
        return Substitution(name, args, self.file, self.line)

    def argument(self, quote: str | None) -> list:
        """One argument: a quoted text (only outside quotes) or unquoted pieces and substitutions."""
        char = self.text[self.i] if self.i < len(self.text) else ""
        if quote is None and char in ("'", '"'):
            return self.quoted(char)
        parts, start = [], self.i
        while self.i < len(self.text):
            if self.at_substitution():
                _add_text(parts, self.text[start:self.i])
                parts.append(self.substitution(quote))
                start = self.i
            elif self.argument_char(quote):
                self.i += 1
            else:
                break
        _add_text(parts, self.text[start:self.i])
        if not parts:
            raise self.error("expected an argument (arguments are separated by one space; quote "
                             "an argument that contains spaces)")
        return parts

    def argument_char(self, quote: str | None) -> bool:
        char, escaped = self.text[self.i], self.escaped(self.i)
        if char == " ":
            return False
        if char in "()":
            return escaped
        if char in "'\"":
            return escaped or (quote is not None and char != quote)
        return True

    def quoted(self, quote: str) -> list:
        opened = self.i
        self.i += 1
        parts, start = [], self.i
        while True:
            if self.i >= len(self.text):
                self.i = opened
                raise self.error(f"the quote {quote} is not closed")
            char = self.text[self.i]
            if char == quote and not self.escaped(self.i):
                break
            if self.at_substitution():
                _add_text(parts, self.text[start:self.i])
                parts.append(self.substitution(quote))
                start = self.i
            else:
                self.i += 1
        _add_text(parts, self.text[start:self.i])
        self.i += 1
        return parts or [""]


def unescape(text: str) -> str:
    """Text with each backslash-escaped character taken literally (``\\$`` is ``$``)."""
    return _ESCAPED.sub(r"\1", text)


def _add_text(parts: list, raw: str) -> None:
    if raw:
        parts.append(unescape(raw))
