"""The chapter notebooks executed once per test session and edition, for the tests that only read
their outputs (the session fixture ``executed_chapters`` of tests/conftest.py hands them out).

* ``instructor``: the notebooks of ``notebooks/`` with their slide types, executed after a first
  cell that gives every figure the slides' description (``slideshow.DESCRIBE_FIGURES``) and every
  figure and explorer its report of `figure_checks` (`notebook_figures.PRELUDE`). The figure-style
  test reads the reports; the slides of the whole course (tests/test_slides.py) are built from it
  by `replay_into` instead of executing the notebooks again.
* ``student``: the student edition as ``python -m coursekit release`` writes it, executed as it
  is (tests/test_release.py).

nbval executes every notebook as its own test besides; the website's build executes its own, since
it draws every figure for its page's column. The notebooks of an edition run side by side, one
kernel per core at a time, in kernels of this interpreter.
"""

from __future__ import annotations

import asyncio
import copy
import os
from dataclasses import dataclass
from pathlib import Path

import nbformat

from kernels import this_python_kernel

__all__ = ["EDITIONS", "Executed", "execute_edition", "replay_into"]

EDITIONS = ("instructor", "student")


@dataclass
class Executed:
    """One edition executed: the files executed (`paths`) and their executed notebooks, whose first
    cell is `prelude` when there is one."""
    paths: list[Path]
    notebooks: list
    prelude: str | None

    def notebook(self, name: str):
        """The executed notebook of the file called `name`."""
        return self.notebooks[[p.name for p in self.paths].index(name)]


def execute_edition(edition: str, folder: Path) -> Executed:
    """Execute the chapter notebooks of `edition` (``instructor`` or ``student``, written into
    `folder`, an empty folder, for the student edition)."""
    from coursekit.tools.chapters import chapter_notebooks
    from coursekit.tools.release import build_release, default_notebook_dir
    if edition not in EDITIONS:
        raise ValueError(f"edition must be one of {EDITIONS}, got {edition!r}")
    if edition == "student":
        paths = build_release(folder)
        notebooks = [nbformat.read(path, as_version=4) for path in paths]
        prelude = None
    else:
        from coursekit.tools.slides import with_slide_metadata
        from coursekit.tools.slideshow import DESCRIBE_FIGURES
        from notebook_figures import PRELUDE
        paths = chapter_notebooks(default_notebook_dir())
        notebooks = [with_slide_metadata(nbformat.read(path, as_version=4)) for path in paths]
        prelude = DESCRIBE_FIGURES + PRELUDE
        for nb in notebooks:
            nb.cells.insert(0, nbformat.v4.new_code_cell(prelude))
    asyncio.run(_execute_all(notebooks, paths))
    return Executed(paths, notebooks, prelude)


async def _execute_all(notebooks: list, paths: list[Path]) -> None:
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError
    gate = asyncio.Semaphore(os.cpu_count() or 1)

    async def run(nb, path):
        # store_widget_state=False as the slides and the website execute: explorers keep their PNG
        client = NotebookClient(nb, km=this_python_kernel(asynchronous=True), timeout=600,
                                store_widget_state=False, resources={"metadata": {"path": str(path.parent)}})
        async with gate:
            try:
                await client.async_execute()
            except CellExecutionError as error:
                raise AssertionError(f"{path.name} failed in a cell:\n{error}") from None

    await asyncio.gather(*(run(nb, path) for nb, path in zip(notebooks, paths)))


def replay_into(nb, executed, *, drop: tuple[str, ...] = ()) -> None:
    """Give `nb` (a notebook about to be executed whose first cell is a prelude contained in
    `executed`'s) the outputs of `executed`, in place, without the data of the media types `drop`.
    Raises AssertionError when `nb` is not the notebook `executed` ran."""
    assert nb.cells[0].source in executed.cells[0].source, "the prelude differs from the shared copy's"
    assert [(c.cell_type, c.source) for c in nb.cells[1:]] == \
        [(c.cell_type, c.source) for c in executed.cells[1:]], "the cells differ from the shared copy's"
    for cell, ran in zip(nb.cells, executed.cells):
        if cell.cell_type == "code":
            cell.outputs = copy.deepcopy(ran.outputs)
            cell.execution_count = ran.execution_count
            for output in cell.outputs:
                for media in drop:
                    output.get("data", {}).pop(media, None)
    nb.metadata["language_info"] = copy.deepcopy(executed.metadata.get("language_info", {}))
