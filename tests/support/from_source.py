"""The course's code that is no installed package, imported from its files without putting a folder
on sys.path: the reference ROS packages' modules (assignments/reference_ws/src), as colcon would
install them, and assignments/build.py, the script that writes the assignments' notebooks."""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from course_lib import contract

REFERENCE_SOURCE = contract.ROOT / "assignments" / "reference_ws" / "src"


def _load(name: str, file: Path, search: list[str] | None = None) -> ModuleType:
    """The module `name` run from `file` (a package when `search` lists its folders), in sys.modules."""
    spec = importlib.util.spec_from_file_location(name, file, submodule_search_locations=search)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    return module


def reference_module(dotted: str) -> ModuleType:
    """The module `dotted` (``readmarker.crop``) of the reference package its first part names,
    imported from the package's source folder."""
    package = dotted.split(".")[0]
    if package not in sys.modules:
        folder = REFERENCE_SOURCE / package / package
        _load(package, folder / "__init__.py", [str(folder)])
    return importlib.import_module(dotted)


def assignments_build() -> ModuleType:
    """assignments/build.py (a script, in no package), imported once as the module ``build``."""
    return sys.modules.get("build") or _load("build", contract.ROOT / "assignments" / "build.py")
