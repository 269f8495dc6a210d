"""Start an IPython kernel with memory, CPU-time and file-size limits (for the grader's kernels).

``python -m coursekit.tools.grading.kernel MEMORY_BYTES CPU_SECONDS -f CONNECTION_FILE ...``
sets the kernel process's limits with `resource.setrlimit` (soft and hard, so
the notebook cannot raise them again) and then replaces itself with the usual
``python -m ipykernel_launcher ...``, which keeps them:

* ``RLIMIT_AS`` (address space): an allocation beyond it fails with
  ``MemoryError`` in the cell (or ends the kernel when it happens in C code)
  instead of taking the machine's memory from the other notebooks;
* ``RLIMIT_CPU``: a kernel left running (its grader gone, a loop that ignores
  interrupts) is ended by the system after that much CPU time;
* ``RLIMIT_FSIZE`` (`FILE_BYTES`): no file the kernel writes, its answers file
  included, grows beyond that size; a write past it fails with ``OSError``
  (``SIGXFSZ`` is ignored, so the kernel is not killed for it).

`kernel_argv` is the command a kernel spec gives for it. Where the `resource`
module does not exist (Windows), or the system refuses a limit, the kernel starts
without it.
"""

from __future__ import annotations

import os
import signal
import sys

__all__ = ["FILE_BYTES", "kernel_argv", "set_limits", "main"]

#: the largest file a grader's kernel may write (its answers file included)
FILE_BYTES = 256 * 2**20


def kernel_argv(memory_bytes: int, cpu_seconds: int) -> list[str]:
    """The ``argv`` of a kernel spec whose kernels start with these limits."""
    return [sys.executable, "-m", "coursekit.tools.grading.kernel", str(int(memory_bytes)), str(int(cpu_seconds)),
            "-f", "{connection_file}", "--HistoryManager.hist_file=:memory:"]


def set_limits(memory_bytes: int, cpu_seconds: int | None = None, file_bytes: int | None = None) -> None:
    """Limit this process's address space, CPU time and file size (soft = hard; None: no limit).

    A limit the system does not support (no `resource` module on Windows, an
    address-space limit macOS refuses) is left unset rather than stopping the kernel.
    """
    try:
        import resource
    except ImportError:
        return
    limits = [(resource.RLIMIT_AS, memory_bytes)]
    if cpu_seconds is not None:
        limits.append((resource.RLIMIT_CPU, cpu_seconds))
    if file_bytes is not None:
        limits.append((resource.RLIMIT_FSIZE, file_bytes))
    for kind, value in limits:
        try:
            resource.setrlimit(kind, (value, value))
        except (ValueError, OSError):
            pass


def main(argv: list[str]) -> None:
    """Set the limits given first in `argv`, then run ipykernel with the rest of `argv`."""
    memory_bytes, cpu_seconds, rest = int(argv[0]), int(argv[1]), argv[2:]
    set_limits(memory_bytes, cpu_seconds, FILE_BYTES)
    if hasattr(signal, "SIGXFSZ"):
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)       # kept across exec: a write too large fails
    os.execv(sys.executable, [sys.executable, "-m", "ipykernel_launcher", *rest])


if __name__ == "__main__":
    main(sys.argv[1:])
