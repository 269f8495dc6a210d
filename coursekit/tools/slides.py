"""Slide metadata of the notebooks: ``python -m coursekit slides``.

``jupyter nbconvert --to slides`` turns a notebook into a reveal.js slide
show from each cell's ``metadata.slideshow.slide_type``. `slide_type` decides
it from the notebook's own structure, so the slides follow the sections when
the text changes:

* the title cell (``# ...``) and every section heading (``## ...``): ``slide``;
* every subsection heading (``### ...``, ``#### ...``): ``subslide``;
* a text cell that follows a code cell: ``subslide``, so that a long section
  is a column of short sub-slides, each one paragraph with its code and figure;
* the cells before the first section (the install cell, the environment check
  and the imports): ``skip``; they still run when the slides are built with
  ``--execute``;
* every other cell: ``-`` (it joins the slide above); that is also what
  nbconvert assumes without metadata, so these cells carry none.

`apply_slide_metadata` writes these types into the notebooks (``python -m
coursekit slides``); a test checks the stored metadata is what it would write.
"""

from __future__ import annotations

from pathlib import Path

from .notebooks import update_notebooks

__all__ = ["slide_type", "slide_types", "with_slide_metadata", "apply_slide_metadata"]


def _heading_level(cell) -> int:
    """1 for '# Title', 2 for '## Section', ...; 0 when the cell is not a markdown heading."""
    if cell.cell_type != "markdown":
        return 0
    first = cell.source.lstrip().split("\n", 1)[0]
    hashes = len(first) - len(first.lstrip("#"))
    return hashes if hashes and first[hashes:hashes + 1] == " " else 0


def slide_type(cell, *, previous=None, before_first_section: bool = False) -> str:
    """The slide type of `cell`, given the cell `previous` to it (see the module docstring)."""
    level = _heading_level(cell)
    if level in (1, 2):
        return "slide"
    if before_first_section:
        return "skip"
    if level >= 3:
        return "subslide"
    if cell.cell_type == "markdown" and previous is not None and previous.cell_type == "code":
        return "subslide"
    return "-"


def slide_types(nb) -> list[str]:
    """The slide type of every cell of the notebook `nb`, in order."""
    types, previous, started = [], None, False
    for cell in nb.cells:
        started = started or _heading_level(cell) == 2
        types.append(slide_type(cell, previous=previous,
                                before_first_section=not started and previous is not None))
        previous = cell
    return types


def _stored_type(cell) -> str:
    return cell.metadata.get("slideshow", {}).get("slide_type", "-")


def with_slide_metadata(nb):
    """`nb` with ``metadata.slideshow.slide_type`` set on every cell (changed in place and returned).

    Cells of type ``-`` carry no slideshow metadata (nbconvert's default).
    """
    for cell, kind in zip(nb.cells, slide_types(nb)):
        if kind == "-":
            cell.metadata.pop("slideshow", None)
        else:
            cell.metadata.setdefault("slideshow", {})["slide_type"] = kind
    return nb


def apply_slide_metadata(notebooks: Path | str | None = None, *, write: bool = True) -> list[Path]:
    """Set the slide metadata of every notebook in the folder `notebooks`; return those out of date.

    `notebooks` defaults to the repository's ``notebooks/``. With
    ``write=False`` nothing is written: the returned list says which notebooks
    a run with ``write=True`` would change.
    """
    if notebooks is not None and not isinstance(notebooks, (str, Path)):
        raise TypeError(f"notebooks must be a folder path (str or Path) or None: received "
                        f"{type(notebooks).__name__}.")
    return update_notebooks(notebooks, _stale, with_slide_metadata, write=write)


def _stale(nb) -> bool:
    """Whether a cell of `nb` lacks its slide type, or stores the default "-" explicitly."""
    stored = [_stored_type(cell) for cell in nb.cells]
    explicit_dash = any(cell.metadata.get("slideshow", {}).get("slide_type") == "-" for cell in nb.cells)
    return stored != slide_types(nb) or explicit_dash
