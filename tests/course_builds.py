"""The course's website and slides, built once per test session for every test that reads them
(the session fixture ``course_builds`` of tests/conftest.py, a `CourseBuilds`).

* `site`: both editions of the website from one execution of the chapters, as
  ``python -m coursekit site --out DIR --student-out DIR`` builds them (tests/test_site_browser.py
  opens them in Chromium; tests/test_build_structure.py compares what they show with its record);
* `slides`: the slides of the whole course, built by `build_slides` (what ``python -m coursekit
  slides`` calls), the chapters the session executed already replayed rather than executed again
  (its `execute` argument, `executed_chapters.replaying`; tests/test_slides.py,
  tests/test_build_structure.py).

Each is built when a test first asks for it; the tests skip themselves when a tool is missing.
"""

from __future__ import annotations

import time
from pathlib import Path

from coursekit.__main__ import main
from coursekit.tools.slideshow import build_slides
from executed_chapters import ExecutedChapters, replaying

__all__ = ["CourseBuilds"]


class CourseBuilds:
    """Lazily built website and slides of the course, in folders of the session's temp area."""

    def __init__(self, tmp_path_factory, executed_chapters: ExecutedChapters):
        self._tmp = tmp_path_factory
        self._executed = executed_chapters
        self._site: dict[str, Path] | None = None
        self._slides: Path | None = None

    def site(self) -> dict[str, Path]:
        """``{"instructor": folder, "student": folder}``: both editions, siblings of one folder."""
        if self._site is None:
            base = self._tmp.mktemp("site")
            site = {"instructor": base / "instructor", "student": base / "student"}
            start = time.monotonic()
            assert main(["site", "--out", str(site["instructor"]), "--student-out", str(site["student"])]) == 0
            print(f"\nboth editions of the site built in {time.monotonic() - start:.0f} s")
            self._site = site
        return self._site

    def slides(self) -> Path:
        """The folder of the whole course's slides."""
        if self._slides is None:
            out = self._tmp.mktemp("slides") / "slides"
            start = time.monotonic()
            build_slides(out, verbose=True, execute=replaying(self._executed))
            print(f"\nslides of the course built in {time.monotonic() - start:.0f} s")
            self._slides = out
        return self._slides
