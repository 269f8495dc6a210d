"""Execute one submitted notebook for the grader, in a process of its own.

``python -m coursekit.tools.grading.runner JOB`` reads the job (JSON written by
the grader: ``notebook``, ``cwd`` (the kernel's working folder, when it is
not sandboxed), ``kernel_argv``, ``timeout``, ``memory``, ``connection_file``) and runs every cell of the notebook top to bottom in a
fresh kernel (nbclient) started with ``kernel_argv`` (the grader's limited
kernel, `coursekit.tools.grading.kernel`, inside its sandbox,
`coursekit.tools.grading.sandbox`). When ``connection_file`` is set, the kernel talks
to this runner through Unix sockets next to that file (the sandboxed kernel
has no network). The saved outputs are cleared first: only this run counts.
A cell that raises does not stop the run (the later exercises still count).
The time limit bounds the whole notebook, not each cell. A kernel that fails
to start is started once more before the notebook counts as crashed.

This runner stays outside the sandbox: a sandboxed kernel can neither see nor
signal it, nor write to its output. The last line it prints on stdout is the outcome
as JSON, ``{"status": ..., "detail": ..., "errors": [...]}``, with status ``ok``,
``cell error``, ``memory`` (a cell ran out of memory), ``timeout`` or
``crashed`` (the kernel died or did not start); ``errors`` lists the cells
that raised, numbered from 1 as they stand in the notebook. The answers
themselves reach the grader through the file the environment variable
``COURSEKIT_ANSWERS_FILE`` names inside the kernel (`coursekit.exercises._answers`).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from ..notebooks import leave_out_the_iri_grammar, read_notebook
from .kernel import set_limits

__all__ = ["KERNEL_NAME", "RUNNER_MEMORY", "STARTS", "RUNNER_STATUSES", "write_kernel_spec", "execute", "main"]

#: name of the kernel spec the grader writes for its kernels
KERNEL_NAME = "coursekit-grade"

#: address space this runner may use beyond its kernel's limit (a notebook that prints without
#: end fills the runner's copy of the outputs: the runner then fails, not the machine)
RUNNER_MEMORY = 2 * 2**30

#: how many times a kernel is started before the notebook counts as crashed
STARTS = 2

#: the statuses this runner reports (the grader accepts no other)
RUNNER_STATUSES = ("ok", "cell error", "memory", "timeout", "crashed")


def write_kernel_spec(kernels_dir: Path, argv: list[str]) -> Path:
    """Write the grader's kernel spec, which starts kernels with `argv`, into `kernels_dir`."""
    folder = Path(kernels_dir) / KERNEL_NAME
    folder.mkdir(parents=True, exist_ok=True)
    spec = {"argv": list(argv), "display_name": "coursekit grader", "language": "python",
            "metadata": {"debugger": False}}
    (folder / "kernel.json").write_text(json.dumps(spec), encoding="utf-8")
    return folder


def _text(value, limit: int = 200) -> str:
    """A kernel-supplied string, cut to `limit` characters on one line."""
    return " ".join(str(value).split())[:limit]


def _cell_errors(nb) -> list[dict]:
    """The cells whose outputs show an error: their number from 1, the exception's name and message."""
    return [{"cell": index + 1, "ename": _text(output.get("ename", "Error"), 80),
             "evalue": _text(output.get("evalue", ""))}
            for index, cell in enumerate(nb.cells) if cell.cell_type == "code"
            for output in cell.get("outputs", []) if output.get("output_type") == "error"]


def _outcome_of_errors(nb) -> dict:
    errors = _cell_errors(nb)
    cells = [str(e["cell"]) for e in errors if e["ename"] == "MemoryError"]
    if cells:
        which = f"cell {cells[0]}" if len(cells) == 1 else f"cells {', '.join(cells)}"
        return {"status": "memory", "detail": f"{which} ran out of memory (MemoryError)", "errors": errors}
    if errors:
        listed = ", ".join(f"cell {e['cell']} ({e['ename']})" for e in errors)
        return {"status": "cell error", "detail": f"cells raised an exception: {listed}", "errors": errors}
    return {"status": "ok", "detail": "the notebook ran to the end", "errors": []}


def _clear_outputs(nb) -> None:
    """Forget the outputs saved with the notebook: a cell this run does not execute shows none."""
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None


def _run_cells(client, nb, deadline: float) -> None:
    """Execute the cells in order, each with the time left of the notebook's budget."""
    for index, cell in enumerate(nb.cells):
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        client.timeout = max(1, math.ceil(left))
        client.execute_cell(cell, index)


def _client(nb, job: dict, kernels_dir: Path):
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import AsyncKernelManager
    from nbclient import NotebookClient
    write_kernel_spec(kernels_dir, job["kernel_argv"])
    options = {}
    if job.get("connection_file"):
        connection = Path(job["connection_file"])
        options = {"transport": "ipc", "ip": str(connection.with_name("ipc")), "connection_file": str(connection)}
    km = AsyncKernelManager(kernel_name=KERNEL_NAME, kernel_spec_manager=KernelSpecManager(
        kernel_dirs=[str(kernels_dir)]), **options)
    return NotebookClient(nb, km=km, allow_errors=True, startup_timeout=120,
                          resources={"metadata": {"path": job["cwd"]}})


def _started(nb, job: dict, kernels_dir: Path, deadline: float):
    """A client whose kernel has started, and the stack that shuts it down; a kernel that fails
    to start is started again (`STARTS` times in all) while time is left."""
    starts = 0
    while True:
        starts += 1
        client, stack = _client(nb, job, kernels_dir), contextlib.ExitStack()
        try:
            stack.enter_context(client.setup_kernel(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            return client, stack
        except RuntimeError:
            stack.close()
            if starts == STARTS or time.monotonic() >= deadline:
                raise


def execute(job: dict, kernels_dir: Path) -> dict:
    """Run the job's notebook and return its outcome (see the module docstring)."""
    from nbclient.exceptions import CellTimeoutError, DeadKernelError

    timeout = float(job["timeout"])
    nb = read_notebook(job["notebook"])
    _clear_outputs(nb)
    deadline = time.monotonic() + timeout
    try:
        client, kernel = _started(nb, job, kernels_dir, deadline)
        with kernel:
            _run_cells(client, nb, deadline)
    except (CellTimeoutError, TimeoutError):
        return {"status": "timeout", "detail": f"stopped at the time limit of {timeout:g} s", "errors": []}
    except DeadKernelError:
        return {"status": "crashed", "detail": "the kernel died while a cell ran (os._exit, a crash "
                                               "in compiled code, or the memory limit)", "errors": []}
    except RuntimeError as error:
        return {"status": "crashed", "detail": f"the kernel did not start: {_text(error)}", "errors": []}
    return _outcome_of_errors(nb)


def _end_with(parent: int) -> None:
    """End this runner (and so its sandboxed kernel, which dies with it) once `parent`, the
    grader, is gone: a grader stopped with Ctrl-C leaves nothing running."""
    while os.getppid() == parent:
        time.sleep(1)
    os._exit(3)


def main(argv: list[str]) -> int:
    """Command-line entry: print the outcome of running the job's notebook as the last line."""
    leave_out_the_iri_grammar()
    threading.Thread(target=_end_with, args=(os.getppid(),), daemon=True).start()
    job_file = Path(argv[0])
    job = json.loads(job_file.read_text(encoding="utf-8"))
    set_limits(int(job["memory"]) + RUNNER_MEMORY)
    outcome = execute(job, job_file.parent / "kernels")
    sys.stdout.write("\n" + json.dumps(outcome) + "\n")
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
