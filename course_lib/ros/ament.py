"""The ament index: which packages are installed, where, and which executables they offer.

What ``ros2 pkg list|prefix|executables``, ``ros2 run`` and a launch file's ``$(find-pkg-share)``
look up, on AMENT_PREFIX_PATH (extended by ``source install/setup.bash`` and, on the pip
install, by course_lib itself with the venv's prefix). One place for all of them.
"""

from __future__ import annotations

import os
from pathlib import Path

from ament_index_python.packages import PackageNotFoundError, get_package_prefix, get_packages_with_prefixes


def packages() -> dict[str, Path]:
    """Every installed package and its prefix (the first on AMENT_PREFIX_PATH wins), sorted by name."""
    return {name: Path(prefix) for name, prefix in sorted(get_packages_with_prefixes().items())}


def prefix(package: str) -> Path:
    """The install prefix of a package.

    Raises:
        LookupError: the package is not installed; the message says how to make it visible.
    """
    from course_lib.ros.node_logs import kernel_hint

    try:
        return Path(get_package_prefix(package))
    except (PackageNotFoundError, ValueError):
        raise LookupError(f"Package '{package}' not found: build it with colcon and `source install/setup.bash`, "
                          "or check its name with `ros2 pkg list`"
                          + kernel_hint("workspace.use_workspace(WS)")) from None


def share(package: str) -> Path:
    """The package's share directory (``$(find-pkg-share package)``)."""
    return prefix(package) / "share" / package


def executables(package: str) -> list[str]:
    """The executables ``ros2 run package`` offers: the executable files in <prefix>/lib/<package>/."""
    return executables_in(prefix(package), package)


def executables_in(install_prefix, package: str) -> list[str]:
    """The executable files a package installs below one prefix (``<prefix>/lib/<package>/``)."""
    folder = Path(install_prefix) / "lib" / package
    if not folder.is_dir():
        return []
    return sorted(p.name for p in folder.iterdir() if p.is_file() and os.access(p, os.X_OK))


def executable(package: str, name: str) -> Path:
    """The path of an executable of a package, as ``ros2 run package name`` starts it.

    Raises:
        LookupError: no such package or executable; the message lists what there is.
    """
    path = prefix(package) / "lib" / package / name
    if path.is_file() and os.access(path, os.X_OK):
        return path
    available = executables(package)
    raise NoExecutable(f"No executable '{name}' found in package '{package}'; it has: "
                       f"{', '.join(available) or 'none'} (add it to entry_points in setup.py and build again)")


class NoExecutable(LookupError):
    """The package is there, the executable is not (``ros2 run``: "No executable found")."""
