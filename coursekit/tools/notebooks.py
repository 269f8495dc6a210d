"""The chapter notebooks as every tool finds, reads, writes and executes them.

The student edition (`release`), the website (`site`), the slides (`slideshow`), the notebooks'
metadata (`slides`, `kernel_metadata`, `colab`) and the grader read their notebooks here:

* `default_notebook_dir`, `notebook_paths` (every ``*.ipynb`` of a folder) and
  `chapter_notebooks` (``01_*.ipynb``, ``02_*.ipynb``, ...) find them;
* `read_notebook` and `write_notebook` read and write them, in the repository's JSON style; `update_notebooks`
  rewrites those a change would alter;
* `execute_all` executes them side by side (nbclient, one kernel per core at a time, without
  storing widget state: explorers keep their figure);
* `harvest_alt_texts` gives each figure of an executed notebook its text alternative;
* `leave_out_the_iri_grammar` spares a process of the tools (the command line, the grader's
  runner, the site's Sphinx build) a second of a core that importing nbformat would cost it.

nbformat and nbclient (installed with JupyterLab) are imported inside the functions, so
``import coursekit`` does not need them.
"""

from __future__ import annotations

import asyncio
import os
import sys
from pathlib import Path
from typing import Callable

__all__ = ["WIDGET_VIEW", "ALT", "default_notebook_dir", "notebook_paths", "chapter_notebooks",
           "read_notebook", "write_notebook", "update_notebooks", "execute_all", "harvest_alt_texts", "text_of", "say",
           "leave_out_the_iri_grammar"]

#: the media type of a widget's view in an output (an explorer's live view)
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
#: the media type under which the kernel adds each figure's description to its display data
ALT = "text/x-coursekit-alt"


def _nbformat():
    try:
        import nbformat
    except ImportError as error:  # pragma: no cover - nbformat comes with the lab extra
        raise ImportError("reading notebooks needs nbformat, which comes with JupyterLab: "
                          'python -m pip install -e ".[lab]"') from error
    return nbformat


def leave_out_the_iri_grammar() -> None:
    """Keep this process from building the IRI grammar of the package rfc3987-syntax: nbformat imports
    jsonschema, which imports that package when it is installed (JupyterLab brings it) for its
    ``iri`` format, and the package builds its grammar on import, about 0.8 s of a core of the 1 s
    that importing nbformat costs (60 % of a grader runner's work on a short notebook;
    python-jsonschema/jsonschema#1428). Nothing here checks that format: nbformat's schemas use
    none and nbformat validates with fastjsonschema. Without the package, jsonschema leaves the
    ``iri`` format out, as it is documented to; the import is refused the way Python documents (a
    ``None`` in ``sys.modules``) and only in this process. Called where a process of the tools
    starts (``python -m coursekit``, the grader's runner, the site's Sphinx build), not by a library call
    into a process of the user's."""
    sys.modules.setdefault("rfc3987_syntax", None)


def default_notebook_dir() -> Path:
    """The repository's ``notebooks/`` folder (the instructor edition).

    The folder next to the package when coursekit is installed from a clone
    with ``pip install -e``; otherwise (``pip install .``, as on Binder)
    ``notebooks/`` in the current folder.
    """
    beside = Path(__file__).resolve().parents[2] / "notebooks"
    return beside if beside.is_dir() else Path.cwd() / "notebooks"


def notebook_paths(notebooks=None) -> tuple[Path, list[Path]]:
    """The folder of the course notebooks (`notebooks`, default `default_notebook_dir`) and its
    ``*.ipynb`` files, sorted; ValueError when it holds none, TypeError when `notebooks` is
    not a path."""
    if notebooks is not None and not isinstance(notebooks, (str, Path)):
        raise TypeError(f"notebooks must be a folder path (str or Path) or None: received "
                        f"{type(notebooks).__name__}.")
    folder = default_notebook_dir() if notebooks is None else Path(notebooks)
    paths = sorted(folder.glob("*.ipynb"))
    if not paths:
        raise ValueError(f"no notebooks (*.ipynb) found in {folder}; pass the folder of the course "
                         "notebooks (--notebooks on the command line).")
    return folder, paths


def chapter_notebooks(notebooks_dir) -> list[Path]:
    """The chapter notebooks (``01_*.ipynb``, ``02_*.ipynb``, ...) of `notebooks_dir`, in order."""
    folder = Path(notebooks_dir)
    if not folder.is_dir():
        raise ValueError(f"notebooks_dir {str(folder)!r} is not a directory; pass the folder "
                         "that holds the chapter notebooks (notebooks/ in the repository)")
    found = sorted(p for p in folder.glob("[0-9]*.ipynb") if p.is_file())
    if not found:
        raise ValueError(f"notebooks_dir {str(folder)!r} holds no chapter notebook "
                         "(files named like 01_representations.ipynb)")
    return found


def read_notebook(path: Path | str):
    """Read a notebook file (nbformat 4) into a NotebookNode."""
    return _nbformat().read(str(path), as_version=4)


def write_notebook(nb, path: Path | str) -> None:
    """Write a notebook in the repository's JSON style (indent 1, sorted keys, final newline)."""
    Path(path).write_text(_nbformat().writes(nb) + "\n", encoding="utf-8")


def update_notebooks(notebooks, stale: Callable, update: Callable, *, write: bool) -> list[Path]:
    """The notebooks of the folder `notebooks` (see `notebook_paths`) for which `stale(nb)` is
    true; with `write`, each is rewritten as `update(nb)` returns it."""
    if not isinstance(write, bool):
        raise TypeError(f"write must be True or False: received {write!r}.")
    changed = []
    for path in notebook_paths(notebooks)[1]:
        nb = read_notebook(path)
        if stale(nb):
            changed.append(path)
            if write:
                write_notebook(update(nb), path)
    return changed


def text_of(value) -> str:
    """A notebook's text field (a cell's source, an output's data) as one string."""
    return "".join(value) if isinstance(value, list) else value


def execute_all(notebooks: list, paths: list[Path], *, timeout: int, what: str, prelude: str = "",
                verbose: bool = False, kernel: Callable | None = None) -> None:
    """Execute every notebook of `notebooks` (in place) in the folder of its file in `paths`, one
    kernel per core at a time, without storing widget state, after a first cell `prelude` (which
    the notebooks do not keep). `timeout` limits one cell (seconds); `what` names the build in
    messages ("the site"); `kernel()`, when given, makes each notebook's (asynchronous) kernel
    manager. A cell that raises stops with RuntimeError naming the notebook."""
    if len(notebooks) != len(paths):
        raise ValueError(f"paths must give one file per notebook: received {len(paths)} for "
                         f"{len(notebooks)} notebooks")
    workers = max(1, min(len(notebooks), os.cpu_count() or 1))
    say(verbose, what, f"executing {len(notebooks)} notebooks, {workers} at a time")
    from nbformat.v4 import new_code_cell
    for nb in notebooks if prelude else []:
        nb.cells.insert(0, new_code_cell(prelude))
    try:
        asyncio.run(_execute_all(notebooks, paths, timeout=timeout, what=what, workers=workers,
                                 verbose=verbose, kernel=kernel))
    finally:
        for nb in notebooks if prelude else []:
            nb.cells.pop(0)


async def _execute_all(notebooks, paths, *, timeout, what, workers, verbose, kernel) -> None:
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError
    gate = asyncio.Semaphore(workers)

    async def run(nb, path):
        manager = {"km": kernel()} if kernel else {"kernel_name": "python3"}
        client = NotebookClient(nb, timeout=timeout, store_widget_state=False,
                                resources={"metadata": {"path": str(Path(path).parent)}}, **manager)
        async with gate:
            try:
                await client.async_execute(cleanup_kc=True)   # shut down a kernel `kernel()` made too
            except CellExecutionError as error:
                raise RuntimeError(f"notebook {Path(path).name} failed while building {what}:\n{error}") from None
        say(verbose, what, f"executed {Path(path).name}")

    await asyncio.gather(*(run(nb, path) for nb, path in zip(notebooks, paths)))


def say(verbose: bool, what: str, message: str) -> None:
    """With `verbose`, print `message` to stderr as a step of the build `what` ("the site")."""
    if verbose:
        print(f"coursekit {what.removeprefix('the ')}: {message}", file=sys.stderr, flush=True)


def harvest_alt_texts(nb):
    """Give every figure of the executed `nb` its text alternative (in place; returned).

    The text goes into the output's ``metadata["image/png"]["alt"]``: a figure's from its
    described data (`ALT`, removed from the data), an explorer's from its text (title, settings,
    readout and data).
    """
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            text = data.pop(ALT, None)
            if text is None and "image/png" in data and WIDGET_VIEW in data:
                text = data.get("text/plain")
            if text and "image/png" in data:
                output.setdefault("metadata", {}).setdefault("image/png", {})["alt"] = text_of(text).strip()
    return nb
