"""The course's chapters, found rather than listed.

A chapter is a notebook ``NN_name.ipynb`` in ``notebooks/`` (`coursekit.tools.notebooks` finds
them) and, when it has them, a module
``chN`` in `coursekit.explorers` (its explorers: public functions named ``*_explorer``) and
one in `coursekit.exercises` (its exercises: public functions named ``check_*``). The tests,
the benchmarks, the release, the website and the slides take the chapters from here, so a
fifth chapter is picked up by all of them without an edit.
"""

from __future__ import annotations

import inspect
from typing import Callable

from .._chapters import chapter_modules

__all__ = ["chapter_modules", "explorer_factories", "check_functions"]


def _public_functions(package: str, test: Callable[[str], bool]) -> dict[str, Callable]:
    """``{"chN.name": function}`` for the public functions of each chapter module that pass `test`."""
    out = {}
    for module in chapter_modules(package):
        chapter = module.__name__.rsplit(".", 1)[1]
        out.update({f"{chapter}.{name}": getattr(module, name) for name in module.__all__
                    if test(name) and inspect.isfunction(getattr(module, name))})
    return out


def explorer_factories() -> dict[str, Callable]:
    """Every explorer of the course: ``{"ch1.euler_explorer": euler_explorer, ...}``."""
    return _public_functions("explorers", lambda name: name.endswith("_explorer"))


def check_functions() -> dict[str, Callable]:
    """Every exercise check of the course: ``{"ch1.check_msd_state_space": ..., ...}``."""
    return _public_functions("exercises", lambda name: name.startswith("check_"))

