"""The course's chapters, found rather than listed: the one registry of chapters and exercises.

Chapter N's explorers are the module ``chN`` of `coursekit.explorers` (an explorer is a public
function named ``*_explorer``), its exercises the module ``chN`` of `coursekit.exercises` (an
exercise is a public check declared with `coursekit.exercises.exercise`, which gives it its
`Exercise` record as the attribute ``exercise``). `coursekit.exercises` (its names, `progress`,
`chapter_exercises`), the tools (`coursekit.tools.chapters`, the grader), the tests and the
command line all read the chapters here, so a new chapter's files are all it needs.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from typing import Callable

__all__ = ["chapter_modules", "explorer_factories", "check_functions", "exercises"]


def chapter_modules(package: str) -> list:
    """The modules ``chN`` of `package` (``"explorers"`` or ``"exercises"``), by N."""
    if package not in ("explorers", "exercises"):
        raise ValueError(f"package must be 'explorers' or 'exercises': received {package!r}.")
    parent = importlib.import_module(f"coursekit.{package}")
    found = [(int(m.group(1)), info.name) for info in pkgutil.iter_modules(parent.__path__)
             if (m := re.fullmatch(r"ch(\d+)", info.name))]
    return [importlib.import_module(f"{parent.__name__}.{name}") for _, name in sorted(found)]


def _public(package: str, keep: Callable) -> dict[str, Callable]:
    """``{"chN.name": function}`` for the public functions of each chapter module that `keep`."""
    return {f"{module.__name__.rsplit('.', 1)[1]}.{name}": value for module in chapter_modules(package)
            for name in module.__all__ if inspect.isfunction(value := getattr(module, name)) and keep(name, value)}


def explorer_factories() -> dict[str, Callable]:
    """Every explorer of the course: ``{"ch1.euler_explorer": euler_explorer, ...}``."""
    return _public("explorers", lambda name, _: name.endswith("_explorer"))


def check_functions() -> dict[str, Callable]:
    """Every exercise check of the course: ``{"ch1.check_msd_state_space": ..., ...}``."""
    return _public("exercises", lambda _, check: hasattr(check, "exercise"))


def exercises() -> dict[int, list]:
    """``{N: the `Exercise` records of chapter N, by label}`` for the chapters that have exercises."""
    chapters: dict[int, list] = {}
    for check in check_functions().values():
        chapters.setdefault(check.exercise.chapter, []).append(check.exercise)
    return {n: sorted(found, key=lambda e: tuple(map(int, e.label.split(".")))) for n, found in sorted(chapters.items())}
