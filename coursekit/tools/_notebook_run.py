"""Execute one submitted notebook for the grader, in a process of its own.

``python -m coursekit.tools._notebook_run NOTEBOOK KERNELS_DIR TIMEOUT MEMORY_BYTES``
runs every cell of NOTEBOOK top to bottom in a fresh kernel (nbclient) whose
working folder is the notebook's folder, started from a kernel spec written to
KERNELS_DIR that applies the memory limit (`coursekit.tools._limited_kernel`). A
cell that raises does not stop the run (the later exercises still count).
TIMEOUT (seconds) bounds the whole notebook, not each cell.

The last line printed on stdout is the outcome as JSON, ``{"status": ...,
"detail": ...}``, with status ``ok``, ``cell error``, ``memory`` (a cell ran
out of memory), ``timeout`` or ``crashed`` (the kernel died or did not
start). The kernel's own output goes nowhere, so it cannot print an outcome.
The answers themselves reach the grader through the file the environment
variable ``COURSEKIT_ANSWERS_FILE`` names (see `coursekit.exercises._answers`).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from pathlib import Path

from ._limited_kernel import kernel_argv, set_limits

__all__ = ["KERNEL_NAME", "RUNNER_MEMORY", "write_kernel_spec", "execute", "main"]

#: name of the kernel spec the grader writes for its kernels
KERNEL_NAME = "coursekit-grade"

#: address space this runner may use beyond its kernel's limit (a notebook that prints without
#: end fills the runner's copy of the outputs: the runner then fails, not the machine)
RUNNER_MEMORY = 2 * 2**30


def write_kernel_spec(kernels_dir: Path, memory_bytes: int, cpu_seconds: int) -> Path:
    """Write the grader's kernel spec into `kernels_dir`; returns its folder."""
    folder = Path(kernels_dir) / KERNEL_NAME
    folder.mkdir(parents=True, exist_ok=True)
    spec = {"argv": kernel_argv(memory_bytes, cpu_seconds), "display_name": "coursekit grader",
            "language": "python", "metadata": {"debugger": False}}
    (folder / "kernel.json").write_text(json.dumps(spec), encoding="utf-8")
    return folder


def _cell_errors(nb) -> list[tuple[int, str]]:
    """(index, exception name) of the cells whose outputs show an error."""
    return [(index, output.get("ename", "Error")) for index, cell in enumerate(nb.cells)
            if cell.cell_type == "code" for output in cell.get("outputs", [])
            if output.get("output_type") == "error"]


def _outcome_of_errors(nb) -> dict:
    errors = _cell_errors(nb)
    cells = [str(i) for i, name in errors if name == "MemoryError"]
    if cells:
        which = f"cell {cells[0]}" if len(cells) == 1 else f"cells {', '.join(cells)}"
        return {"status": "memory", "detail": f"{which} ran out of memory (MemoryError)"}
    if errors:
        listed = ", ".join(f"cell {i} ({name})" for i, name in errors)
        return {"status": "cell error", "detail": f"cells raised an exception: {listed}"}
    return {"status": "ok", "detail": "the notebook ran to the end"}


def _run_cells(client, nb, deadline: float) -> None:
    """Execute the cells in order, each with the time left of the notebook's budget."""
    for index, cell in enumerate(nb.cells):
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        client.timeout = max(1, math.ceil(left))
        client.execute_cell(cell, index)


def execute(notebook: Path, kernels_dir: Path, timeout: float, memory_bytes: int) -> dict:
    """Run `notebook` (read with nbformat) and return its outcome (see the module docstring)."""
    import nbformat
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import AsyncKernelManager
    from nbclient import NotebookClient
    from nbclient.exceptions import CellTimeoutError, DeadKernelError

    nb = nbformat.read(notebook, as_version=4)
    write_kernel_spec(kernels_dir, memory_bytes, cpu_seconds=math.ceil(timeout) + 30)
    km = AsyncKernelManager(kernel_name=KERNEL_NAME,
                            kernel_spec_manager=KernelSpecManager(kernel_dirs=[str(kernels_dir)]))
    client = NotebookClient(nb, km=km, allow_errors=True, startup_timeout=120,
                            resources={"metadata": {"path": str(notebook.parent)}})
    deadline = time.monotonic() + timeout
    try:
        with client.setup_kernel(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL):
            _run_cells(client, nb, deadline)
    except (CellTimeoutError, TimeoutError):
        return {"status": "timeout", "detail": f"stopped at the time limit of {timeout:g} s"}
    except DeadKernelError:
        return {"status": "crashed", "detail": "the kernel died while a cell ran (os._exit, a crash "
                                               "in compiled code, or the memory limit)"}
    except RuntimeError as error:
        return {"status": "crashed", "detail": f"the kernel did not start: {error}"}
    return _outcome_of_errors(nb)


def main(argv: list[str]) -> int:
    """Command-line entry: print the outcome of running the notebook as the last line."""
    notebook, kernels_dir, timeout, memory_bytes = Path(argv[0]), Path(argv[1]), float(argv[2]), int(argv[3])
    set_limits(memory_bytes + RUNNER_MEMORY)
    outcome = execute(notebook, kernels_dir, timeout, memory_bytes)
    sys.stdout.write("\n" + json.dumps(outcome) + "\n")
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
