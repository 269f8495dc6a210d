"""Work done once per test run, however many pytest-xdist workers ask for it.

The run is spread over the cores (``-n logical --dist loadfile``, pyproject.toml); each worker is a
process with its own session fixtures. The session's executions and builds (tests/executed_chapters.py,
tests/course_builds.py) are made by the first worker that asks, into a folder all workers share,
under a file lock (the ``filelock`` package); a worker that asks later waits for the lock and
reads what the first one wrote, as files. A failed build is not tried again: every worker that
asks for it fails with its message.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import pytest
from filelock import FileLock

__all__ = ["shared_folder", "once"]

_DONE, _FAILED = ".done", ".failed"


def shared_folder(tmp_path_factory, worker_id: str) -> Path:
    """The temp folder every worker of this run shares: for an xdist worker (`worker_id`, xdist's
    fixture, is not "master") the parent of the workers' own, else the session's. (Not the
    environment's PYTEST_XDIST_WORKER: a pytest started by a worker's test inherits it.)"""
    base = tmp_path_factory.getbasetemp()
    return base.parent if worker_id != "master" else base


def once(folder: Path, build: Callable[[Path], None]) -> Path:
    """`folder`, made by ``build(folder)`` unless a worker of this run made it already (or is
    making it: then this one waits). Fails the asking test, with the first attempt's message,
    when that build raised."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    with FileLock(folder.with_name(folder.name + ".lock")):
        done, failed = folder.with_name(folder.name + _DONE), folder.with_name(folder.name + _FAILED)
        if failed.exists():
            pytest.fail(failed.read_text(encoding="utf-8"))
        if not done.exists():
            try:
                build(folder)
            except Exception as error:
                failed.write_text(f"building {folder.name} failed: {type(error).__name__}: {str(error)[:2000]}",
                                  encoding="utf-8")
                raise
            done.touch()
    return folder
