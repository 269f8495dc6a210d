"""The four builds an instructor runs, compared with what they wrote before the notebook plumbing
moved into one module (coursekit.tools.notebooks) and the student website came from the full
edition's execution: ``python -m coursekit release``, ``grade`` (chapter 1: the student edition,
the instructor edition and a solved copy), ``site`` with both editions at once (``--student-out``)
and ``slides``.

tests/build_structure.json is the record (tests/build_structure.py says what it holds: per page
its headings, images and their ``alt``, boxes, links and visible text; per notebook its cells'
types, tags and sources; the grader's grades and feedback), written from the builds of the code
before that change. A difference names the file and what a reader would see change. When a
change is meant to change the outputs, write the record again from the new builds
(``python tests/build_structure.py tests/build_structure.json RELEASE GRADE SITE STUDENT SLIDES``).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools.notebooks import default_notebook_dir, read_notebook
from coursekit.tools.site import missing_site_tools
from coursekit.tools.slideshow import missing_slide_tools

from build_structure import PARTS, record
from grading_cases import SANDBOX, solved

RECORD = Path(__file__).with_name("build_structure.json")


def _submissions(folder: Path, release: Path) -> Path:
    """Chapter 1 as three students hand it in: untouched student edition, instructor edition, solved."""
    folder.mkdir()
    chapter = default_notebook_dir() / "01_representations.ipynb"
    shutil.copyfile(release / chapter.name, folder / "alice.ipynb")
    shutil.copyfile(chapter, folder / "bob.ipynb")
    nb = read_notebook(chapter)
    nbformat.write(nbformat.v4.new_notebook(cells=solved(nb), metadata=nb.metadata), folder / "carol.ipynb")
    return folder


@pytest.fixture(scope="module")
def built(tmp_path_factory, course_builds) -> dict:
    """The record of the four commands' outputs: the release and the grades built now, the site
    and the slides the session's (tests/course_builds.py)."""
    missing = missing_site_tools() + missing_slide_tools()
    if missing:
        pytest.skip("the site and slides extras are not installed (missing: " + ", ".join(missing) + ")")
    root = tmp_path_factory.mktemp("built")
    folders = {part: root / part for part in PARTS}
    assert main(["release", "--out", str(folders["release"])]) == 0
    subs = _submissions(root / "submissions", folders["release"])
    assert main(["grade", str(subs), "--chapter", "1", "--out", str(folders["grade"]), "--jobs", "1",
                 *([] if SANDBOX else ["--no-sandbox"])]) == 0
    site = course_builds.site()
    folders["site"], folders["student_site"] = site["instructor"], site["student"]
    folders["slides"] = course_builds.slides()
    return record(folders)


@pytest.mark.parametrize("part", PARTS)
def test_the_build_shows_what_it_showed_before(built, part):
    before, now = json.loads(RECORD.read_text(encoding="utf-8"))[part], built[part]
    assert sorted(now) == sorted(before), (f"files gone: {sorted(set(before) - set(now))}; "
                                           f"files new: {sorted(set(now) - set(before))}")
    changed = [path for path in before if now[path] != before[path]]
    assert not changed, "\n".join(f"{path}:\n  before {before[path]}\n  now    {now[path]}" for path in changed[:3])
