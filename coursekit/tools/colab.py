"""The first code cell of every notebook: install coursekit where it is missing (Colab).

Colab opens a notebook from GitHub without the rest of the repository, so
``import coursekit`` fails there until the package is installed from the
course repository. The cell made by `install_cell_source` does that, and does
nothing where coursekit is installed (your own JupyterLab, Binder, CI).

A notebook knows nothing of the repository it was opened from, so the
repository's address has to be written into the cell: ``python -m coursekit
colab`` writes the address of the git remote ``origin`` (or the one given with
``--repository``) into the cell of every notebook. Until that is done, the cell names no
address (an install line with a stand-in such as OWNER/NAME would be copied as it stands): it
stops on Colab saying that coursekit is missing and where to find how to install it.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

from .cells import ENVIRONMENT, INSTALL, ROLE_KEY, role
from .notebooks import update_notebooks

__all__ = ["INSTALL_MARK", "install_cell_source", "cell_repository", "with_install_cell",
           "apply_install_cell", "repository_from_git"]

#: the cell metadata ``coursekit`` value that marks the install cell
INSTALL_MARK = INSTALL

_DOES_NOTHING = "# Where coursekit is installed (your own JupyterLab, Binder, CI) it does nothing.\n"

_WITH_REPOSITORY = ("# Colab and other hosted notebooks start without coursekit: this cell installs it there.\n"
                    + _DOES_NOTHING) + '''import importlib.util, subprocess, sys
if importlib.util.find_spec("coursekit") is None:
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet",
                    "coursekit @ git+{repository}"], check=True)'''

_WITHOUT_REPOSITORY = ("# Colab and other hosted notebooks start without coursekit: this cell stops there and says\n"
                       "# where to read how to install it (an instructor's `python -m coursekit colab` installs here).\n"
                       + _DOES_NOTHING) + '''import importlib.util
if importlib.util.find_spec("coursekit") is None:
    raise ModuleNotFoundError(
        "coursekit is missing: install it from the course repository these notebooks come from "
        "(its README), then run this cell again.")'''

_URL = re.compile(r"^https://[A-Za-z0-9.\-]+(:[0-9]+)?/[A-Za-z0-9_.\-/~]+$")
_CELL_URL = re.compile(r'"coursekit @ git\+([^"]+)"\], check=True\)')


def install_cell_source(repository: str | None = None) -> str:
    """The source of the install cell for the git repository at `repository` (an https URL) or None."""
    if repository is None:
        return _WITHOUT_REPOSITORY
    if not isinstance(repository, str) or not _URL.match(repository):
        raise ValueError(f"repository must be the https address of the course's git repository, e.g. "
                         f"https://github.com/OWNER/NAME: received {repository!r}.")
    return _WITH_REPOSITORY.format(repository=repository)


def cell_repository(source: str) -> str | None:
    """The repository address an install cell's `source` installs from (None when it names none)."""
    match = _CELL_URL.search(source)
    return match.group(1) if match else None


def _install_cell_index(nb) -> int | None:
    for index, cell in enumerate(nb.cells):
        if role(cell) == INSTALL_MARK:
            return index
    return None


def with_install_cell(nb, *, repository: str | None = None):
    """`nb` with the install cell for `repository` before its first code cell (in place, returned).

    An existing install cell is rewritten where it is; otherwise a new one is
    inserted before the environment check (the cells marked ``coursekit:
    environment``), or before the first code cell when there is none.
    """
    import nbformat
    source = install_cell_source(repository)
    index = _install_cell_index(nb)
    if index is not None:
        nb.cells[index].source = source
        return nb
    cell = nbformat.v4.new_code_cell(source, metadata={ROLE_KEY: INSTALL_MARK})
    # before the environment check (its text and code cell), else before the first code cell
    marks = [role(c) for c in nb.cells]
    kinds = [c.cell_type for c in nb.cells]
    at = marks.index(ENVIRONMENT) if ENVIRONMENT in marks else (
        kinds.index("code") if "code" in kinds else len(nb.cells))
    nb.cells.insert(at, cell)
    return nb


def repository_from_git(folder: Path | str) -> str | None:
    """The https address of the git remote ``origin`` of the repository holding `folder`, or None.

    An SSH address (``git@host:owner/name.git``) is turned into its https form;
    a trailing ``.git`` is dropped.
    """
    try:
        result = subprocess.run(["git", "-C", str(folder), "remote", "get-url", "origin"],
                                capture_output=True, text=True, check=False)
    except OSError:
        return None
    url = result.stdout.strip()
    if result.returncode != 0 or not url:
        return None
    ssh = re.match(r"^(?:ssh://)?git@([^:/]+)[:/](.+)$", url)
    if ssh:
        url = f"https://{ssh.group(1)}/{ssh.group(2)}"
    url = url[:-4] if url.endswith(".git") else url
    return url if _URL.match(url) else None


def apply_install_cell(notebooks: Path | str | None = None, *, repository: str | None = None,
                       write: bool = True) -> list[Path]:
    """Write the install cell for `repository` into every notebook of `notebooks`; return those changed.

    `notebooks` defaults to the repository's ``notebooks/``; ``write=False``
    only reports which notebooks would change.
    """
    source = install_cell_source(repository)   # validates the address before anything is written

    def stale(nb) -> bool:
        index = _install_cell_index(nb)
        return index is None or nb.cells[index].source != source
    return update_notebooks(notebooks, stale, lambda nb: with_install_cell(nb, repository=repository), write=write)
