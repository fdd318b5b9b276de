"""The notebook's run inside the sandbox (autograder.grading.pipeline.run_notebook)::

    python -m autograder.grading.sandboxed_autograde COURSE_ROOT ASSIGNMENT STUDENT

does what ``nbgrader autograde ASSIGNMENT --student STUDENT --force`` does in COURSE_ROOT (the
grading's private course root): nbgrader's Autograde converter with the root's nbgrader_config.py,
its log on stderr in the app's format (``[AutogradeApp | INFO] ...``), exit code 1 when it fails.
It runs the converter in this process, as autograder.nbgrader_cli runs nbgrader's other steps,
without nbgrader's command line and package imports (its apps, exchange and server extensions):
about half of the CLI's start-up.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    root, assignment, student = (sys.argv[1:] if argv is None else argv)
    from autograder import nbgrader_cli

    nbgrader_cli.import_without_server_extensions()
    from nbgrader.converters import Autograde, NbGraderException

    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("[AutogradeApp | %(levelname)s] %(message)s"))
    log = logging.getLogger("AutogradeApp")
    for logger in (log, logging.getLogger("traitlets")):  # the latter: parts made without a parent
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
        logger.propagate = False
    converter = nbgrader_cli.converter_for(Autograde, Path(root), assignment, student)
    converter.log = log
    converter.force = True
    try:
        converter.start()
    except NbGraderException:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
