"""docs/extending.md works as written: its blocks, run in order in a copy of the project, add an
explorer, an exercise and a fifth chapter, and the checks every chapter must pass pick the new
chapter up there.

A ``python`` block whose first line is ``# file: PATH`` is written to PATH; every other
``python`` block runs, in order, in one interpreter started at the copy's root.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "extending.md"
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)


def _blocks() -> list[tuple[str, str]]:
    return [(lang, body) for lang, body in BLOCK.findall(DOC.read_text(encoding="utf-8"))]


def _copy_project(to: Path) -> None:
    """The project's files as a fresh clone has them (no caches, builds or git data)."""
    ignore = shutil.ignore_patterns(".git", "__pycache__", "*.egg-info", ".hypothesis", "build", "site",
                                    "site-student", ".ipynb_checkpoints", ".venv")
    shutil.copytree(ROOT, to, ignore=ignore)


def _run(args: list[str], cwd: Path, timeout: int) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(cwd), MPLBACKEND="Agg")
    return subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def test_the_doc_has_an_explorer_an_exercise_and_a_chapter():
    files = [body.splitlines()[0] for lang, body in _blocks() if body.startswith("# file: ")]
    assert files == ["# file: coursekit/explorers/ch5.py", "# file: coursekit/exercises/ch5.py"]
    text = DOC.read_text(encoding="utf-8")
    for public in ("from coursekit.explorers import Explorer", "from coursekit.exercises import"):
        assert public in text
    assert not re.search(r"coursekit\.\w+\._|from \._|import _", text), "the doc uses a private name"


@pytest.fixture(scope="module")
def extended(tmp_path_factory) -> Path:
    """A copy of the project with every block of the doc applied."""
    copy = tmp_path_factory.mktemp("extended") / "project"
    _copy_project(copy)
    script = []
    for lang, body in _blocks():
        if lang != "python":
            continue
        if body.startswith("# file: "):
            path = copy / body.splitlines()[0].removeprefix("# file: ").strip()
            path.write_text(body.split("\n", 1)[1], encoding="utf-8")
        else:
            script.append(body)
    (copy / "extending_blocks.py").write_text("\n\n".join(script), encoding="utf-8")
    result = _run([sys.executable, "extending_blocks.py"], copy, timeout=600)
    assert result.returncode == 0, f"the doc's blocks failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    (copy / "extending_blocks.py").unlink()
    return copy


def test_the_new_chapter_is_found_by_the_course_tools(extended):
    code = ("from coursekit.tools.chapters import explorer_factories, check_functions\n"
            "from coursekit.tools.notebooks import chapter_notebooks\n"
            "import coursekit.exercises as ex\n"
            "print(sorted(explorer_factories())[-1], sorted(check_functions())[-1], "
            "chapter_notebooks('notebooks')[-1].name, [e.check for e in ex.chapter_exercises(5)])")
    result = _run([sys.executable, "-c", code], extended, timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.split() == ["ch5.lag_explorer", "ch5.check_lag_gain", "05_lag.ipynb",
                                     "['check_lag_gain']"]
    release = _run([sys.executable, "-m", "coursekit", "release", "--out", "build/student"], extended, timeout=120)
    assert release.returncode == 0, release.stderr[-3000:]
    assert (extended / "build" / "student" / "05_lag.ipynb").is_file()


@pytest.mark.parametrize("args", [
    ["notebooks/05_lag.ipynb", "tests/test_slides.py", "tests/test_notebooks_clean.py"],
    ["tests/test_bad_input.py", "-k", "lag or every_public"],
    ["tests/test_explorer_frames.py", "tests/test_figure_layout.py", "-k", "lag_explorer"],
    ["tests/test_figure_style.py", "-k", "lag_explorer or 05_lag"],
], ids=["notebook and slides", "bad input", "explorer frames and layout", "colours and contrast"])
def test_the_checks_every_chapter_must_pass_pass_for_the_new_chapter(extended, args):
    result = _run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args], extended, timeout=900)
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
        result = _run([sys.executable, "-m", "coursekit", *command], extended, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]
    assert len(list((extended / "build" / "student").glob("0*.ipynb"))) == 5
