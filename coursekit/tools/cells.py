"""The roles of a chapter notebook's cells, as the course tools read them.

A notebook marks its special cells in their metadata, and every tool (the student edition,
the website, the Colab install cell, the slides, the grader) reads them through this module:

* ``"coursekit": "install"`` -- the first code cell: installs coursekit where it is missing
  (Colab), and does nothing elsewhere (``python -m coursekit colab`` writes it);
* ``"coursekit": "environment"`` -- the environment check (``ck.check_environment()``) and the
  text that introduces it;
* ``"coursekit": "exercise"`` -- every cell of the exercise section: the tasks, the answer
  cells that call a ``check_*``, and the solutions;
* the tag ``solution`` (``"tags": ["solution"]``) -- a worked solution, right after its
  exercise: a markdown cell with a collapsed ``<details>`` block (or a code cell). The
  student edition removes it and the website folds it.
"""

from __future__ import annotations

__all__ = ["ROLE_KEY", "INSTALL", "ENVIRONMENT", "EXERCISE", "SOLUTION_TAG", "role", "is_solution"]

#: the cell metadata key that holds a cell's role
ROLE_KEY = "coursekit"
INSTALL, ENVIRONMENT, EXERCISE = "install", "environment", "exercise"
#: the cell tag of a worked solution
SOLUTION_TAG = "solution"


def role(cell) -> str | None:
    """The role of `cell` (`INSTALL`, `ENVIRONMENT`, `EXERCISE`) or None."""
    return cell.get("metadata", {}).get(ROLE_KEY)


def is_solution(cell) -> bool:
    """True when `cell` is a worked solution (tagged `SOLUTION_TAG`)."""
    return SOLUTION_TAG in cell.get("metadata", {}).get("tags", [])
