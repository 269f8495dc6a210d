"""The student edition of the notebooks: ``python -m coursekit release --out DIR``.

The notebooks in ``notebooks/`` are the instructor edition: every exercise is
followed by its worked solution, in a cell tagged ``solution`` (cell metadata
``tags: ["solution"]``; a markdown cell with a collapsed ``<details>`` block,
or, in older notebooks, a code cell). The student edition is the same
notebook with

* every cell tagged ``solution`` removed, whatever its type;
* every output and execution count cleared, and no stored widget state;
* a note at the end of the first cell saying that the worked solutions are in
  the instructor edition;
* in the exercise section, the sentences that point to a solution below an
  exercise ("the solution follows in a collapsed cell") removed, since it is
  not there any more.

The exercises and their ``check_*`` cells stay: run on an unanswered exercise,
a check prints its "Not yet" feedback, so the edition runs top to bottom
without errors (tests/test_release.py builds it and executes every notebook).

nbformat and nbconvert (installed with JupyterLab, the ``lab`` extra) are imported
inside the functions, so ``import coursekit`` does not need them.
"""

from __future__ import annotations

import copy
import re
from pathlib import Path

from .cells import EXERCISE, SOLUTION_TAG, role
from .notebooks import notebook_paths, read_notebook, write_notebook

__all__ = [
    "STUDENT_NOTE",
    "student_text",
    "student_edition",
    "build_release",
]


#: appended to the first cell of every notebook of the student edition
STUDENT_NOTE = ("> **Student edition.** The worked solutions of the exercises are not in this copy: "
                "they are in the instructor edition of the notebooks. Each exercise's `check_*` cell "
                "tells you whether your answer is right.")

# a sentence of the exercise section that points to a solution cell, e.g. "The solution follows in
# a collapsed cell (click the three dots to open it) — try first!"; a sentence that says the checks
# never show the solution is kept
_WHERE = r"(follow\w*|below|beneath|collapsed|click\w*|hidden|sits)"
_POINTER = re.compile(rf"\bsolutions?\b.*\b{_WHERE}\b|\b{_WHERE}\b.*\bsolutions?\b", re.IGNORECASE)
_TRY_FIRST = re.compile(r"^\W*try\b[\w ]{0,25}\bfirst\W*$", re.IGNORECASE)
_NEGATION = re.compile(r"\b(never|not|no)\b", re.IGNORECASE)
_SENTENCE_END = re.compile(r"(?<=[.!?])\s+(?=\S)")


def _without_solution_pointers(text: str) -> str:
    """`text` minus the sentences that point to a solution cell (paragraph by paragraph).

    Where such a sentence goes, a short "Try first!" of the same paragraph
    (about the solution that is no longer there) goes with it.
    """
    paragraphs = []
    for paragraph in text.split("\n\n"):
        sentences = _SENTENCE_END.split(paragraph)
        kept = [s for s in sentences if not (_POINTER.search(s) and not _NEGATION.search(s))]
        if len(kept) < len(sentences):
            kept = [s for s in kept if not _TRY_FIRST.match(s)]
        if kept:
            paragraphs.append(" ".join(kept) if len(kept) < len(sentences) else paragraph)
    return "\n\n".join(paragraphs)


def _add_note(nb) -> None:
    from nbformat.v4 import new_markdown_cell
    first = nb.cells[0] if nb.cells else None
    if first is not None and first.cell_type == "markdown":
        if STUDENT_NOTE not in first.source:
            first.source = first.source.rstrip() + "\n\n" + STUDENT_NOTE
    else:
        nb.cells.insert(0, new_markdown_cell(STUDENT_NOTE))


def student_text(nb):
    """A copy of `nb` with the student edition's cells and text, its outputs kept: the cells
    tagged ``solution`` removed (nbconvert's ``TagRemovePreprocessor``), the exercise section's
    pointers to them dropped and the note added to the first cell; `nb` is unchanged."""
    from nbconvert.preprocessors import TagRemovePreprocessor
    if not hasattr(nb, "cells") or not hasattr(nb, "metadata"):
        raise TypeError(f"nb must be a notebook (nbformat NotebookNode): received {type(nb).__name__}; "
                        "read it with coursekit.tools.notebooks.read_notebook(path).")
    nb, _ = TagRemovePreprocessor(remove_cell_tags={SOLUTION_TAG}).preprocess(copy.deepcopy(nb), {})
    for cell in nb.cells:
        if cell.cell_type == "markdown" and role(cell) == EXERCISE:
            cell.source = _without_solution_pointers(cell.source)
    _add_note(nb)
    return nb


def student_edition(nb):
    """A copy of the notebook `nb` for students (see the module docstring); `nb` is unchanged:
    `student_text` with every output cleared (nbconvert's ``ClearOutputPreprocessor``) and no
    widget state.

    `nb` is a NotebookNode (from `read_notebook` or ``nbformat.read``). Applying
    it to a student edition again changes nothing.
    """
    from nbconvert.preprocessors import ClearOutputPreprocessor
    nb, _ = ClearOutputPreprocessor().preprocess(student_text(nb), {})
    nb.metadata.pop("widgets", None)
    return nb


def _check_out_dir(out: Path, source: Path, force: bool) -> None:
    if out.resolve() == source.resolve():
        raise ValueError(f"out is the notebooks' own folder ({out}): the student edition would replace "
                         "the instructor edition; choose another folder.")
    if out.exists() and not out.is_dir():
        raise ValueError(f"out must be a folder: {out} is a file; choose a new folder name.")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ValueError(f"out folder {out} is not empty; choose a new or empty folder, or pass force=True "
                         "(--force on the command line) to overwrite the notebooks of the same names in it.")


def build_release(out: Path | str, *, notebooks: Path | str | None = None, force: bool = False) -> list[Path]:
    """Write the student edition of every notebook of `notebooks` into the folder `out`.

    `notebooks` defaults to the repository's ``notebooks/`` folder. `out` is
    created when missing; an existing non-empty `out` is refused unless
    ``force=True``, which overwrites the files of the same names and leaves
    any other file there alone. Returns the paths written, sorted by name.
    """
    if not isinstance(out, (str, Path)):
        raise TypeError(f"out must be a folder path (str or Path): received {type(out).__name__}.")
    if notebooks is not None and not isinstance(notebooks, (str, Path)):
        raise TypeError(f"notebooks must be a folder path (str or Path) or None: received "
                        f"{type(notebooks).__name__}.")
    if not isinstance(force, bool):
        raise TypeError(f"force must be True or False: received {force!r}.")
    out = Path(out)
    source, paths = notebook_paths(notebooks)
    _check_out_dir(out, source, force)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in paths:
        target = out / path.name
        write_notebook(student_edition(read_notebook(path)), target)
        written.append(target)
    return written
