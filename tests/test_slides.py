"""Slide metadata: every section is a slide, and the stored metadata is what the tool writes."""

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools.release import default_notebook_dir, read_notebook
from coursekit.tools.slides import apply_slide_metadata, slide_types, with_slide_metadata

NOTEBOOKS = sorted(default_notebook_dir().glob("*.ipynb"))


def _stored(cell):
    return cell.metadata.get("slideshow", {}).get("slide_type", "-")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_section_heading_is_a_slide_and_every_subsection_a_subslide(path):
    nb = read_notebook(path)
    headings = {2: 0, 3: 0}
    for cell in nb.cells:
        first = cell.source.split("\n", 1)[0] if cell.cell_type == "markdown" else ""
        if first.startswith(("# ", "## ")):
            assert _stored(cell) == "slide", first
            headings[2] += first.startswith("## ")
        elif first.startswith(("### ", "#### ")):
            assert _stored(cell) == "subslide", first
            headings[3] += 1
    assert headings[2] >= 2 and headings[3] >= 1, headings     # sections, at least the exercises


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_setup_cells_are_skipped_and_sections_are_not(path):
    nb = read_notebook(path)
    first_section = next(i for i, c in enumerate(nb.cells) if c.source.startswith("## "))
    assert [_stored(c) for c in nb.cells[1:first_section]] == ["skip"] * (first_section - 1)
    assert "skip" not in [_stored(c) for c in nb.cells[first_section:]]
    marks = [c.metadata.get("coursekit") for c in nb.cells[1:first_section]]
    assert "install" in marks and "environment" in marks


def test_stored_slide_metadata_is_up_to_date():
    stale = apply_slide_metadata(write=False)
    assert not stale, f"run: python -m coursekit slides (out of date: {[p.name for p in stale]})"


def _small():
    v4 = nbformat.v4
    return v4.new_notebook(cells=[
        v4.new_markdown_cell("# Title"),
        v4.new_code_cell("import numpy as np"),
        v4.new_markdown_cell("## 1 Section"),
        v4.new_markdown_cell("Text."),
        v4.new_code_cell("x = 1"),
        v4.new_markdown_cell("More text after code."),
        v4.new_code_cell("y = 2"),
        v4.new_markdown_cell("### 1.1 Subsection"),
        v4.new_markdown_cell("#hashtag is not a heading"),
    ])


def test_slide_types_follow_the_rules():
    assert slide_types(_small()) == ["slide", "skip", "slide", "-", "-", "subslide", "-", "subslide", "-"]


def test_dash_cells_carry_no_metadata_and_rewriting_changes_nothing():
    nb = with_slide_metadata(_small())
    assert ["slideshow" in c.metadata for c in nb.cells] == [True, True, True, False, False, True, False,
                                                              True, False]
    again = nbformat.writes(with_slide_metadata(nbformat.reads(nbformat.writes(nb), as_version=4)))
    assert again == nbformat.writes(nb)


def test_cli_slides_check_and_write(tmp_path, capsys):
    nbformat.write(_small(), str(tmp_path / "a.ipynb"))
    assert main(["slides", "--notebooks", str(tmp_path), "--check"]) == 1
    assert "slide metadata out of date: a.ipynb" in capsys.readouterr().out
    assert main(["slides", "--notebooks", str(tmp_path)]) == 0
    assert main(["slides", "--notebooks", str(tmp_path), "--check"]) == 0
    assert [_stored(c) for c in read_notebook(tmp_path / "a.ipynb").cells] == slide_types(_small())


def test_cli_slides_without_notebooks(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["slides", "--notebooks", str(tmp_path)])
    assert "no notebooks (*.ipynb) found" in capsys.readouterr().err
