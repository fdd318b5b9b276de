"""The notebook's run in the sandbox (autograder.grading.sandboxed_autograde) says and exits what
``nbgrader autograde`` says and exits, and imports nbgrader's steps without its server extensions
(autograder.nbgrader_cli.import_without_server_extensions). Gradings through it: test_autograder_pipeline."""

from __future__ import annotations

import os
import subprocess
import sys

from autograder import config
from course_lib import contract

REPO = contract.ROOT
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}


def _run(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, check=True).stdout


def test_a_missing_submission_gets_nbgraders_words_and_exit_code(tmp_path):
    """No notebook handed in: the same error line on stderr and exit code 1, as the CLI's."""
    config.write_config(tmp_path)
    cli = subprocess.run([sys.executable, "-m", "nbgrader", "autograde", "ps1", "--student", "bob", "--force",
                          f"--CourseDirectory.root={tmp_path}"], cwd=tmp_path, env=ENV, capture_output=True, text=True)
    ours = subprocess.run([sys.executable, "-m", "autograder.grading.sandboxed_autograde", str(tmp_path), "ps1", "bob"],
                          cwd=tmp_path, env=ENV, capture_output=True, text=True)
    assert cli.returncode == ours.returncode == 1
    assert f"[AutogradeApp | ERROR] No notebooks were matched by '{tmp_path}/submitted/bob/ps1'" in ours.stderr
    assert ours.stderr.strip().splitlines() == cli.stderr.strip().splitlines()


def test_nbgraders_steps_import_without_its_server_extensions():
    """The converters, the gradebook and the plugins import; jupyter_server and the apps do not."""
    out = _run("import sys\nfrom autograder import nbgrader_cli\nnbgrader_cli.import_without_server_extensions()\n"
               "from nbgrader.converters import Autograde, GenerateFeedback\nfrom nbgrader import api, plugins\n"
               "import nbgrader\nfrom nbgrader._version import __version__\n"
               "print(nbgrader.__version__ == __version__, 'jupyter_server' in sys.modules,"
               " 'nbgrader.apps' in sys.modules, 'nbgrader.server_extensions' in sys.modules)")
    assert out.split() == ["True", "False", "False", "False"]


def test_an_nbgrader_already_imported_is_kept():
    """A process that imported nbgrader itself (a Jupyter server with its extensions) keeps it whole."""
    out = _run("import nbgrader\nfrom autograder import nbgrader_cli\nnbgrader_cli.import_without_server_extensions()\n"
               "import sys\nprint(sys.modules['nbgrader'] is nbgrader,"
               " hasattr(nbgrader, '_jupyter_server_extension_points'))")
    assert out.split() == ["True", "True"]
