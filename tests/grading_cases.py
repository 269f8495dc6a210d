"""Chapter 1's exercise section as the grading tests build submissions from it."""

from __future__ import annotations

import re
import subprocess

from nbformat.v4 import new_code_cell

from coursekit.tools.grading.sandbox import find_bwrap

__all__ = ["SOLUTION", "SANDBOX", "exercise_section", "solved", "answer"]


def _bwrap_works() -> bool:
    """Whether bubblewrap is installed and may make namespaces here."""
    if find_bwrap() is None:
        return False
    return subprocess.run([find_bwrap(), "--unshare-all", "--ro-bind", "/", "/", "true"],
                          capture_output=True).returncode == 0


#: whether the grader's sandbox runs here (the README's install does not bring bubblewrap)
SANDBOX = _bwrap_works()

#: the code block a solution cell shows
SOLUTION = re.compile(r"```python\n(?P<code>.*?)\n```", re.S)


def exercise_section(nb) -> list:
    """The chapter heading, an import of NumPy, and the cells of the exercise section."""
    cells = [nb.cells[0], new_code_cell("import numpy as np")]
    return cells + [cell for cell in nb.cells if cell.metadata.get("coursekit") == "exercise"]


def solved(nb) -> list:
    """The exercise section with every solution cell turned into the code cell it shows."""
    cells = []
    for cell in exercise_section(nb):
        if "solution" in cell.metadata.get("tags", []):
            cell = new_code_cell(SOLUTION.search(cell.source)["code"])
        cells.append(cell)
    return cells


def answer(cells, check: str) -> list:
    """The code cell of `cells` that answers `check` (the solution: it calls the check last)."""
    return [cell for cell in cells if cell.cell_type == "code" and f"ex.{check}(" in cell.source][-1:]
