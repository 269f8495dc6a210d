"""docs/extending.md works as written: its blocks, run in order in a copy of the project, add an
explorer, an exercise and a fifth chapter, and the checks every chapter must pass pick the new
chapter up there.

The copy is made by `extending_doc.extend` (``python tests/extending_doc.py DEST`` makes one to run
the README's whole test command in, where this module skips itself).
"""

from __future__ import annotations

import re
import shutil
import sys
from pathlib import Path

import pytest

from extending_doc import BUILT, DOC, ROOT, doc_blocks, extend, is_extended, run_in

pytestmark = pytest.mark.skipif(is_extended(), reason="this project already holds the doc's chapter 5 "
                                "(a copy made by tests/extending_doc.py); the doc is checked on the original")


def test_the_doc_has_an_explorer_an_exercise_and_a_chapter():
    files = [body.splitlines()[0] for lang, body in doc_blocks() if body.startswith("# file: ")]
    assert files == ["# file: coursekit/explorers/ch5.py", "# file: coursekit/exercises/ch5.py",
                     "# file: tests/cases_ch5.py"]
    text = DOC.read_text(encoding="utf-8")
    for public in ("from coursekit.explorers import Explorer", "from coursekit.exercises import"):
        assert public in text
    assert not re.search(r"coursekit\.\w+\._|from \._|import _", text), "the doc uses a private name"


#: the files of chapter 5, the only ones the doc may add or change (besides what builds write)
CHAPTER_5 = {"coursekit/explorers/ch5.py", "coursekit/exercises/ch5.py", "tests/cases_ch5.py",
             "notebooks/05_lag.ipynb"}


@pytest.fixture(scope="module")
def extended(tmp_path_factory) -> Path:
    """A copy of the project with every block of the doc applied."""
    copy = tmp_path_factory.mktemp("extended") / "project"
    extend(copy)
    return copy


def test_the_new_chapter_needs_no_edit_outside_its_own_files(extended):
    def files(root: Path) -> dict:
        return {str(p.relative_to(root)): p for p in root.rglob("*") if p.is_file()
                and not BUILT & set(p.relative_to(root).parts) and not p.parent.name.endswith(".egg-info")}
    before, after = files(ROOT), files(extended)
    touched = {name for name, path in after.items()
               if name not in before or path.read_bytes() != before[name].read_bytes()}
    assert touched == CHAPTER_5, f"outside chapter 5's files: {sorted(touched - CHAPTER_5)}"


def test_the_new_chapter_is_found_by_the_course_tools(extended):
    code = ("from coursekit.tools.chapters import explorer_factories, check_functions\n"
            "from coursekit.tools.notebooks import chapter_notebooks\n"
            "import coursekit.exercises as ex\n"
            "print(sorted(explorer_factories())[-1], sorted(check_functions())[-1], "
            "chapter_notebooks('notebooks')[-1].name, [e.check for e in ex.chapter_exercises(5)])")
    result = run_in([sys.executable, "-c", code], extended, timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.split() == ["ch5.lag_explorer", "ch5.check_lag_gain", "05_lag.ipynb",
                                     "['check_lag_gain']"]
    release = run_in([sys.executable, "-m", "coursekit", "release", "--out", "build/student"], extended, timeout=120)
    assert release.returncode == 0, release.stderr[-3000:]
    assert (extended / "build" / "student" / "05_lag.ipynb").is_file()


@pytest.mark.parametrize("args", [
    ["notebooks/05_lag.ipynb", "tests/test_slides.py", "tests/test_notebooks_clean.py", "-m", "not browser"],
    ["tests/test_bad_input.py", "-k", "lag or every_public"],
    ["tests/test_explorer_frames.py", "tests/test_figure_layout.py", "-k", "lag_explorer"],
    ["tests/test_figure_style.py", "-k", "lag_explorer or 05_lag"],
], ids=["notebook and slides", "bad input", "explorer frames and layout", "colours and contrast"])
def test_the_checks_every_chapter_must_pass_pass_for_the_new_chapter(extended, args):
    """The checks the doc names, on chapter 5 (the slides without the browser, which built and
    opened every chapter's slides again: the README's whole command on a copy made by
    tests/extending_doc.py runs them)."""
    # -n 0: in one process (this run's own workers already take the cores)
    result = run_in([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "0", *args], extended,
                    timeout=900)
    assert result.returncode == 0, result.stdout[-5000:]
    assert re.search(r"\b\d+ passed", result.stdout), result.stdout[-2000:]


def test_the_checks_the_doc_runs_say_which_extra_they_need():
    text = DOC.read_text(encoding="utf-8")
    before = text[:text.index("python -m pytest notebooks/05_lag.ipynb")]
    assert '".[dev]"' in before.rsplit("```", 2)[-2], "say that pytest and the test tools come with the dev extra"


def test_the_release_command_of_the_doc_runs_after_the_instructors_guide_s(extended):
    """The instructors' guide writes build/student first; the doc's command replaces that edition."""
    shutil.rmtree(extended / "build" / "student", ignore_errors=True)   # what other tests released there
    guide = (ROOT / "docs" / "instructors.md").read_text(encoding="utf-8")
    first = re.search(r"^python -m coursekit release --out build/student$", guide, re.M)
    assert first, "docs/instructors.md no longer writes build/student"
    again = re.search(r"`python -m coursekit (release --out build/student[^`]*)`", DOC.read_text(encoding="utf-8"))
    for command in (first.group(0).split()[3:], again.group(1).split()):
        result = run_in([sys.executable, "-m", "coursekit", *command], extended, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]
    assert len(list((extended / "build" / "student").glob("0*.ipynb"))) == 5
