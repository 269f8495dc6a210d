"""The chapters' modules, found rather than listed: the one registry of the course's chapters.

A chapter's explorers are the module ``chN`` of `coursekit.explorers`, its exercises the module
``chN`` of `coursekit.exercises`; `exercises`, the tools (`coursekit.tools.chapters`), the
tests and the command line take the chapters from `chapter_modules`, so a new chapter's files
are all it needs.
"""

from __future__ import annotations

import importlib
import pkgutil
import re

__all__ = ["chapter_modules"]


def chapter_modules(package: str) -> list:
    """The modules ``chN`` of `package` (``"explorers"`` or ``"exercises"``), by N."""
    if package not in ("explorers", "exercises"):
        raise ValueError(f"package must be 'explorers' or 'exercises': received {package!r}.")
    parent = importlib.import_module(f"coursekit.{package}")
    found = [(int(m.group(1)), info.name) for info in pkgutil.iter_modules(parent.__path__)
             if (m := re.fullmatch(r"ch(\d+)", info.name))]
    return [importlib.import_module(f"{parent.__name__}.{name}") for _, name in sorted(found)]
