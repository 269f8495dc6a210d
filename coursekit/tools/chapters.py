"""The course's chapters, as the tools and the tests read them from the one registry.

A chapter is a notebook ``NN_name.ipynb`` in ``notebooks/`` (`coursekit.tools.notebooks` finds
them) and, when it has them, a module ``chN`` in `coursekit.explorers` and one in
`coursekit.exercises`, found by `coursekit._chapters` (which `coursekit.exercises` reads too).
The tests, the benchmarks, the release, the website, the slides and the grader take the chapters
from there, so a fifth chapter is picked up by all of them without an edit.
"""

from __future__ import annotations

from .._chapters import chapter_modules, check_functions, exercises, explorer_factories

__all__ = ["chapter_modules", "explorer_factories", "check_functions", "exercises"]
