"""The four builds an instructor runs, compared with what they wrote before the notebook plumbing
moved into one module (coursekit.tools.notebooks) and the student website came from the full
edition's execution: ``python -m coursekit release``, ``grade`` (chapter 1: the student edition,
the instructor edition and a solved copy), ``site`` with both editions at once (``--student-out``)
and ``slides``.

tests/build_structure.json is the record (tests/build_structure.py says what it holds: per page
its headings, images and their ``alt``, boxes, links and visible text; per notebook its cells'
types, tags and sources; the grader's grades and feedback; the chapters it was built from),
written from the builds of the code before that change. A difference names the file and what a
reader would see change. When a change is meant to change the outputs, write the record again
from the new builds
(``python tests/build_structure.py tests/build_structure.json RELEASE GRADE SITE STUDENT SLIDES``).

A chapter the record does not know (one added as docs/extending.md shows) is compared by the
rule every recorded chapter's outputs follow: the same kinds of file (its notebook, page,
download, slides; explorer frames numbered from 0 and figures, as many as it has), an entry on
every page that lists all the recorded chapters; without those files and entries, the build shows
exactly what the record holds.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools.notebooks import chapter_notebooks, default_notebook_dir, read_notebook
from coursekit.tools.site import missing_site_tools
from coursekit.tools.slideshow import missing_slide_tools

from build_structure import PARTS, chapter_files, listed, structure, template
from grading_cases import SANDBOX, solved

RECORD = Path(__file__).with_name("build_structure.json")
#: a kind of file a chapter has as many of as it has explorers, frames or figures (zero or more)
_COUNTED = ("{n}", "{i}", "{image}")


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
    """The folders of the four commands' outputs: the release and the grades built now, the site
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
    return folders


def _recorded() -> dict:
    return json.loads(RECORD.read_text(encoding="utf-8"))


def _new_chapters(recorded: dict) -> list[str]:
    """The course's chapters (its notebooks) that the record does not know."""
    return [p.stem for p in chapter_notebooks(default_notebook_dir()) if p.stem not in recorded["chapters"]]


@pytest.mark.parametrize("part", PARTS)
def test_the_build_shows_what_it_showed_before(built, part):
    recorded = _recorded()
    new = _new_chapters(recorded)
    before, now = recorded[part], structure(built[part], leave_out=new)
    theirs = set().union(*(chapter_files(now, chapter) for chapter in new))
    now = {path: summary for path, summary in now.items() if path not in theirs}
    assert sorted(now) == sorted(before), (f"files gone: {sorted(set(before) - set(now))}; "
                                           f"files new: {sorted(set(now) - set(before))}")
    changed = [path for path in before if now[path] != before[path]]
    assert not changed, "\n".join(f"{path}:\n  before {before[path]}\n  now    {now[path]}" for path in changed[:3])


def _kinds(summaries: dict, chapter: str) -> set:
    return {template(path, chapter) for path in chapter_files(summaries, chapter)}


def _frames_from_0(paths: set) -> bool:
    """Every explorer's frames (``{chapter}-{n}/{i}.webp``) are numbered 0, 1, ... without a gap."""
    frames = {}
    for path in paths:
        folder, _, name = path.rpartition("/")
        if name.split(".")[0].isdigit() and folder.rsplit("-", 1)[-1].isdigit():
            frames.setdefault(folder, set()).add(int(name.split(".")[0]))
    return all(numbers == set(range(len(numbers))) for numbers in frames.values())


@pytest.mark.parametrize("part", PARTS)
def test_every_chapter_has_what_every_recorded_chapter_has(built, part):
    """Each chapter of the course, recorded or not, has the files of the kinds each recorded chapter
    has, and an entry on every page that lists all the recorded chapters."""
    recorded = _recorded()
    kinds = [_kinds(recorded[part], chapter) for chapter in recorded["chapters"]]
    fixed = [{k for k in ks if not any(c in k for c in _COUNTED)} for ks in kinds]
    assert kinds and all(f == fixed[0] for f in fixed), "the recorded chapters have different kinds of file"
    chapters = [p.stem for p in chapter_notebooks(default_notebook_dir())]
    now, pages = structure(built[part]), listed(built[part], chapters)
    for chapter in chapters:
        mine = chapter_files(now, chapter)
        has = {k for k in _kinds(now, chapter) if not any(c in k for c in _COUNTED)}
        assert has == fixed[0], f"{chapter}: missing {sorted(fixed[0] - has)}, more {sorted(has - fixed[0])}"
        assert _kinds(now, chapter) <= set().union(*kinds), f"{chapter}: files of a kind no chapter had"
        assert _frames_from_0(mine), f"{chapter}: an explorer's frames are not numbered 0, 1, ..."
        for page, links in pages.items():
            if page not in mine and set(recorded["chapters"]) - {Path(page).stem} <= set(links["linked"]):
                assert links["entries"].get(chapter), f"{page} does not list {chapter}"
