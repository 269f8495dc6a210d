"""The chapter notebooks executed once per test session, for the tests that only read their
outputs (the session fixture ``executed_chapters`` of tests/conftest.py, an `ExecutedChapters`).

* the instructor edition: each chapter of ``notebooks/`` with its slide types, executed when a
  test first asks for it, after a first cell (`PRELUDE`) that gives every figure the slides'
  description (``slideshow.DESCRIBE_FIGURES``) and every figure and explorer its report of
  `figure_checks` (`notebook_figures.PRELUDE`). The figure-style test reads the reports; the
  slides of the whole course (tests/test_slides.py) take, by `replay_into`, the chapters executed
  already (in a full run, all of them) and execute only the others.
* the student edition: as ``python -m coursekit release`` writes it, executed as it is
  (tests/test_release.py).

nbval executes every notebook as its own test besides; the website's build executes its own, since
it draws every figure for its page's column. Chapters asked for together run side by side, one
kernel per core at a time, in kernels of this interpreter.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import nbformat
import pytest

from coursekit.tools.notebooks import default_notebook_dir, execute_all, read_notebook
from coursekit.tools.slideshow import DESCRIBE_FIGURES
from kernels import this_python_kernel
from notebook_figures import PRELUDE as FIGURE_CHECKS, REPORT

__all__ = ["PRELUDE", "Executed", "ExecutedChapters", "replay_into", "replaying"]

#: the first cell of the instructor edition: the slides' figure descriptions, the figure checks
PRELUDE = DESCRIBE_FIGURES + FIGURE_CHECKS

@dataclass
class Executed:
    """The student edition executed: the files written and executed and their executed notebooks."""
    paths: list[Path]
    notebooks: list


class ExecutedChapters:
    """The chapters this session executed. `instructor(names)` and `student()` execute what was
    not executed yet (side by side) and hand out the executed notebooks; `has_instructor(name)`
    says whether that chapter's is there, without executing it. A chapter that failed fails every
    test that asks for it, with the message, and is not executed again."""

    def __init__(self, tmp_path_factory):
        self._tmp = tmp_path_factory
        self._done = {}     # ("instructor", file name) or ("student", "") -> result or failure message

    def instructor(self, names: list[str]) -> list:
        """The executed notebooks of the instructor edition's files called `names`."""
        missing = [name for name in names if ("instructor", name) not in self._done]
        if missing:
            self._run([("instructor", name) for name in missing], lambda: _execute_instructor(missing))
        return [self._ready(("instructor", name)) for name in names]

    def has_instructor(self, name: str) -> bool:
        return not isinstance(self._done.get(("instructor", name), ""), str)

    def student(self) -> Executed:
        if ("student", "") not in self._done:
            self._run([("student", "")], lambda: [_execute_student(self._tmp.mktemp("student") / "edition")])
        return self._ready(("student", ""))

    def _run(self, keys: list, run) -> None:
        try:
            self._done.update(zip(keys, run()))
        except Exception as error:
            message = f"executing {', '.join(k[1] or k[0] for k in keys)} failed: {type(error).__name__}: "
            self._done.update(dict.fromkeys(keys, message + str(error)[:2000]))
            raise

    def _ready(self, key):
        if isinstance(self._done[key], str):
            pytest.fail(self._done[key])
        return self._done[key]


def _execute_instructor(names: list[str]) -> list:
    """The instructor edition's chapters called `names`, with their slide types, executed after
    the slides' first cell and the figure checks' (`PRELUDE`)."""
    from coursekit.tools.slides import with_slide_metadata
    paths = [default_notebook_dir() / name for name in names]
    notebooks = [with_slide_metadata(read_notebook(path)) for path in paths]
    for nb in notebooks:
        nb.cells.insert(0, nbformat.v4.new_code_cell(PRELUDE))
    _execute(notebooks, paths)
    return notebooks


def _execute_student(folder: Path) -> Executed:
    """The student edition as ``python -m coursekit release`` writes it into `folder`, executed."""
    from coursekit.tools.release import build_release
    paths = build_release(folder)
    notebooks = [read_notebook(path) for path in paths]
    _execute(notebooks, paths)
    return Executed(paths, notebooks)


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
    for cell, ran in zip(nb.cells, executed.cells):
        if cell.cell_type == "code":
            cell.outputs = copy.deepcopy(ran.outputs)
            cell.execution_count = ran.execution_count
            for output in cell.outputs:
                for media in drop:
                    output.get("data", {}).pop(media, None)
    nb.metadata["language_info"] = copy.deepcopy(executed.metadata.get("language_info", {}))


def replaying(executed_chapters: ExecutedChapters) -> Callable:
    """An `execute_all` for ``build_slides(execute=...)`` that executes only the chapters
    `executed_chapters` has not executed: the others take the outputs of the shared copies
    (`replay_into`, without the figure checks' reports), which must match them cell by cell."""
    def execute(notebooks: list, paths: list[Path], *, prelude: str = "", **options) -> None:
        rest = []
        for nb, path in zip(notebooks, paths):
            if executed_chapters.has_instructor(path.name):
                nb.cells.insert(0, nbformat.v4.new_code_cell(prelude))
                replay_into(nb, executed_chapters.instructor([path.name])[0], drop=(REPORT,))
                nb.cells.pop(0)
            else:
                rest.append((nb, path))
        if rest:
            execute_all([nb for nb, _ in rest], [path for _, path in rest], prelude=prelude, **options)

    return execute
