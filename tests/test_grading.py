"""``python -m coursekit grade``: answers are checked again outside the notebook, any submission gets a row.

One grading run (two notebooks at a time, short time limit, small memory limit)
of a folder of chapter-1 submissions:

* ``solutions``: the instructor solutions turned into code cells: all correct;
* ``student``: the untouched student edition (the whole notebook): 0;
* ``patched``: the checks replaced by ``lambda *a: True``: 0, "not answered";
* ``tampered``: the feedback helpers patched so that the real checks praise
  wrong answers: 0 (the answers are checked again by the grader);
* ``loop``, ``exit``, ``memory``, ``invalid``, ``chapter2``, ``untitled3``, ``files``: an
  endless loop (one that sleeps: the grader's limit is a time, and a spinning loop would only
  take a core from the rest of the test run for the limit's 45 s, twice), ``os._exit(3)``, a
  50 GiB allocation, invalid JSON, another chapter's notebook and cells that write and delete
  files around them: each gets its status, and the answers given before (and after) the
  accident count.

The other notebooks hold the exercise section only (not the whole chapter),
which keeps the run short; the chapter's other cells run in their own tests.
"""

from __future__ import annotations

import contextlib
import csv
import importlib.util
import json
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

from coursekit.__main__ import main
from coursekit.exercises._catalog import chapter_exercises
from coursekit.tools.grading import grade, parse_memory
from coursekit.tools.notebooks import default_notebook_dir, read_notebook
from coursekit.tools.release import student_edition
from grading_cases import SANDBOX, answer, exercise_section, solved

CHECKS = [entry.check for entry in chapter_exercises(1)]
TIMEOUT = 45      # the whole student edition must finish well inside it on a busy machine


def _submissions(folder: Path) -> None:
    instructor = read_notebook(default_notebook_dir() / "01_representations.ipynb")
    edition = student_edition(instructor)
    student = exercise_section(edition)
    right = solved(instructor)
    heading, setup = right[0], [new_code_cell("import numpy as np\nimport coursekit.exercises as ex")]
    patch = new_code_cell("for name in dir(ex):\n    if name.startswith('check_'):\n"
                          "        setattr(ex, name, lambda *a, **k: True)")
    tamper = new_code_cell("import coursekit.exercises._feedback as fb\n"
                           "fb.close = lambda a, e, rtol=0: np.ones(np.broadcast(a, e).shape, bool)\n"
                           "assert ex.check_euler_discretization([[1, 0], [0, 1]], [[0], [0]])")
    notebooks = {
        "solutions": right,
        "student": edition.cells,                       # the whole edition, untouched
        "patched": [heading, *setup, patch, *student[2:]],
        "tampered": [heading, *setup, tamper],
        "loop": [heading, *setup, *answer(right, CHECKS[0]),
                 new_code_cell("import time\nwhile True:\n    time.sleep(0.05)"), *answer(right, CHECKS[1])],
        "exit": [heading, *setup, *answer(right, CHECKS[1]), new_code_cell("import os\nos._exit(3)")],
        "memory": [heading, *setup, *answer(right, CHECKS[3]),
                   new_code_cell("big = np.ones(50 * 2**30, dtype=np.uint8)"),
                   # 3 GiB of address space, never touched: refused only under the 2G limit
                   new_code_cell("reserved = np.empty(3 * 2**30, dtype=np.uint8)"), *answer(right, CHECKS[4])],
        "chapter2": [new_markdown_cell("# Chapter 2 — Controllability"), *setup],
        "untitled3": [*setup, new_code_cell("ex.check_stability([True, True, True, True])")],
        "files": [heading, *setup, *answer(right, CHECKS[2]), new_code_cell(
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
    """The submissions folder and the output of grading it twice (the second run is compared),
    by `grade` and, at the same time, by the command an instructor types (each run spends most
    of its time waiting on the endless loop's limit); in the sandbox where bubblewrap runs, else
    without (these notebooks harm nobody)."""
    folder = tmp_path_factory.mktemp("submissions")
    _submissions(folder)
    out, again = tmp_path_factory.mktemp("grades"), tmp_path_factory.mktemp("again")
    command = subprocess.Popen(
        [sys.executable, "-m", "coursekit", "grade", "--chapter", "1", str(folder), "--out", str(again),
         "--timeout", str(TIMEOUT), "--memory", "2G", "--jobs", "2", *([] if SANDBOX else ["--no-sandbox"])],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        grade(folder, out, chapter=1, timeout=TIMEOUT, memory="2G", jobs=2, sandbox=SANDBOX)
    finally:
        printed = command.communicate()[0]
    assert command.returncode == 0, printed
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
    assert "cells 4, 5 ran out of memory (MemoryError)" in feedback     # numbered from 1, as they stand


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


def test_help_names_the_sandbox_and_the_flag_that_goes_without(capsys):
    with pytest.raises(SystemExit):
        main(["grade", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "bubblewrap" in text and "--no-sandbox" in text and "with your own rights" in text


def test_an_empty_folder_still_writes_the_grade_book(tmp_path):
    (tmp_path / "subs").mkdir()
    table = grade(tmp_path / "subs", tmp_path / "out", chapter=1, jobs=1, sandbox=SANDBOX)
    assert table.read_text(encoding="utf-8").splitlines() == [",".join(["student", *CHECKS, "total", "status"])]


def test_missing_tools_name_the_extra_to_install(tmp_path, monkeypatch):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "nbclient" else real(name, *a))
    with pytest.raises(RuntimeError, match=r"nbclient.*coursekit\[grade\]"):
        grade(tmp_path, tmp_path / "out", chapter=1)


def test_a_kernel_that_fails_to_start_once_is_started_again(monkeypatch, tmp_path):
    """A kernel start that fails once (a busy machine) must not cost an honest student the chapter."""
    from coursekit.tools.grading import runner
    starts = []

    class Client:
        @contextlib.contextmanager
        def setup_kernel(self, **kwargs):
            starts.append(kwargs)
            if len(starts) == 1:
                raise RuntimeError("Kernel died before replying to kernel_info")
            yield

    monkeypatch.setattr(runner, "_client", lambda *args: Client())
    client, kernel = runner._started(None, {}, tmp_path, time.monotonic() + 60)
    with kernel:
        assert isinstance(client, Client)
    assert len(starts) == runner.STARTS == 2
    starts.clear()
    monkeypatch.setattr(runner, "STARTS", 1)
    with pytest.raises(RuntimeError, match="kernel_info"):
        runner._started(None, {}, tmp_path, time.monotonic() + 60)


@pytest.mark.parametrize("printed", ['{"status": "excellent", "detail": "", "errors": []}', "not json", "",
                                     '{"status": "ok"}', '["ok"]', '{"status": "grader error", "detail": "", '
                                     '"errors": []}'])
def test_only_the_runners_own_outcomes_are_accepted(printed):
    from coursekit.tools.grading.grader import _runner_outcome
    assert _runner_outcome(f"noise\n{printed}\n", 0)["status"] == "crashed"
    good = _runner_outcome('{"status": "cell error", "detail": "d", "errors": [{"cell": 2, "ename": "E", '
                           '"evalue": "m"}, {"cell": "x"}]}', 0)
    assert good == {"status": "cell error", "detail": "d", "errors": [{"cell": 2, "ename": "E", "evalue": "m"}]}


def test_the_runner_refuses_only_the_iri_grammar_and_still_validates_notebooks():
    """jsonschema's ``iri`` format (rfc3987-syntax's grammar, 1 s of a core on import) stays out
    of the runner's process; nbformat and nbclient work as before."""
    if importlib.util.find_spec("rfc3987_syntax") is None:
        pytest.skip("rfc3987-syntax is not installed here: there is no grammar to leave out")
    code = ("import sys\nfrom coursekit.tools.notebooks import leave_out_the_iri_grammar\n"
            "leave_out_the_iri_grammar()\nimport jsonschema, nbclient, nbformat\n"
            "nbformat.validate(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell('1 + 1')]))\n"
            "print(sys.modules['rfc3987_syntax'], 'iri' in jsonschema.FormatChecker.checkers,\n"
            "      'email' in jsonschema.FormatChecker.checkers)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["None", "False", "True"], out


def test_the_runner_leaves_out_the_iri_grammar_before_it_runs_the_notebook(monkeypatch, tmp_path):
    from coursekit.tools.grading import runner
    calls = []
    monkeypatch.setattr(runner, "leave_out_the_iri_grammar", lambda: calls.append("left out"))
    monkeypatch.setattr(runner, "set_limits", lambda *limits: None)      # not on the test's own process
    monkeypatch.setattr(runner, "execute", lambda job, kernels: calls.append("executed") or
                        {"status": "ok", "detail": "", "errors": []})
    job = tmp_path / "job.json"
    job.write_text(json.dumps({"memory": 2**30}), encoding="utf-8")
    assert runner.main([str(job)]) == 0
    assert calls == ["left out", "executed"]


def test_feedback_is_caught_per_thread():
    """Two students' answers checked at once keep their own feedback (no process-wide redirect)."""
    from concurrent.futures import ThreadPoolExecutor

    from coursekit.tools.grading import grade_answers
    exercises = chapter_exercises(1)[:1]
    answers = {"right": {"A": [[0, 1], [-4, -0.2]], "B": [[0], [0.5]], "C": [[1, 0]]},
               "wrong": {"A": [[0, 1], [4, 0.2]], "B": [[0], [1]], "C": [[0, 1]]}}
    alone = {name: grade_answers({CHECKS[0]: args}, exercises) for name, args in answers.items()}
    assert alone["right"][0][CHECKS[0]] == 1 and alone["wrong"][0][CHECKS[0]] == 0
    with ThreadPoolExecutor(max_workers=2) as pool:
        together = list(pool.map(lambda name: (name, grade_answers({CHECKS[0]: answers[name]}, exercises)),
                                 ["right", "wrong"] * 100))
    assert all(result == alone[name] for name, result in together)
