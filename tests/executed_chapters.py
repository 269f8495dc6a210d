"""The chapter notebooks executed once per test session, for the tests that only read their
outputs (the session fixture ``executed_chapters`` of tests/conftest.py, an `ExecutedChapters`).

* the instructor edition: each chapter of ``notebooks/`` with its slide types, executed when a
  test first asks for it, after a first cell (`PRELUDE`) that gives every figure the slides'
  description (``slideshow.DESCRIBE_FIGURES``) and every figure and explorer its report of
  `figure_checks` (`notebook_figures.PRELUDE`). The figure-style test reads the reports; the
  slides of the whole course (tests/test_slides.py) take every chapter from here, by
  `replay_into`, executing none themselves (a chapter no worker executed yet is executed here
  first: the slides' build once ran the chapters the figure-style test had not reached yet,
  which that test then executed a second time).
* the student edition: as ``python -m coursekit release`` writes it (tests/test_release.py). A
  chapter whose code cells are the instructor edition's, in the same order (no solution is code:
  the solutions are markdown), runs exactly what the instructor edition runs, so it takes the
  outputs of the instructor edition's execution (`replay_code`), as the website's build serves
  both editions from one execution; a chapter with a solution in code is executed as it is.

nbval executes every notebook as its own test besides; the website's build executes its own, since
it draws every figure for its page's column. Each is executed once per run, in a kernel of this
interpreter, by the first xdist worker that asks, and written to the run's shared folder
(tests/run_once.py), which the other workers read.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import nbformat

from coursekit.tools.notebooks import ALT, default_notebook_dir, execute_all, read_notebook, write_notebook
from coursekit.tools.slideshow import DESCRIBE_FIGURES
from coursekit.tools.static_explorers import MIME as FRAMES
from kernels import this_python_kernel
from notebook_figures import PRELUDE as FIGURE_CHECKS, REPORT
from run_once import once, shared_folder

__all__ = ["PRELUDE", "Executed", "ExecutedChapters", "replay_into", "replay_code", "replaying"]

#: the first cell of the instructor edition: the slides' figure descriptions, the figure checks
PRELUDE = DESCRIBE_FIGURES + FIGURE_CHECKS
#: what `PRELUDE` adds to the outputs (descriptions, explorers' frames, figure checks' reports)
PRELUDE_MEDIA = (ALT, FRAMES, REPORT)

@dataclass
class Executed:
    """The student edition executed: the files written and executed and their executed notebooks."""
    paths: list[Path]
    notebooks: list


class ExecutedChapters:
    """The chapters this run executed, each once however many xdist workers ask (tests/run_once.py):
    `instructor(name)` and `student()` execute what no worker executed yet and hand out the
    executed notebooks. A chapter that failed fails every test that asks for it, with the message."""

    def __init__(self, tmp_path_factory, worker_id: str):
        self._folder = shared_folder(tmp_path_factory, worker_id) / "executed"
        self._read = {}     # ("instructor", file name) or ("student", "") -> what was read

    def instructor(self, name: str):
        """The executed notebook of the instructor edition's file called `name`."""
        key = ("instructor", name)
        if key not in self._read:
            folder = once(self._folder / "instructor" / name, lambda out: _execute_instructor(name, out))
            self._read[key] = read_notebook(folder / name)
        return self._read[key]

    def student(self) -> Executed:
        """The student edition, built and executed (see the module's doc)."""
        if ("student", "") not in self._read:
            folder = once(self._folder / "student", lambda out: _execute_student(out, self.instructor))
            paths = sorted((folder / "edition").glob("*.ipynb"))
            executed = [read_notebook(folder / "executed" / path.name) for path in paths]
            self._read[("student", "")] = Executed(paths, executed)
        return self._read[("student", "")]


def _execute_instructor(name: str, out: Path) -> None:
    """The instructor edition's chapter called `name`, with its slide types, executed after the
    slides' first cell and the figure checks' (`PRELUDE`), written into the folder `out`."""
    from coursekit.tools.slides import with_slide_metadata
    path = default_notebook_dir() / name
    nb = with_slide_metadata(read_notebook(path))
    nb.cells.insert(0, nbformat.v4.new_code_cell(PRELUDE))
    _execute([nb], [path])
    out.mkdir()
    write_notebook(nb, out / name)


def _execute_student(folder: Path, instructor: Callable) -> None:
    """The student edition as ``python -m coursekit release`` writes it into ``folder/edition``, each
    chapter given the outputs of `instructor` (its name -> the instructor edition executed) where
    their code is the same, else executed there; the executed copies written into ``folder/executed``."""
    from coursekit.tools.release import build_release
    paths = build_release(folder / "edition")
    notebooks = [read_notebook(path) for path in paths]
    own = []
    for nb, path in zip(notebooks, paths):
        shared = instructor(path.name)
        if _code(nb) == _code(shared)[1:]:       # after the prelude
            replay_code(nb, shared)
        else:
            own.append((nb, path))
    if own:
        _execute(*map(list, zip(*own)))
    (folder / "executed").mkdir()
    for nb, path in zip(notebooks, paths):
        write_notebook(nb, folder / "executed" / path.name)


def _execute(notebooks: list, paths: list[Path]) -> None:
    """Execute as the builds do (`coursekit.tools.notebooks.execute_all`), in kernels of this interpreter."""
    execute_all(notebooks, paths, timeout=600, what="the tests' shared chapters",
                kernel=lambda: this_python_kernel(asynchronous=True))


def replay_into(nb, executed, *, drop: tuple[str, ...] = ()) -> None:
    """Give `nb` (a notebook about to be executed whose first cell is a prelude contained in
    `executed`'s) the outputs of `executed`, in place, without the data of the media types `drop`.
    Raises AssertionError when `nb` is not the notebook `executed` ran."""
    assert nb.cells[0].source in executed.cells[0].source, "the prelude differs from the shared copy's"
    assert [(c.cell_type, c.source) for c in nb.cells[1:]] == \
        [(c.cell_type, c.source) for c in executed.cells[1:]], "the cells differ from the shared copy's"
    _give_outputs(nb, executed, [(c, ran) for c, ran in zip(nb.cells, executed.cells) if c.cell_type == "code"],
                  drop=drop, counted_from=1)


def _code(nb) -> list[str]:
    return [c.source for c in nb.cells if c.cell_type == "code"]


def replay_code(nb, executed) -> None:
    """Give the code cells of `nb` (a notebook whose code cells are those of `executed` after its
    prelude cell) the outputs and execution counts they had in `executed`, in place, as a run
    without the prelude gives them: without what it adds (`PRELUDE_MEDIA`), counted from 1."""
    ran = [c for c in executed.cells[1:] if c.cell_type == "code"]
    cells = [c for c in nb.cells if c.cell_type == "code"]
    assert [c.source for c in cells] == [c.source for c in ran], "the code differs from the shared copy's"
    _give_outputs(nb, executed, list(zip(cells, ran)), drop=PRELUDE_MEDIA, counted_from=2)


def _give_outputs(nb, executed, pairs: list, *, drop: tuple[str, ...], counted_from: int) -> None:
    """Each (cell of `nb`, cell of `executed`) of `pairs`: the first gets the second's outputs without
    the media types `drop`, and its execution count renumbered from 1 where `executed` counted from
    `counted_from`; `nb` gets the language of `executed`."""
    for cell, ran in pairs:
        cell.outputs = copy.deepcopy(ran.outputs)
        count = ran.execution_count
        cell.execution_count = None if count is None else count - (counted_from - 1)
        for output in cell.outputs:
            for media in drop:
                output.get("data", {}).pop(media, None)
                output.get("metadata", {}).pop(media, None)
    nb.metadata["language_info"] = copy.deepcopy(executed.metadata.get("language_info", {}))


def replaying(executed_chapters: ExecutedChapters) -> Callable:
    """An `execute_all` for ``build_slides(execute=...)`` of the course's own notebooks that gives
    each chapter the outputs of its shared copy (`replay_into`, without the figure checks'
    reports), which must match it cell by cell: executed once per run, by whichever worker asks
    first (``ExecutedChapters.instructor``). The `options` of `execute_all` are not needed."""
    def execute(notebooks: list, paths: list[Path], *, prelude: str = "", **options) -> None:
        for nb, path in zip(notebooks, paths):
            nb.cells.insert(0, nbformat.v4.new_code_cell(prelude))
            replay_into(nb, executed_chapters.instructor(path.name), drop=(REPORT,))
            nb.cells.pop(0)

    return execute
