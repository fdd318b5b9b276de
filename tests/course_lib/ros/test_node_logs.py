"""Tests for course_lib.ros.node_logs: in a kernel, a node's log lines stay under the cell that added it."""

import nbformat
from builtin_interfaces.msg import Time
from rcl_interfaces.msg import Log

from course_lib.ros import node_logs

CELLS = [
    """from rclpy.node import Node
from course_lib import node_logs, session
session.start()

class Hello(Node):
    def __init__(self):
        super().__init__("hello")
        self.count = 0
        self.until = 4  # lines to log: "hi 0" to "hi 3" (a later cell asks for more)
        self.create_timer(0.05, self.tick)
        self.get_logger().info("created")

    def tick(self):
        if self.count < self.until:
            self.get_logger().info(f"hi {self.count}")
            self.count += 1

def shown(end):
    \"\"\"Wait until the newest hello node's view holds a line ending with `end`.\"\"\"
    return session.wait_for(lambda: any(line.endswith(end) for line in node_logs.text("hello").splitlines()),
                            timeout=60)

hello = session.add_node(Hello())""",
    # The node logs while this cell runs: four more lines, each logged after the cell began.
    "hello.until += 4\nassert shown(f'[hello]: hi {hello.until - 1}')\nprint('the next cell')",
    "print(node_logs.text('hello').splitlines()[0])",
    # The first cell, re-run; the kernel shuts down once the new node's first line is shown (in a
    # live notebook they appear in the widget whenever they come).
    "hello = session.add_node(Hello())\nassert shown('[hello]: created')",
]


def test_log_lines_stay_with_the_cell_that_added_the_node(domain_id, monkeypatch):
    """The lines go to an output widget of the first cell, not as stderr into the cells after it,
    and are said once what they are; node_logs.text() gives them back."""
    from nbclient import NotebookClient  # nbclient is imported when this test runs, not at collection

    monkeypatch.setenv("ROS_DOMAIN_ID", str(domain_id))
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(source) for source in CELLS])
    NotebookClient(notebook, timeout=120, kernel_name="python3").execute()
    outputs = [cell.outputs for cell in notebook.cells]
    assert not any(output.get("name") == "stderr" for cell in outputs for output in cell), outputs
    assert outputs[1] == [nbformat.v4.new_output("stream", name="stdout", text="the next cell\n")]
    assert outputs[2][0].text.startswith("[INFO] [") and "[hello]: created" in outputs[2][0].text
    widgets = notebook.metadata["widgets"]["application/vnd.jupyter.widget-state+json"]["state"]
    shown = [model["state"]["outputs"] for model in widgets.values() if model["model_name"] == "OutputModel"]
    assert len(shown) == 2 and shown[0][0]["text"].startswith(node_logs.EXPLANATION)
    assert "[hello]: hi 3" in shown[0][0]["text"]
    first = [output for output in outputs[0] if output.output_type == "display_data"]
    again = [output for output in outputs[3] if output.output_type == "display_data"]
    assert len(first) == len(again) == 1  # each widget sits in the cell that added its node
    texts = {model_id: model["state"]["outputs"][0]["text"] for model_id, model in widgets.items()
             if model["model_name"] == "OutputModel"}
    for displayed in (first[0], again[0]):
        text = texts[displayed.data["application/vnd.jupyter.widget-view+json"]["model_id"]]
        assert text.count("[hello]: created") == 1, texts  # the re-run's __init__ line is its own


def test_outside_a_kernel_the_console_keeps_the_lines():
    assert not node_logs.in_kernel() and node_logs.init_arguments() == []


def test_outside_a_kernel_asking_imports_no_ipython():
    """A process that is no kernel (a `ros2` call, a node) learns it without importing IPython."""
    import subprocess
    import sys

    code = "import sys; from course_lib import node_logs; print(node_logs.in_kernel(), 'IPython' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.stdout.split() == ["False", "False"], done.stderr


def test_a_record_reads_like_the_console_line():
    record = Log(stamp=Time(sec=12, nanosec=5), level=30, name="robot1.talker", msg="careful")
    assert node_logs.format_record(record) == "[WARN] [12.000000005] [robot1.talker]: careful"
