"""``ex.progress(chapter)`` and the recording of answers for the grader.

* progress lists the chapter's exercises (as the notebooks number and call
  them) with "not tried", "not yet" or "correct" from the last answer, and
  shows no answer;
* with ``COURSEKIT_ANSWERS_FILE`` set, every check appends its answer, and the
  answer read back and checked again gives the same verdict and the same
  feedback as in the notebook, also for a function given as the answer.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import coursekit.exercises as ex
from coursekit.tools.chapters import check_functions, exercises
from coursekit.exercises._answers import ANSWERS_ENV, decode, read_last_records
from coursekit.exercises._catalog import STATE
from coursekit.exercises._progress import CORRECT, NOT_TRIED, NOT_YET

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("0*.ipynb"))
MSD_RIGHT = ([[0, 1], [-4, -0.2]], [[0], [0.5]], [[1, 0]])


@pytest.fixture(autouse=True)
def fresh_session():
    """Each test starts with no exercise tried (and leaves the session as it found it)."""
    saved = dict(STATE)
    STATE.clear()
    yield
    STATE.clear()
    STATE.update(saved)


def _quiet(call, *args):
    with contextlib.redirect_stdout(io.StringIO()) as printed:
        result = call(*args)
    return result, printed.getvalue()


def _states(chapter) -> dict[str, str]:
    return {entry.check: state for entry, state in ex.progress(chapter).rows}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_the_catalog_is_the_notebook_exercises_in_order(path):
    cells = ["".join(c["source"]) for c in json.loads(path.read_text(encoding="utf-8"))["cells"]]
    labels = re.findall(r"^### Exercise (\d+\.\d+):", "\n".join(cells), re.M)
    chapter = int(path.name[:2])
    assert labels == [e.label for e in ex.chapter_exercises(chapter)]
    called = [m for c in cells if not c.startswith("<details>") for m in re.findall(r"ex\.(check_\w+)\(", c)]
    assert list(dict.fromkeys(called)) == [e.check for e in ex.chapter_exercises(chapter)]
    assert f"ex.progress({chapter})" in cells[-1], "the last cell shows the chapter's progress"


def test_states_follow_the_last_answer():
    assert set(_states(1).values()) == {NOT_TRIED}
    _quiet(ex.check_msd_state_space, None, None, None)               # the untouched placeholders
    assert _states(1)["check_msd_state_space"] == NOT_TRIED
    _quiet(ex.check_msd_state_space, *MSD_RIGHT)
    assert _states(1)["check_msd_state_space"] == CORRECT
    _quiet(ex.check_msd_state_space, None, None, None)               # no answer: the last one stays
    assert _states(1)["check_msd_state_space"] == CORRECT
    _quiet(ex.check_msd_state_space, [[1]], None, None)              # partly filled in: an answer
    assert _states(1)["check_msd_state_space"] == NOT_YET
    assert list(_states(1).values()).count(NOT_TRIED) == 4


def _answer_cells(path):
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    return ["".join(c["source"]) for c in cells if c["cell_type"] == "code"
            and c["metadata"].get("coursekit") == "exercise" and re.search(r"ex\.check_\w+\(", "".join(c["source"]))]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_run_all_on_a_fresh_chapter_leaves_every_exercise_not_tried_and_unanswered(path, tmp_path, monkeypatch):
    """Run All calls each check with its placeholders: the check says what to do, and the
    exercise stays "not tried" in the progress overview and unanswered in the grader's file."""
    answers = tmp_path / "answers.jsonl"
    monkeypatch.setenv(ANSWERS_ENV, str(answers))
    cells = _answer_cells(path)
    assert len(cells) == len(ex.chapter_exercises(int(path.name[:2])))
    for source in cells:
        with contextlib.redirect_stdout(io.StringIO()) as printed:
            exec(source, {"ex": ex, "display": lambda *objects: None})      # as the notebook runs it
        assert printed.getvalue().startswith("Not yet"), printed.getvalue()
    shown = ex.progress(int(path.name[:2]))
    assert set(_states(int(path.name[:2])).values()) == {NOT_TRIED}, repr(shown)
    assert shown.summary().endswith(f"0 of {len(cells)} exercises correct, 0 not yet, {len(cells)} not tried")
    assert not answers.exists() or read_last_records(answers) == {}


@pytest.mark.parametrize("placeholder", [None, ..., [None, None, None, None], (None,)])
def test_a_placeholder_is_no_answer(placeholder, tmp_path, monkeypatch):
    monkeypatch.setenv(ANSWERS_ENV, str(tmp_path / "answers.jsonl"))
    result, printed = _quiet(ex.check_stability, placeholder)
    assert not result and printed.startswith("Not yet")
    assert _states(3)["check_stability"] == NOT_TRIED
    assert not (tmp_path / "answers.jsonl").exists()


def _untouched(x, u):
    return None   # [theta', theta'']


def _forgot_the_return(x, u):
    x[1] + u[0]


def test_an_untouched_function_is_no_answer_but_one_with_a_body_is(tmp_path, monkeypatch):
    monkeypatch.setenv(ANSWERS_ENV, str(tmp_path / "answers.jsonl"))
    _quiet(ex.check_pendulum_f, _untouched)
    assert _states(1)["check_pendulum_f"] == NOT_TRIED and not (tmp_path / "answers.jsonl").exists()
    result, printed = _quiet(ex.check_pendulum_f, _forgot_the_return)
    assert not result and "return" in printed
    assert _states(1)["check_pendulum_f"] == NOT_YET
    assert list(read_last_records(tmp_path / "answers.jsonl")) == ["check_pendulum_f"]


def test_a_replaced_check_changes_nothing(monkeypatch):
    monkeypatch.setattr(ex, "check_ctrb_matrix", lambda *a: True)
    ex.check_ctrb_matrix([[1]])
    assert _states(2)["check_ctrb_matrix"] == NOT_TRIED


def test_text_and_html_show_sections_and_states_but_no_answer():
    _quiet(ex.check_msd_state_space, *MSD_RIGHT)
    _quiet(ex.check_compartment_state_space, [[1, 2], [3, 4]], None, None)
    shown = ex.progress(1)
    text, page = repr(shown), shown._repr_html_()
    assert text.startswith("Chapter 1: 1 of 5 exercises correct, 1 not yet, 3 not tried")
    for entry in ex.chapter_exercises(1):
        assert entry.label in text and entry.section in text and entry.section in page
    assert "correct" in page and "not yet" in page and "not tried" in page and "<table" in page
    for answer in ("-4", "0.5", "-0.2", "[[1, 2]"):
        assert answer not in text and answer not in page


def _chapters() -> list[int]:
    """The chapters with exercises, from the course's one registry (a fifth one added by docs/extending.md too)."""
    return list(exercises())


def test_the_exercises_are_the_declared_checks_of_their_chapter_modules():
    """One registry: each check of a module chN is an exercise of chapter N under its own name, and
    every exercise `progress` and the grader list is such a check."""
    checks = check_functions()
    assert {f"ch{e.chapter}.{e.check}" for found in exercises().values() for e in found} == set(checks)
    assert all(check.exercise.check == label.split(".")[1] for label, check in checks.items())
    assert [e.check for e in ex.chapter_exercises(2)] == [name for name in ex.ch2.__all__ if name.startswith("check_")]


def test_every_chapter_when_none_is_given():
    shown = [e.chapter for e, _ in ex.progress().rows]
    assert shown == [n for n in _chapters() for _ in ex.chapter_exercises(n)]
    assert shown[:18] == [1] * 5 + [2] * 5 + [3] * 4 + [4] * 4      # the course's own four chapters


@pytest.mark.parametrize("chapter, error", [(9, ValueError), (0, ValueError), ("1", TypeError), (1.0, TypeError),
                                             (True, TypeError)])
def test_a_bad_chapter_says_which_exist(chapter, error):
    with pytest.raises(error, match=r"chapter.*\[" + ", ".join(map(str, _chapters())) + r"\]"):
        ex.progress(chapter)


def _pendulum_f(x, u):
    p = ex.PENDULUM
    return [x[1], -p["g"] / p["l"] * np.sin(x[0]) - p["d_theta"] / p["m"] * x[1] + u[0] / (p["m"] * p["l"] ** 2)]


def _raises(x, u):
    raise ZeroDivisionError("no")


ANSWERS = [
    ("check_msd_state_space", MSD_RIGHT),
    ("check_msd_state_space", (np.array([[0, 1], [-8, -0.4]]), "B", None)),
    ("check_ctrb_matrix", (sp.Matrix([[1, sp.Symbol("a")]]),)),
    ("check_pendulum_f", (_pendulum_f,)),
    ("check_pendulum_f", (lambda x, u: np.array([x[1], 0.0]),)),
    ("check_pendulum_f", (_raises,)),
    ("check_stability", (np.array([1, 0, 0, 1]) == 1,)),
    ("check_separation_poles", ([1 + 2j, 1 - 2j, -1, 3],)),
    ("check_kalman_decision", (sp.Integer(2), np.False_)),
    ("check_gain_ccf", ({"K": 1},)),
]


def test_recorded_answers_check_again_to_the_same_feedback(tmp_path, monkeypatch):
    for number, (name, args) in enumerate(ANSWERS):
        path = tmp_path / f"answers{number}.jsonl"
        monkeypatch.setenv(ANSWERS_ENV, str(path))
        result, printed = _quiet(getattr(ex, name), *args)
        recorded = read_last_records(path)
        assert list(recorded) == [name]
        again, printed_again = _quiet(getattr(ex, name).__wrapped__, *(decode(v) for v in recorded[name].values()))
        assert (bool(again), printed_again) == (bool(result), printed), name


def test_nothing_is_recorded_without_the_variable(tmp_path, monkeypatch):
    monkeypatch.delenv(ANSWERS_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    _quiet(ex.check_msd_state_space, *MSD_RIGHT)
    assert list(tmp_path.iterdir()) == []


def test_unreadable_lines_are_skipped(tmp_path):
    path = tmp_path / "answers.jsonl"
    path.write_text('not json\n{"check": 3}\n[1]\n' + "[" * 100_000 + "\n"
                    '{"check": "check_ctrb_matrix", "args": {"Wc": [[1]]}}\n', encoding="utf-8")
    assert read_last_records(path) == {"check_ctrb_matrix": {"Wc": [[1]]}}
