"""Does the kernel of a graded notebook (autograder.sandbox.kernel) run code, without the debugger?"""

import json
import sys

from autograder.nbgrader_cli import env_for_tools
from autograder.sandbox import kernel


def test_the_graded_kernel_runs_code_and_offers_no_debugger(tmp_path, monkeypatch):
    """The kernelspec the grader writes starts a kernel that runs a cell and prints; it never
    imports debugpy (KERNEL_CODE), so it offers no debugger; sys.argv[0] and sys.path[0] are those
    of ``python -m ipykernel_launcher`` (student code may tell a kernel by them)."""
    from jupyter_client import KernelManager

    spec = tmp_path / "jupyter" / "kernels" / "graded"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "autograder.sandbox.kernel", "{connection_file}"], "language": "python",
        "display_name": "graded"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.delenv("AUTOGRADER_KERNEL_UID", raising=False)  # the launcher's part as root: test_autograder_pipeline
    manager = KernelManager(kernel_name="graded")
    manager.start_kernel(cwd=str(tmp_path), env={**env_for_tools(), "JUPYTER_PATH": str(tmp_path / "jupyter")})
    client = manager.client()
    try:
        client.start_channels()
        client.wait_for_ready(timeout=60)
        info = client.kernel_info(reply=True, timeout=30)["content"]
        outputs = []
        client.execute_interactive("import os, sys; "
                                   "print(6 * 7, any(m.startswith(('debugpy.', '_pydevd')) for m in sys.modules), "
                                   "os.path.basename(sys.argv[0]), sys.path[0] == os.getcwd())", timeout=30,
                                   output_hook=lambda msg: outputs.append(msg["content"].get("text", "")))
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)
    assert "".join(outputs).split() == ["42", "False", "ipykernel_launcher.py", "True"]
    assert "debugger" not in info.get("supported_features", []) and not info.get("debugger")
    assert "debugpy" in kernel.KERNEL_CODE
