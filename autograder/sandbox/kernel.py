"""The kernel of a notebook under grading: ``python -m autograder.sandbox.kernel CONNECTION_FILE``.

The grader installs a kernelspec whose argv runs this module instead of ipykernel directly.
When the grader runs as root it sets AUTOGRADER_KERNEL_UID, and this launcher (still root):

- copies the connection file (jupyter_client writes it 0600 for root) to a private directory,
- copies the notebook's folder (the autograded copy) into a subfolder, WORK_SUBDIR, that it
  gives to that uid, and makes it the kernel's working directory. The folder itself stays
  root's: nbgrader (root) writes the graded notebook there after the run, and a student who
  could write in that folder could replace the notebook by a symlink that root then writes
  through. Modules the notebook writes (%%writefile) land in WORK_SUBDIR, where the grader's
  checks find them,
- drops to the uid with no supplementary groups and sets RLIMIT_NPROC (the kernel enforces it for
  non-root users only: a fork bomb stops there) with autograder.sandbox.run_as.become, and execs ipykernel
  (KERNEL_CODE: without its debugger).

So the student's code never runs as root: it cannot read the gradebook (0600, root) or other
students' files, and its process count is bounded per worker (each worker has its own uid).
Without AUTOGRADER_KERNEL_UID (not root), it execs that kernel unchanged.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile

from autograder.sandbox import run_as
from course_lib import contract

#: The kernel's working directory, inside the notebook's folder (see the module docstring).
WORK_SUBDIR = ".autograder-cwd"

#: ``python -m ipykernel_launcher`` without the debugger: nobody attaches one to a graded kernel,
#: and importing debugpy costs each grading about 0.15 s of processor time (ipykernel offers no
#: debugger when debugpy does not import). sys.argv[0] and sys.path[0] are what ``-m`` gives (the
#: launcher's path, the working directory): code that tells a kernel by them sees one. The kernel
#: runs as the student's uid, which cannot read the grader's copy of this package: hence code.
KERNEL_CODE = ("import os, sys\n"
               "from importlib.util import find_spec\n"
               "sys.argv[0] = find_spec('ipykernel_launcher').origin\n"
               "sys.path[0] = os.getcwd()\n"
               "sys.modules['debugpy'] = None\n"
               "from ipykernel import kernelapp\n"
               "kernelapp.launch_new_instance()\n")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    connection = argv[0]
    uid = os.environ.get(contract.KERNEL_UID_ENV)
    if uid and os.geteuid() == 0:
        uid = int(uid)
        private = tempfile.mkdtemp(prefix="autograder-kernel-", dir=os.environ.get(contract.KERNEL_TMP_ENV))
        copy = os.path.join(private, "connection.json")
        shutil.copyfile(connection, copy)
        for name in ("home", "tmp"):
            os.mkdir(os.path.join(private, name))
        run_as.give_tree(private, uid)
        os.chmod(private, 0o700)
        work = os.path.join(os.getcwd(), WORK_SUBDIR)
        if os.path.islink(work) or os.path.isfile(work):  # handed in under that name: not ours
            os.unlink(work)
        elif os.path.isdir(work):
            shutil.rmtree(work)
        shutil.copytree(os.getcwd(), work, symlinks=True, ignore=shutil.ignore_patterns(WORK_SUBDIR))
        run_as.give_tree(work, uid)
        os.chmod(work, 0o700)
        os.chmod(os.getcwd(), 0o711)
        os.chdir(work)
        os.environ.update(HOME=os.path.join(private, "home"), TMPDIR=os.path.join(private, "tmp"),
                          IPYTHONDIR=os.path.join(private, "home", ".ipython"),
                          MPLCONFIGDIR=os.path.join(private, "home", ".matplotlib"))
        os.environ.pop("ROS_LOG_DIR", None)
        run_as.become(uid, uid, int(os.environ.get(contract.KERNEL_NPROC_ENV, str(contract.MAX_PROCESSES))))
        connection = copy
    os.execv(sys.executable, [sys.executable, "-c", KERNEL_CODE, "-f", connection])
    return 1  # not reached


if __name__ == "__main__":
    sys.exit(main())
