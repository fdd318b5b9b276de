"""Zoo submissions of the brightness assignment: what each does, and what grading must give it.

Each entry: edits of the reference solution (see tests/support/zoo/__init__.py), the expected scores
per check (None: not asserted) and a phrase the graded notebook must show as the reason.
"""

from __future__ import annotations

import nbformat

SUM = "return int(image.sum(dtype=np.uint64) // image.size)"
CALLBACK = "        self.publisher.publish(UInt8(data=average_brightness(frame)))"
IMPORTS = "from course_lib import images\n"


def _hostile_cell(course_dir: str):
    """A cell that tries what a submission must not be able to do, and prints what happened."""
    code = f'''
import os, pathlib, socket, subprocess, sys
try:
    socket.create_connection(("1.1.1.1", 53), timeout=3)
    print("NETWORK: open")
except OSError as error:
    print("NETWORK: blocked", error)
course = pathlib.Path({course_dir!r})
try:
    print("COURSE:", "visible" if (course / "submitted").exists() else "hidden")
except OSError as error:
    print("COURSE: hidden", type(error).__name__)
try:
    for parent in pathlib.Path.cwd().parents:
        if (parent / "gradebook.db").exists():
            (parent / "gradebook.db").read_bytes()
            print("GRADEBOOK: readable")
            break
    else:
        print("GRADEBOOK: not found")
except OSError as error:
    print("GRADEBOOK: denied", type(error).__name__)
try:  # root writes the graded notebook into this folder afterwards: it must not follow a planted link
    os.symlink("/etc/hostname", pathlib.Path.cwd().parent / "brightness-link.ipynb")
    print("SYMLINK: planted")
except OSError as error:
    print("SYMLINK: denied", type(error).__name__)
# Left running on purpose: sleeps, and floods /brightness with zeros in nearby ROS domains.
flood = """
import os, time, rclpy
from std_msgs.msg import UInt8
from rclpy.context import Context
from rclpy.qos import qos_profile_sensor_data
own = int(os.environ.get("ROS_DOMAIN_ID", "0"))
pubs = []
for domain in sorted({{max(0, min(101, own + d)) for d in range(-3, 4)}} | {{0}}):
    ctx = Context(); rclpy.init(context=ctx, domain_id=domain)
    node = rclpy.create_node("intruder", context=ctx)
    pubs.append(node.create_publisher(UInt8, "/brightness", qos_profile_sensor_data))
while True:
    for pub in pubs:
        pub.publish(UInt8(data=0))
    time.sleep(0.01)
"""
subprocess.Popen([sys.executable, "-c", flood], start_new_session=True,
                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
subprocess.Popen(["sleep", "1234"], start_new_session=True)
print("BACKGROUND: started")
'''
    return code


def hostile(course_dir: str):
    def edit(nb):
        index = next(i for i, c in enumerate(nb.cells) if "importlib.reload(" in c.source)
        nb.cells.insert(index + 1, nbformat.v4.new_code_cell(_hostile_cell(course_dir)))
        for cell in nb.cells:
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id")
            if grade_id == "check_values":
                cell.source = "4.0  # trust me"          # edited test cell: nbgrader restores it
        nb.cells[:] = [c for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id") != "check_node"]
    return edit


CHEAT = """
# Fakes the hidden tests from inside the kernel: every check "earns" its full points.
import course_lib.checks.registry as registry_module
import course_lib.checks.runner as runner_module
def full_points(assignment, name, *args, **kwargs):
    return registry_module.get_check(assignment, name).points
runner_module.grade = full_points
runner_module.run_check = full_points
checks.grade = lambda name: full_points("brightness", name)
print("CHEAT: installed")
"""


#: Returns the grader's own answer when the answer key can be imported, else 0.
STEAL_ANSWER = """try:
        from autograder.answers.brightness import average_brightness as stolen
        return stolen(image)
    except ImportError:
        return 0"""


def cheater(nb):
    """Wrong answers, and a cell that patches the grading functions the hidden tests call."""
    index = next(i for i, c in enumerate(nb.cells) if "importlib.reload(" in c.source)
    nb.cells.insert(index + 1, nbformat.v4.new_code_cell(CHEAT))


#: The throughput item's verdict: the grading got that far.
THROUGHPUT_VERDICT = "your node used"


def entries(course_dir: str) -> dict[str, dict]:
    """student id -> {"edits", "values", "node", "reason"}: expected points per check (a number, a
    (low, high) range when fresh seeds decide how many items fail, or None: not asserted) and a
    phrase the autograded notebook's outputs must contain, or a tuple of phrases one of which it
    must contain (optional: `first_failure`, a phrase of the
    first ✘ line of a check's verdict, and `absent`, phrases it must not contain). Entries with
    level="check" are typical mistakes in the module only: tests/assignments/test_autograder.py runs the
    checks on them directly (no nbgrader run), which is much cheaper; the rest go through the parallel
    nbgrader zoo run."""
    return {
        # The reference solution with a hostile cell (tests/assignments/test_autograder_zoo.py): every point. It
        # is the brightness reference's run through the whole pipeline in the suite.
        "hostile": dict(edits=[hostile(course_dir)], values=4, node=7, reason="NETWORK: blocked"),
        "float_mean": dict(level="check", edits=[(SUM, "return image.mean()")], values=0, node=None,
                           reason="the contract asks for an int"),
        "rounding": dict(level="check", edits=[(SUM, "return int(round(image.mean()))")], values=(0, 3.2), node=None,
                         reason="rounded to nearest"),
        "reliable_qos": dict(level="check",
                             edits=[('self.create_subscription(Image, "/image", self.on_image, '
                                     'qos_profile_sensor_data)',
                                     'self.create_subscription(Image, "/image", self.on_image, 10)')],
                             values=None, node=1.0, reason="incompatible QoS",
                             # The cause comes first; what follows from it says so and guesses nothing.
                             first_failure="the subscription on /image is reliable",
                             absent=("Python loop", "namespaces")),
        # numpy's uint64 is no Python int: check 1 says so, and the node's crash in publish() is named.
        "numpy_int": dict(level="check", edits=[(SUM, "return image.sum() // image.size")], values=0, node=2.0,
                          reason="put a Python int in it", first_failure="the node process ended"),
        "wrong_topic": dict(level="check", edits=[('UInt8, "/brightness"', 'UInt8, "/image_brightness"')], values=None,
                            node=(0, 6.2),
                            reason="does not publish /brightness"),
        "python_loop": dict(level="check", edits=[(SUM, "total = 0\n    for value in image.reshape(-1):\n"
                                                        "        total += int(value)\n"
                                                        "    return total // image.size")], values=None, node=5.0,
                            reason="too slow"),
        # Points come from the grader's own run of the checks, not from what the kernel reports;
        # and the grader's answer key is out of the student's reach (else values would be 4).
        "cheater": dict(edits=[(SUM, STEAL_ANSWER), cheater], values=0, node=None, reason="returned 0, expected"),
        # The classic slip of a module that spins at import instead of in main(): the import never
        # returns (it waits, as a spin does, rather than burning a core for the whole time limit).
        "import_loop": dict(edits=[(IMPORTS,
                                    IMPORTS + "rclpy.init()\nrclpy.spin(rclpy.create_node('spun_at_import'))\n")],
                            values=0, node=0, reason="did not finish within"),
        # A callback that computes with Python's sum() over msg.data: right answers, 6-9 times the
        # processor time per frame of the grader's yardstick (the throughput item allows 3).
        "slow_callback": dict(level="check",
                              edits=[(CALLBACK,
                                      "        self.publisher.publish(UInt8(data=sum(msg.data) // len(msg.data)))")],
                              values=None, node=5.0, reason="too slow"),
        # A callback that never returns: the endpoints' points only; what needs answers is named
        # as following from the unanswered frames (run through the checks: no kernel involved).
        "callback_loop": dict(level="check", edits=[(CALLBACK, "        while True:\n            pass")], values=None,
                              node=2.0, reason="no value on /brightness"),
        # Crashes in the student's function also crash the kernel when the notebook's own demo
        # cell calls it: nbgrader cannot finish the notebook, the grade is 0 with the reason. (An
        # os._exit() in the kernel takes the same way: nbgrader reports a dead kernel alike.)
        "segfault": dict(edits=[(SUM, "import ctypes; ctypes.string_at(0)")], values=0, node=0,
                         reason="kernel died", failed=True),
        # The same crash only in the grader's processes (not in the kernel): the checks say how.
        "segfault_in_node": dict(level="check", edits=[(CALLBACK, "        import ctypes; ctypes.string_at(0)")],
                                 values=None, node=(0, 5), reason="SIGSEGV"),
        "memory_hog": dict(edits=[(SUM, "hog = np.ones(10**10, np.uint8); return int(hog[0])")], values=0, node=None,
                           reason="MemoryError"),
        # Gated to the grader's student processes (not the notebook kernel), to keep the zoo short.
        "fork_bomb": dict(edits=[(SUM, "import os, sys\n    while 'ipykernel' not in sys.argv[0]:\n"
                                       "        os.fork()\n    " + SUM)], values=0, node=None,
                          # fork() refused at the process limit, or the function's server killed
                          # there (whichever comes first: the call then ended with its server)
                          reason=("average_brightness failed", "the call average_brightness on",
                                  "the most processes and threads it may have")),
        # 256 MB of output from each of the grader's student processes, 800 times what the grader
        # keeps of a log (course_lib.supervision.bounded_log): neither memory nor disk fills, the answers count.
        "prints_flood": dict(edits=[(SUM, "import sys\n"
                                          "    if 'ipykernel' not in sys.argv[0] "
                                          "and not getattr(average_brightness, 'printed', False):\n"
                                          "        average_brightness.printed = True\n"
                                          "        for _ in range(256):\n"
                                          "            sys.stdout.write('x' * 2**20)\n    " + SUM)],
                             values=4, node=None, reason=THROUGHPUT_VERDICT),
    }
