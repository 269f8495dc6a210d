"""What the builds of the course (the website, the slides) share before they start.

Each build executes the chapter notebooks, writes into a fresh folder and then replaces its
output folder by it. `start_build` checks the arguments they share, finds the chapters and
refuses an output folder whose replacement would delete anything but an earlier build of the
same kind (`check_out_dir`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from .notebooks import chapter_notebooks, default_notebook_dir

__all__ = ["start_build", "check_out_dir"]


def start_build(out_dir, notebooks_dir, *, timeout: int, verbose: bool,
                built_before: Callable[[Path], bool], kind: str) -> tuple[Path, list[Path]]:
    """``(out, sources)``: the absolute output folder and the chapter notebooks to build.

    `notebooks_dir` None means the repository's ``notebooks/``; `timeout` (seconds for one
    cell) must be a positive whole number and `verbose` True or False; `built_before` and `kind`
    are those of `check_out_dir`.
    """
    if not isinstance(verbose, bool):
        raise TypeError(f"verbose must be True or False, got {verbose!r}")
    if not isinstance(timeout, int) or isinstance(timeout, bool) or timeout <= 0:
        raise ValueError(f"timeout must be a positive whole number of seconds, got {timeout!r}")
    out = Path(out_dir).resolve()
    sources = chapter_notebooks(default_notebook_dir() if notebooks_dir is None else notebooks_dir)
    check_out_dir(out, sources, built_before=built_before, kind=kind)
    return out, sources


def check_out_dir(out: Path, sources: list[Path], *, built_before: Callable[[Path], bool],
                  kind: str) -> None:
    """Raise ValueError when `out` is the notebooks' folder (of `sources`), a file, or a folder
    holding anything but an earlier build (`built_before(out)` says whether it is one); `kind`
    names the build in the message ("a site", "slides")."""
    if out in [p.parent.resolve() for p in sources]:
        raise ValueError(f"out_dir {str(out)!r} is the notebooks folder; pick an empty or new folder")
    if out.exists() and not out.is_dir():
        raise ValueError(f"out_dir {str(out)!r} is a file; pick an empty or new folder")
    if out.is_dir() and any(out.iterdir()) and not built_before(out):
        raise ValueError(f"out_dir {str(out)!r} holds files that are not {kind} built before "
                         "(they would be deleted); pick an empty or new folder")
