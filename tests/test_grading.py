"""``python -m coursekit grade``: answers are checked again outside the notebook, any submission gets a row.

One grading run (two notebooks at a time, short time limit, small memory limit)
of a folder of chapter-1 submissions:

* ``solutions``: the instructor solutions turned into code cells: all correct;
* ``student``: the untouched student edition (the whole notebook): 0;
* ``patched``: the checks replaced by ``lambda *a: True``: 0, "not answered";
* ``tampered``: the feedback helpers patched so that the real checks praise
  wrong answers: 0 (the answers are checked again by the grader);
* ``loop``, ``exit``, ``memory``, ``invalid``, ``chapter2``, ``untitled3``, ``files``: an
  endless loop, ``os._exit(3)``, a 50 GiB allocation, invalid JSON, another
  chapter's notebook and cells that write and delete files around them: each
  gets its status, and the answers given before (and after) the accident count.

The other notebooks hold the exercise section only (not the whole chapter),
which keeps the run short; the chapter's other cells run in their own tests.
"""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from coursekit.__main__ import main
from coursekit.exercises._catalog import chapter_exercises
from coursekit.tools.grading import grade, parse_memory
from coursekit.tools.release import default_notebook_dir, read_notebook, student_edition

SOLUTION = re.compile(r"```python\n(?P<code>.*?)\n```", re.S)
CHECKS = [entry.check for entry in chapter_exercises(1)]
TIMEOUT = 15


def _exercise_section(nb) -> list:
    """The chapter heading, an import of NumPy, and the cells of the exercise section."""
    cells = [nb.cells[0], new_code_cell("import numpy as np")]
    return cells + [cell for cell in nb.cells if cell.metadata.get("coursekit") == "exercise"]


def _solved(nb) -> list:
    """The exercise section with every solution cell turned into the code cell it shows."""
    cells = []
    for cell in _exercise_section(nb):
        if "solution" in cell.metadata.get("tags", []):
            cell = new_code_cell(SOLUTION.search(cell.source)["code"])
        cells.append(cell)
    return cells


def _answer(cells, check: str) -> list:
    """The code cell of `cells` that answers `check` (the solution: it calls the check last)."""
    return [cell for cell in cells if cell.cell_type == "code" and f"ex.{check}(" in cell.source][-1:]


def _submissions(folder: Path) -> None:
    instructor = read_notebook(default_notebook_dir() / "01_representations.ipynb")
    edition = student_edition(instructor)
    student = _exercise_section(edition)
    solved = _solved(instructor)
    heading, setup = solved[0], [new_code_cell("import numpy as np\nimport coursekit.exercises as ex")]
    patch = new_code_cell("for name in dir(ex):\n    if name.startswith('check_'):\n"
                          "        setattr(ex, name, lambda *a, **k: True)")
    tamper = new_code_cell("import coursekit.exercises._feedback as fb\n"
                           "fb.close = lambda a, e, rtol=0: np.ones(np.broadcast(a, e).shape, bool)\n"
                           "assert ex.check_euler_discretization([[1, 0], [0, 1]], [[0], [0]])")
    notebooks = {
        "solutions": solved,
        "student": edition.cells,                       # the whole edition, untouched
        "patched": [heading, *setup, patch, *student[2:]],
        "tampered": [heading, *setup, tamper],
        "loop": [heading, *setup, *_answer(solved, CHECKS[0]), new_code_cell("while True:\n    pass"),
                 *_answer(solved, CHECKS[1])],
        "exit": [heading, *setup, *_answer(solved, CHECKS[1]), new_code_cell("import os\nos._exit(3)")],
        "memory": [heading, *setup, *_answer(solved, CHECKS[3]),
                   new_code_cell("big = np.ones(50 * 2**30, dtype=np.uint8)"),
                   # 3 GiB of address space, never touched: refused only under the 2G limit
                   new_code_cell("reserved = np.empty(3 * 2**30, dtype=np.uint8)"), *_answer(solved, CHECKS[4])],
        "chapter2": [new_markdown_cell("# Chapter 2 — Controllability"), *setup],
        "untitled3": [*setup, new_code_cell("ex.check_stability([True, True, True, True])")],
        "files": [heading, *setup, *_answer(solved, CHECKS[2]), new_code_cell(
            "import os, shutil\nos.remove(os.environ['COURSEKIT_ANSWERS_FILE'])\n"
            "open('../stray.txt', 'w').write('x')\nfor entry in os.listdir('.'):\n    os.remove(entry)\n"
            "shutil.rmtree('..', ignore_errors=True)\nprint('all gone')")],
    }
    for name, cells in notebooks.items():
        nbformat.write(new_notebook(cells=cells, metadata=instructor.metadata), folder / f"{name}.ipynb")
    (folder / "invalid.ipynb").write_text('{"cells": [', encoding="utf-8")
    (folder / "notes.txt").write_text("not a notebook: ignored", encoding="utf-8")


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    """The submissions folder and the output of grading it twice (the second run is compared)."""
    folder = tmp_path_factory.mktemp("submissions")
    _submissions(folder)
    out, again = tmp_path_factory.mktemp("grades"), tmp_path_factory.mktemp("again")
    grade(folder, out, chapter=1, timeout=TIMEOUT, memory="2G", jobs=2)
    status = main(["grade", "--chapter", "1", str(folder), "--out", str(again), "--timeout", str(TIMEOUT),
                   "--memory", "2G", "--jobs", "2"])
    assert status == 0
    return folder, out, again


def _rows(out: Path) -> dict[str, dict]:
    with open(out / "grades.csv", newline="", encoding="utf-8") as file:
        return {row["student"]: row for row in csv.DictReader(file)}


def _scores(row) -> list[int]:
    return [int(row[check]) for check in CHECKS]


def test_grades_csv_has_one_sorted_row_per_notebook_and_the_columns_of_the_chapter(graded):
    _, out, _ = graded
    lines = (out / "grades.csv").read_text(encoding="utf-8").splitlines()
    assert lines[0].split(",") == ["student", *CHECKS, "total", "status"]
    students = [line.split(",")[0] for line in lines[1:]]
    assert students == sorted(students) == sorted(
        ["solutions", "student", "patched", "tampered", "loop", "exit", "memory", "chapter2", "untitled3",
         "files", "invalid"])
    assert sorted(p.stem for p in (out / "feedback").glob("*.md")) == students


def test_instructor_solutions_grade_all_correct_and_the_student_edition_zero(graded):
    rows = _rows(graded[1])
    assert _scores(rows["solutions"]) == [1] * 5 and rows["solutions"]["total"] == "5"
    assert rows["solutions"]["status"] == "ok"
    assert _scores(rows["student"]) == [0] * 5 and rows["student"]["status"] == "ok"


def test_checks_patched_in_the_notebook_award_nothing(graded):
    rows = _rows(graded[1])
    assert _scores(rows["patched"]) == [0] * 5 and rows["patched"]["total"] == "0"
    feedback = (graded[1] / "feedback" / "patched.md").read_text(encoding="utf-8")
    assert feedback.count("Not answered") == 5
    # the tampered notebook's own kernel printed "Correct"; the grader checks the answer again
    assert rows["tampered"]["status"] == "ok" and _scores(rows["tampered"]) == [0] * 5
    tampered = (graded[1] / "feedback" / "tampered.md").read_text(encoding="utf-8")
    assert "Not yet (Euler discretization)" in tampered


@pytest.mark.parametrize("student, status, scores", [
    ("loop", "timeout", [1, 0, 0, 0, 0]),        # answered before the loop, not after
    ("exit", "crashed", [0, 1, 0, 0, 0]),
    ("memory", "memory", [0, 0, 0, 1, 1]),       # the cell fails, the notebook goes on
    ("invalid", "invalid notebook", [0] * 5),
    ("chapter2", "wrong chapter", [0] * 5),
    ("untitled3", "wrong chapter", [0] * 5),       # no title, but it calls chapter 3's checks
    ("files", "ok", [0, 0, 1, 0, 0]),            # its answers file deleted, its folder removed
])
def test_each_accident_gets_its_status_and_keeps_the_answers_given(graded, student, status, scores):
    row = _rows(graded[1])[student]
    assert (row["status"], _scores(row)) == (status, scores)
    assert int(row["total"]) == sum(scores)


def test_the_memory_limit_applies_to_the_kernel(graded):
    feedback = (graded[1] / "feedback" / "memory.md").read_text(encoding="utf-8")
    assert "cells 3, 4 ran out of memory (MemoryError)" in feedback


def test_feedback_is_what_the_checks_say_never_the_solution(graded):
    feedback = (graded[1] / "feedback" / "student.md").read_text(encoding="utf-8")
    # the untouched edition called each check with its placeholders: no answer, so no verdict
    assert "Status: **ok**" in feedback and "Not yet" not in feedback and "is empty (None)" not in feedback
    assert feedback.count("Not answered") == 5
    solved = (graded[1] / "feedback" / "solutions.md").read_text(encoding="utf-8")
    assert solved.count("Correct:") == 5 and "Score: 5 of 5" in solved
    for text in (feedback, solved):
        assert "```python" not in text and "[[0, 1], [-4" not in text


def test_grading_again_gives_the_same_files(graded):
    _, out, again = graded
    assert (out / "grades.csv").read_bytes() == (again / "grades.csv").read_bytes()
    for path in (out / "feedback").glob("*.md"):
        assert path.read_bytes() == (again / "feedback" / path.name).read_bytes()


def test_the_submissions_folder_is_left_as_it_was(graded):
    folder = graded[0]
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        [f"{name}.ipynb" for name in ("solutions", "student", "patched", "tampered", "loop", "exit", "memory",
                                      "chapter2", "untitled3", "files", "invalid")] + ["notes.txt"])


def test_bad_arguments_name_the_argument(tmp_path):
    with pytest.raises(ValueError, match="submissions"):
        grade(tmp_path / "missing", tmp_path / "out", chapter=1)
    with pytest.raises(ValueError, match="chapter 9"):
        grade(tmp_path, tmp_path / "out", chapter=9)
    with pytest.raises(ValueError, match="timeout"):
        grade(tmp_path, tmp_path / "out", chapter=1, timeout=0)
    with pytest.raises(ValueError, match="jobs"):
        grade(tmp_path, tmp_path / "out", chapter=1, jobs=0)
    with pytest.raises(ValueError, match="memory"):
        parse_memory("lots")
    assert parse_memory("2G") == 2 * 2**30 and parse_memory("512M") == 512 * 2**20


def test_help_says_it_is_not_a_sandbox(capsys):
    with pytest.raises(SystemExit):
        main(["grade", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "not a sandbox" in text and "docker run" in text


def test_an_empty_folder_still_writes_the_grade_book(tmp_path):
    (tmp_path / "subs").mkdir()
    table = grade(tmp_path / "subs", tmp_path / "out", chapter=1, jobs=1)
    assert table.read_text(encoding="utf-8").splitlines() == [",".join(["student", *CHECKS, "total", "status"])]


def test_recorded_answers_are_data_only():
    """A forged answers line cannot run code in the grader: it decodes to plain data."""
    from coursekit.exercises._answers import decode
    forged = json.loads('{"opaque": "os.system(\'echo hi\')", "sympy_symbol": "__import__(\'os\')"}')
    value = decode(forged)
    assert type(value).__name__ == "Symbol" and str(value) == "__import__('os')"


def test_missing_tools_name_the_extra_to_install(tmp_path, monkeypatch):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "nbclient" else real(name, *a))
    with pytest.raises(RuntimeError, match=r"nbclient.*coursekit\[grade\]"):
        grade(tmp_path, tmp_path / "out", chapter=1)
