"""The numbers of an exercise, readable when printed and typeset in Jupyter.

`ExerciseData` is a read-only mapping: ``ex.MSD["m"]``,
``np.array(ex.EULER["A"])`` and ``models.compartment(**ex.COMPARTMENT)``
work as with a dict. ``print(ex.CTRB)`` gives one line per entry with a
matrix as aligned rows (nested lists, as they are typed)::

    A = [[1,  2,  0],
         [0, -1,  1],
         [1,  0, -2]]
    B = [[0],
         [1],
         [1]]

and ``display(ex.CTRB)`` in Jupyter typesets the matrices as in the notes.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

__all__ = ["ExerciseData"]


class ExerciseData(Mapping):
    """The named numbers of one exercise (scalars, lists and matrices as nested tuples)."""

    def __init__(self, items: Mapping[str, Any]):
        if not isinstance(items, Mapping):
            raise TypeError(f"items must be a mapping of names to numbers, e.g. {{'m': 2.0}}; "
                            f"received {type(items).__name__}.")
        bad = [key for key in items if not isinstance(key, str)]
        if bad:
            raise TypeError(f"items: every name must be a string; received {bad!r}.")
        self._items = dict(items)

    def __getitem__(self, key: str) -> Any:
        return self._items[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return "\n".join(_text_entry(key, value) for key, value in self._items.items())

    def _repr_markdown_(self) -> str:
        # names as code (what the student types between the brackets), values typeset
        return " &emsp; ".join(f"`{key}` {_latex_entry(value)}" for key, value in self._items.items())


def _numbers(value: Any) -> np.ndarray | None:
    """`value` as a float array of at most 2 dimensions, or None when it is something else."""
    if isinstance(value, (str, bytes)):
        return None
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    return arr if arr.ndim <= 2 else None


def _number(v: float) -> str:
    # up to 6 significant digits, no trailing ".0": 2.0 -> 2, 0.05 -> 0.05, pi -> 3.14159
    return f"{v:.6g}"


def _text_entry(key: str, value: Any) -> str:
    arr = _numbers(value)
    if arr is None:
        return f"{key} = {value!r}"
    if arr.ndim == 0:
        return f"{key} = {_number(arr)}"
    if arr.ndim == 1:
        return f"{key} = [{', '.join(_number(v) for v in arr)}]"
    cells = [[_number(v) for v in row] for row in arr]
    widths = [max(len(row[j]) for row in cells) for j in range(arr.shape[1])]
    rows = ["[" + ", ".join(c.rjust(w) for c, w in zip(row, widths)) + "]" for row in cells]
    lead = f"{key} = ["
    return lead + (",\n" + " " * len(lead)).join(rows) + "]"


def _latex_entry(value: Any) -> str:
    arr = _numbers(value)
    if arr is None:
        return f"= `{value!r}`"
    if arr.ndim == 0:
        return f"$= {_number(arr)}$"
    if arr.ndim == 1:
        # braces keep a minus sign unary: [-1, -2] and not [-1, - 2]
        return "$= [" + r",\ ".join("{" + _number(v) + "}" for v in arr) + "]$"
    rows = r" \\ ".join(" & ".join(_number(v) for v in row) for row in arr)
    return r"$= \begin{bmatrix} " + rows + r" \end{bmatrix}$"
