"""What the chapter notebooks print reads as the course writes numbers, in JupyterLab and on the website.

NumPy 2 writes its scalars as ``np.float64(1.875)`` inside a list, a dict or a tuple; a student
reading ``alpha = [1.0, -0.5, np.float64(1.875), ...]`` sees the library's plumbing, not the
number. Every text a notebook prints or shows (the session's execution of the chapters that the
figure checks read, tests/executed_chapters.py) holds no NumPy scalar repr.
"""

import re
from pathlib import Path

import pytest

from coursekit.tools.notebooks import chapter_notebooks
from notebook_figures import text_outputs

NOTEBOOKS = chapter_notebooks(Path(__file__).resolve().parents[1] / "notebooks")

#: how NumPy 2 writes a scalar inside a container: np.float64(1.875), np.True_, np.str_('a')
NUMPY_REPR = re.compile(r"\bnp\.(?:float|int|uint|complex|bool|str_|True_|False_)\w*\b")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_no_output_shows_a_numpy_scalar_repr(path, executed_chapters):
    executed = executed_chapters.instructor(path.name)
    found = [f"cell {index}: {line.strip()}" for index, text in text_outputs(executed)
             for line in text.splitlines() if NUMPY_REPR.search(line)]
    assert not found, "\n".join(found)
