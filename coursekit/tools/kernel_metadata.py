"""The notebooks' kernel metadata, stored as JupyterLab writes it: ``python -m coursekit slides --kernel-metadata``.

When JupyterLab 4 (and Notebook 7, the same notebook widget) connects a notebook to its kernel,
it writes two entries of the notebook's metadata from what the kernel says about itself:

* ``kernelspec``: ``name``, and the ``display_name`` and ``language`` of the installed
  kernel spec (ipykernel's ``python3``: "Python 3 (ipykernel)", "python");
* ``language_info``: the kernel's ``kernel_info_reply`` as it comes, which for ipykernel
  includes the exact Python version (``"version": "3.11.7"``).

The notebook's model treats a value equal to the stored one as no change; any other value
marks the notebook modified (the unsaved dot on its tab, and "Save your work" when it is
closed), although the reader changed nothing. So the notebooks store exactly these two
entries, taken from the course's reference kernel by `kernel_metadata`, which asks the kernel
the way JupyterLab does (its spec, then a ``kernel_info`` request). A reader whose kernel
reports another Python version sees the notebook marked modified on opening: the version is
part of what the kernel reports and nothing in Jupyter leaves it out (jupyter/notebook#2123).

``python -m coursekit slides --kernel-metadata`` stores the metadata of this environment's
kernel in every notebook (`apply_kernel_metadata`); a test checks the stored metadata.
"""

from __future__ import annotations

import copy
from pathlib import Path

from .notebooks import update_notebooks

__all__ = ["COURSE_KERNEL", "KERNEL_KEYS", "kernelspec_metadata", "kernel_language_info",
           "kernel_metadata", "with_kernel_metadata", "apply_kernel_metadata"]

#: the kernel the course's notebooks run on (ipykernel's kernel spec)
COURSE_KERNEL = "python3"

#: the notebook metadata entries JupyterLab writes from the kernel
KERNEL_KEYS = ("kernelspec", "language_info")


def kernelspec_metadata(kernel_name: str = COURSE_KERNEL) -> dict:
    """The ``kernelspec`` entry JupyterLab writes for the installed kernel `kernel_name`."""
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel
    try:
        spec = KernelSpecManager().get_kernel_spec(kernel_name)
    except NoSuchKernel as error:
        raise ValueError(f"kernel_name {kernel_name!r} is not an installed kernel; install ipykernel "
                         "(python -m pip install ipykernel) or name one of `jupyter kernelspec list`.") from error
    return {"display_name": spec.display_name, "language": spec.language, "name": kernel_name}


def kernel_language_info(kernel_name: str = COURSE_KERNEL, *, timeout: float = 60.0) -> dict:
    """The ``language_info`` the kernel `kernel_name` reports: it is started, asked once
    (``kernel_info``, as JupyterLab asks it) and shut down."""
    from jupyter_client.manager import start_new_kernel
    manager, client = start_new_kernel(kernel_name=kernel_name, startup_timeout=timeout)
    try:
        reply = client.kernel_info(reply=True, timeout=timeout)
        return reply["content"]["language_info"]
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


def kernel_metadata(kernel_name: str = COURSE_KERNEL) -> dict:
    """``{"kernelspec": ..., "language_info": ...}`` as JupyterLab writes them into a notebook it
    opens with the kernel `kernel_name` of this environment."""
    return {"kernelspec": kernelspec_metadata(kernel_name),
            "language_info": kernel_language_info(kernel_name)}


def with_kernel_metadata(nb, metadata: dict):
    """`nb` with the entries of `metadata` (from `kernel_metadata`) in its metadata; changed
    in place and returned."""
    if not isinstance(metadata, dict):
        raise TypeError(f"metadata must be a dict: received {type(metadata).__name__}; pass what "
                        "kernel_metadata() returns.")
    missing = [key for key in KERNEL_KEYS if key not in metadata]
    if missing:
        raise ValueError(f"metadata lacks {missing}: pass the dictionary kernel_metadata() returns.")
    for key in KERNEL_KEYS:
        nb.metadata[key] = copy.deepcopy(metadata[key])
    return nb


def apply_kernel_metadata(notebooks: Path | str | None = None, *, write: bool = True,
                          metadata: dict | None = None) -> list[Path]:
    """Store `metadata` (default: `kernel_metadata()` of this environment) in every notebook of
    the folder `notebooks` (default: the repository's ``notebooks/``); return the notebooks
    whose stored entries differ. With ``write=False`` nothing is written."""
    metadata = kernel_metadata() if metadata is None else metadata
    return update_notebooks(notebooks, lambda nb: any(nb.metadata.get(key) != metadata.get(key) for key in KERNEL_KEYS),
                            lambda nb: with_kernel_metadata(nb, metadata), write=write)
