"""A kernel for the tests that execute notebooks: ipykernel started with this very interpreter."""

from __future__ import annotations

import sys

__all__ = ["this_python_kernel"]


def this_python_kernel(*, asynchronous: bool = False):
    """A kernel manager that starts ipykernel with this interpreter (whatever kernels are installed);
    with `asynchronous`, jupyter_client's asynchronous one (for nbclient's ``async_execute``)."""
    from jupyter_client.kernelspec import KernelSpec, KernelSpecManager
    from jupyter_client.manager import AsyncKernelManager, KernelManager

    class ThisPython(KernelSpecManager):
        def get_kernel_spec(self, kernel_name):
            return KernelSpec(argv=[sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                              display_name="this Python", language="python")

    manager = AsyncKernelManager if asynchronous else KernelManager
    return manager(kernel_name="python3", kernel_spec_manager=ThisPython())
