"""The course's website and slides, built once per test run for every test that reads them
(the session fixture ``course_builds`` of tests/conftest.py, a `CourseBuilds`).

* `site`: both editions of the website from one execution of the chapters, as
  ``python -m coursekit site --out DIR --student-out DIR`` builds them (tests/test_site_browser.py
  opens them in Chromium; tests/test_build_structure.py compares what they show with its record);
* `slides`: the slides of the whole course, built by `build_slides` (what ``python -m coursekit
  slides`` calls), each chapter replayed from the session's one execution of it rather than
  executed again (its `execute` argument, `executed_chapters.replaying`; tests/test_slides.py,
  tests/test_build_structure.py).

Each is built once per run, when a test first asks for it, however many xdist workers ask; the
tests skip themselves when a tool is missing.
"""

from __future__ import annotations

import time
from pathlib import Path

from coursekit.__main__ import main
from coursekit.tools.slideshow import build_slides
from executed_chapters import ExecutedChapters, replaying
from run_once import once, shared_folder

__all__ = ["CourseBuilds"]


class CourseBuilds:
    """The website and the slides of the course, each built once per run, when a test first asks
    for it, into the run's shared folder (tests/run_once.py)."""

    def __init__(self, tmp_path_factory, worker_id: str, executed_chapters: ExecutedChapters):
        self._folder = shared_folder(tmp_path_factory, worker_id) / "builds"
        self._executed = executed_chapters

    def site(self) -> dict[str, Path]:
        """``{"instructor": folder, "student": folder}``: both editions, siblings of one folder."""
        base = once(self._folder / "site", _build_site)
        return {"instructor": base / "instructor", "student": base / "student"}

    def slides(self) -> Path:
        """The folder of the whole course's slides."""
        return once(self._folder / "slides", self._build_slides) / "slides"

    def _build_slides(self, out: Path) -> None:
        start = time.monotonic()
        build_slides(out / "slides", verbose=True, execute=replaying(self._executed))
        print(f"\nslides of the course built in {time.monotonic() - start:.0f} s")


def _build_site(out: Path) -> None:
    start = time.monotonic()
    assert main(["site", "--out", str(out / "instructor"), "--student-out", str(out / "student")]) == 0
    print(f"\nboth editions of the site built in {time.monotonic() - start:.0f} s")
