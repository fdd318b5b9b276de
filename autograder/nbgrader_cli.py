"""nbgrader on a course directory: the environment of its processes (this repository importable),
and the steps of its commands run in this process with the course's configuration, as its formgrader runs
them (the converters of ``generate_assignment`` and ``generate_feedback``, ``zip_collect``'s app,
``release_assignment``'s exchange step), which spares a Python start and a second ``import
nbgrader`` (1.5-3 s of processor time on an idle machine) per call."""

from __future__ import annotations

import contextlib
import logging
import os
import sys
from pathlib import Path

from autograder.results import gradebook

REPO = Path(__file__).resolve().parent.parent


def import_without_server_extensions() -> None:
    """Make ``nbgrader``'s submodules importable without running its package ``__init__``, which
    imports its Jupyter server extensions (jupyter_server, tornado, the exchange, every app): about
    0.2-0.5 CPU-s that a grading process never uses. The package gets its version and its folder;
    its submodules load as usual. A process that already imported nbgrader keeps it; one that serves
    Jupyter (the lab, the formgrader) imports nbgrader itself and never calls this."""
    if "nbgrader" in sys.modules:
        return
    import importlib.util
    import types

    spec = importlib.util.find_spec("nbgrader")
    if spec is None or not spec.submodule_search_locations:
        return  # not installed: the import that needs it says so
    package = types.ModuleType("nbgrader", "A system for assigning and grading notebooks (its submodules only).")
    package.__path__, package.__file__, package.__spec__ = list(spec.submodule_search_locations), spec.origin, spec
    package.__package__ = "nbgrader"
    sys.modules["nbgrader"] = package
    try:
        from nbgrader._version import __version__
    except BaseException:
        del sys.modules["nbgrader"]
        raise
    package.__version__ = __version__


def env_for_tools() -> dict:
    """This process's environment with this repository on PYTHONPATH and this Python's folder on PATH."""
    env = dict(os.environ)
    path = [str(REPO)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p and p != str(REPO)]
    env["PYTHONPATH"] = os.pathsep.join(path)
    env["PATH"] = gradebook.with_this_python(env.get("PATH", ""))
    return env


def converter_for(converter_class, course: Path, assignment: str, student: str | None = None, settings=None):
    """An nbgrader converter (GenerateAssignment, GenerateFeedback, ...) for one assignment of the
    course (and one student's submission, if given), with the course's configuration or `settings`."""
    from autograder import config

    settings = config.load(course) if settings is None else settings
    return converter_class(coursedir=_course_directory(course, assignment, settings, student), config=settings)


def _course_directory(course: Path, assignment: str, settings, student: str | None = None):
    """nbgrader's CourseDirectory of the course with `settings`, set to one assignment (and student)."""
    from nbgrader.coursedir import CourseDirectory

    coursedir = CourseDirectory(config=settings, root=str(course))
    coursedir.assignment_id = assignment
    if student:
        coursedir.student_id = student
    return coursedir


def _run_in_process(step, what: str) -> str:
    """Start an nbgrader app, converter or exchange step; its log; RuntimeError with the log on failure
    (an app's ``fail`` exits, which is caught here like any error)."""
    from nbgrader.utils import capture_log

    outcome = capture_log(step)
    log = outcome.get("log", "")
    if not outcome["success"]:
        raise RuntimeError(f"nbgrader {what} failed:\n{(log + outcome.get('error', ''))[-3000:]}")
    return log


def _run_converter(converter_class, course: Path, assignment: str, student: str | None = None) -> str:
    """Run a converter as its command does with --force; its log; RuntimeError with the log on failure."""
    converter = converter_for(converter_class, course, assignment, student)
    converter.force = True
    return _run_in_process(converter, f"{converter_class.__name__} of {assignment}")


def _command_log(command: str) -> logging.Logger:
    """A logger at the command's level (INFO) that prints nothing: what it logs is returned (an
    app's own logger would print to this process's stderr, a plain step's drop the INFO lines)."""
    log = logging.getLogger(f"autograder.nbgrader_cli.{command}")
    log.propagate = False
    log.setLevel(logging.INFO)
    return log


@contextlib.contextmanager
def _course_importable(course: Path):
    """The course directory on sys.path, as the command has its working directory (there), so that a
    plugin the course's nbgrader_config.py names from a module beside it is found."""
    added = str(course) not in sys.path
    if added:
        sys.path.insert(0, str(course))
    try:
        yield
    finally:
        if added:
            sys.path.remove(str(course))


def generate_assignment(course: Path, assignment: str) -> str:
    """``nbgrader generate_assignment ASSIGNMENT --force``: the student version in release/, and the
    assignment, its cells and hidden tests in the gradebook."""
    from nbgrader.converters import GenerateAssignment

    return _run_converter(GenerateAssignment, Path(course), assignment)


def generate_feedback(course: Path, assignment: str, student: str | None = None) -> str:
    """``nbgrader generate_feedback ASSIGNMENT --force [--student STUDENT]``: the feedback pages of
    the autograded submissions."""
    from nbgrader.converters import GenerateFeedback

    return _run_converter(GenerateFeedback, Path(course), assignment, student)


def zip_collect(course: Path, assignment: str) -> str:
    """``nbgrader zip_collect ASSIGNMENT --force``: the files in downloaded/ASSIGNMENT/archive/
    extracted and copied to submitted/<student>/ASSIGNMENT/ by the course's collector plugin."""
    from nbgrader.apps.zipcollectapp import ZipCollectApp

    from autograder import config

    course = Path(course)
    settings = config.load(course)
    settings.ZipCollectApp.force = settings.ExtractorPlugin.force = True  # --force
    with _course_importable(course):  # the plugins are imported when the app reads its settings
        app = ZipCollectApp(config=settings, log=_command_log("zip_collect"))
        app.coursedir = _course_directory(course, assignment, settings)
        return _run_in_process(app, f"zip_collect {assignment}")


def release_assignment(course: Path, assignment: str, exchange: Path) -> str:
    """``nbgrader release_assignment ASSIGNMENT --force --Exchange.root=EXCHANGE``: the assignment's
    release/ folder into the exchange's outbound/, as the files of this process's user."""
    from nbgrader.auth import Authenticator
    from nbgrader.exchange import ExchangeFactory

    from autograder import config

    course = Path(course)
    settings = config.load(course)
    settings.Exchange.root = str(exchange)
    settings.ExchangeReleaseAssignment.force = True  # --force
    with _course_importable(course):  # the exchange and authenticator classes are imported with the settings
        step = ExchangeFactory(config=settings).ReleaseAssignment(
            coursedir=_course_directory(course, assignment, settings), authenticator=Authenticator(config=settings),
            config=settings, log=_command_log("release_assignment"))
        return _run_in_process(step, f"release_assignment {assignment}")
