"""Substitutions in launch files: ``$(var rate)``, ``$(env HOME /tmp)``, ``$(find-pkg-share demo)/x``.

An attribute's text is split into plain text and substitutions, following the grammar of the
real launch front end (launch/frontend/grammar.lark): ``$(NAME ARG ARG ...)`` with arguments
separated by one space; an argument may hold further substitutions, or be quoted ('...' or
"...") to contain spaces; a backslash makes the next character literal (``\\$(`` is text).
Substitutions are performed when their action runs, against the launch context (its
arguments, environment and current file).

Besides the values (var, env, find-pkg-share, find-pkg-prefix, dirname, filename) there are
launch's logic ones, as Jazzy has them: ``$(not X)``, ``$(and X Y)``, ``$(or X Y)``,
``$(any X ...)``, ``$(all X ...)`` read "true"/"false"/"1"/"0" (coercion.to_bool) and give
"true" or "false"; ``$(equals X Y)`` and ``$(not-equals X Y)`` compare booleans as booleans and
numbers as numbers; ``$(if C A [B])`` chooses; ``$(eval 'EXPR' [MODULES])`` is a Python
expression with the math module (its functions also without ``math.``), as PythonExpression."""

from __future__ import annotations

import importlib
import math
import re
from dataclasses import dataclass
from pathlib import Path

from course_lib.launch import coercion
from course_lib.launch.entities import LaunchFileError, did_you_mean

#: The substitutions supported here: name -> (fewest arguments, most arguments (None: any number),
#: how to write it). launch's Jazzy front end exposes each under the same name.
SUPPORTED = {
    "var": (1, 2, "$(var NAME [DEFAULT])"),
    "env": (1, 2, "$(env NAME [DEFAULT])"),
    "find-pkg-share": (1, 1, "$(find-pkg-share PACKAGE)"),
    "find-pkg-prefix": (1, 1, "$(find-pkg-prefix PACKAGE)"),
    "dirname": (0, 0, "$(dirname)"),
    "filename": (0, 0, "$(filename)"),
    "eval": (1, 2, "$(eval 'PYTHON EXPRESSION' [MODULE,MODULE...])"),
    "not": (1, 1, "$(not VALUE)"),
    "and": (2, 2, "$(and LEFT RIGHT)"),
    "or": (2, 2, "$(or LEFT RIGHT)"),
    "any": (0, None, "$(any VALUE ...)"),
    "all": (0, None, "$(all VALUE ...)"),
    "equals": (2, 2, "$(equals LEFT RIGHT)"),
    "not-equals": (2, 2, "$(not-equals LEFT RIGHT)"),
    "if": (2, 3, "$(if CONDITION IF_VALUE [ELSE_VALUE])"),
}

#: Substitutions of the full ROS 2 launch that this one does not do.
NOT_SUPPORTED = ("command", "anon", "file-content", "find-exec", "exec-in-pkg", "param", "launch_log_dir",
                 "log_dir")

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


def _count_words(name: str, fewest: int, most: int) -> str:
    """launch's words for a wrong number of arguments (its substitutions' parse methods; for
    or, equals and not-equals launch says "and substitution", a slip not copied here)."""
    if most == 0:
        return f"{name} substitution doesn't expect arguments"
    if fewest == most:
        return f"{name} substitution expects {fewest} argument{'' if fewest == 1 else 's'}"
    return f"{name} substitution expects {fewest} or {most} arguments"


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
            from course_lib.ros import ament

            try:
                found = ament.share(first) if self.name == "find-pkg-share" else ament.prefix(first)
            except LookupError as error:
                raise self.error(str(error)) from None
            return str(found)
        if self.name == "dirname":
            return str(context.current_file.parent)
        if self.name == "filename":
            return str(context.current_file)
        if self.name == "eval":
            return self._evaluate(first, context)
        if self.name == "equals":
            return _text_of(_equal(first, perform(self.args[1], context)))
        if self.name == "not-equals":
            return _text_of(not _equal(first, perform(self.args[1], context)))
        if self.name == "if":
            branch = self.args[1] if self._truth(first) else (self.args[2] if len(self.args) == 3 else [""])
            return perform(branch, context)
        # not, and, or, any, all: every argument is read as a boolean (none is skipped), as in launch
        values = [self._truth(perform(arg, context)) for arg in self.args]
        if self.name == "not":
            return _text_of(not values[0])
        return _text_of(any(values) if self.name in ("or", "any") else all(values))

    def _truth(self, text: str) -> bool:
        try:
            return coercion.to_bool(text)
        except ValueError as error:  # launch raises SubstitutionFailure with these words
            raise self.error(str(error)) from None

    def _evaluate(self, expression: str, context) -> str:
        """``$(eval)``: a Python expression, as launch's PythonExpression: the modules named
        (math when none are) are available by name, and math's functions also without it."""
        modules = ["math"]
        if len(self.args) == 2:
            text = perform(self.args[1], context)
            modules = [name.strip() for name in text.split(",")] if text else []
        names = {}
        try:
            for module in map(importlib.import_module, modules):
                if module.__name__ == "math":
                    names.update(vars(module))
                names[module.__name__] = module
            return str(eval(expression, {}, names))  # noqa: S307 (what launch's PythonExpression does)
        except Exception as error:  # launch reports what the expression raised, in its words
            raise self.error(str(error)) from None

    def describe(self) -> str:
        """How ``ros2 launch --show-args`` prints it, like the real tool's describe()."""
        inner = [describe(arg) for arg in self.args]
        if self.name == "eval":
            modules = "'math'" if len(self.args) == 1 else inner[1]
            return f"PythonExpr({inner[0]}, [{modules}])"
        names = {"var": "LaunchConfig({})", "env": "EnvVar({})", "find-pkg-share": "FindPackageShare(pkg={})",
                 "find-pkg-prefix": "FindPackagePrefix(pkg={})", "dirname": "ThisLaunchFileDir()",
                 "filename": "ThisLaunchFile()"}
        if self.name in names:
            return names[self.name].format(inner[0] if inner else "")
        kind = {"not": "Not", "and": "And", "or": "Or", "any": "Any", "all": "All", "equals": "Equals",
                "not-equals": "NotEquals", "if": "IfElse"}[self.name]
        return f"{kind}Substitution({', '.join(inner)})"


def _text_of(value: bool) -> str:
    return "true" if value else "false"


def _equal(left: str, right: str) -> bool:
    """launch's EqualsSubstitution: booleans as booleans ("1" is "true"), numbers as numbers
    (math.isclose, so "nan" equals nothing), anything else as text."""
    booleans = ("true", "false", "1", "0")
    if left.lower() in booleans and right.lower() in booleans:
        return (left.lower() in ("true", "1")) == (right.lower() in ("true", "1"))
    try:
        return math.isclose(float(left), float(right))
    except ValueError:
        return left == right


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
            near = "" if name in NOT_SUPPORTED else did_you_mean(name, SUPPORTED)
            raise LaunchFileError(f"$({name}) {kind}{near}; supported: "
                                  f"{supported_list()}", self.file, self.line)
        fewest, most, form = SUPPORTED[name]
        if len(args) < fewest or (most is not None and len(args) > most):
            raise LaunchFileError(f"{_count_words(name, fewest, most)} (got {len(args)} in {self.text!r}): "
                                  f"write {form}", self.file, self.line)
        if name == "eval" and len(args) == 2 and has_substitutions(args[1]):
            raise LaunchFileError(f"$(eval) takes its modules as plain text, like 'math, sys', not substitutions "
                                  f"(in {self.text!r})", self.file, self.line)
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
