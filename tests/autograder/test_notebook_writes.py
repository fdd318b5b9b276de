"""autograder.builds.notebook_writes: the files a notebook writes, predicted without running it, and the
digest that tells whether a run wrote exactly those."""

from __future__ import annotations

import os

import nbformat
import pytest

from autograder.builds.notebook_writes import folder_digest, predicted_writes

CELLS = [
    "!mkdir -p ws/src/pkg/pkg ws/src/pkg/resource\n!touch ws/src/pkg/pkg/__init__.py ws/src/pkg/resource/pkg",
    "%%writefile ws/src/pkg/setup.py\nfrom setuptools import setup\nsetup(name='pkg')",  # no newline at the end
    "%%writefile ws/src/pkg/pkg/node.py\nprint('first')\n",
    "%%writefile -a ws/src/pkg/pkg/node.py\nprint('appended')\n",
    "%%writefile ws/src/pkg/resource/pkg\nmarker\n",  # touched first, then written
    "if False:\n    !touch ws/never.txt",            # indented: may not run, not predicted
    "!touch $HOME/elsewhere.txt ws/with_variable.txt",  # a shell variable: not predicted
    "!touch /tmp/absolute.txt",                       # outside the notebook's folder
    "!touch ../outside.txt",
    "%%writefile ../outside.py\nx = 1\n",
    "%%bash\ntouch ws/by_bash.txt",                   # another cell magic
    "open('ws/by_python.txt', 'w').write('x')",      # Python: not predicted (the digest tells)
]


def notebook(tmp_path, cells=CELLS):
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(source) for source in cells])
    path = tmp_path / "assignment.ipynb"
    nbformat.write(nb, path)
    return path


def test_writefile_mkdir_and_touch_are_predicted_as_ipython_runs_them(tmp_path):
    writes = predicted_writes(notebook(tmp_path))
    assert writes.files == {
        "ws/src/pkg/pkg/__init__.py": None,
        "ws/src/pkg/resource/pkg": b"marker\n",
        "ws/src/pkg/setup.py": b"from setuptools import setup\nsetup(name='pkg')\n",
        "ws/src/pkg/pkg/node.py": b"print('first')\nprint('appended')\n",
    }
    assert writes.folders == {"ws/src/pkg/pkg", "ws/src/pkg/resource"}


def test_the_prediction_equals_a_real_run_of_the_predicted_cells(tmp_path):
    """The notebook's predictable cells run by a real IPython kernel leave the predicted files."""
    pytest.importorskip("nbclient")
    from nbclient import NotebookClient

    cells = CELLS[:5]
    predicted_dir, run_dir = tmp_path / "predicted", tmp_path / "run"
    predicted_dir.mkdir()
    run_dir.mkdir()
    predicted_writes(notebook(tmp_path, cells)).apply(predicted_dir)
    nb = nbformat.read(notebook(run_dir, cells), as_version=4)
    NotebookClient(nb, timeout=60, kernel_name="python3", resources={"metadata": {"path": str(run_dir)}}).execute()
    assert folder_digest(predicted_dir) == folder_digest(run_dir)


def test_touch_keeps_a_submitted_file(tmp_path):
    (tmp_path / "ws").mkdir()
    (tmp_path / "ws" / "kept.txt").write_text("handed in")
    path = tmp_path / "nb.ipynb"
    nbformat.write(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("!touch ws/kept.txt")]), path)
    predicted_writes(path).apply(tmp_path)
    assert (tmp_path / "ws" / "kept.txt").read_text() == "handed in"


def test_a_broken_notebook_predicts_nothing(tmp_path):
    path = tmp_path / "broken.ipynb"
    path.write_text("{not json")
    assert predicted_writes(path).files == {}


def test_digest_ignores_build_outputs_byte_code_and_notebooks_and_sees_every_other_change(tmp_path):
    (tmp_path / "ros2_ws" / "src" / "pkg").mkdir(parents=True)
    module = tmp_path / "ros2_ws" / "src" / "pkg" / "node.py"
    module.write_text("x = 1\n")
    before = folder_digest(tmp_path)
    for ignored in ("ros2_ws/build/pkg/out.txt", "ros2_ws/install/setup.bash", "ros2_ws/log/latest",
                    "ros2_ws/src/pkg/__pycache__/node.pyc", "assignment.ipynb", ".ipynb_checkpoints/a.ipynb"):
        (tmp_path / ignored).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / ignored).write_text("anything")
    assert folder_digest(tmp_path) == before
    module.write_text("x = 2\n")
    assert folder_digest(tmp_path) != before
    module.write_text("x = 1\n")
    (tmp_path / "data.txt").write_text("a file beside the notebook")
    assert folder_digest(tmp_path) != before
    (tmp_path / "data.txt").unlink()
    os.symlink("node.py", tmp_path / "ros2_ws" / "src" / "pkg" / "link.py")
    assert folder_digest(tmp_path) != before
