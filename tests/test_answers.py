"""The answers file as the grader reads it: data only, bounded, the last record found, honest
answers recorded as the checks see them (`coursekit.exercises._answers`).

Each test below is an attack or an honest answer that broke the grader before: a string that
sympy would have run, a record of a quarter of a million objects, an answer behind 10,000
records or 64 Mi characters, and answers given as ``np.matrix`` or an object with
``__array__``.
"""

from __future__ import annotations

import contextlib
import io
import json
import tracemalloc

import numpy as np
import pytest
import sympy as sp

import coursekit.exercises as ex
from coursekit.exercises._answers import (ANSWERS_ENV, MAX_LINE, Opaque, Replay, decode, encode,
                                          read_last_records)
from coursekit.exercises._feedback import feedback_to

MSD_RIGHT = ([[0, 1], [-4, -0.2]], [[0], [0.5]], [[1, 0]])


def _check(name: str, *args):
    """(verdict, feedback) of a course check called as in a notebook."""
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = getattr(ex, name)(*args)
    return bool(result), printed.getvalue()


def _regrade(path, name: str):
    """(verdict, feedback) of the course's own check on the last answer recorded in `path`."""
    printed = io.StringIO()
    arguments = read_last_records(path)[name]
    with feedback_to(printed):
        result = getattr(ex, name).__wrapped__(**{k: decode(v) for k, v in arguments.items()})
    return bool(result), printed.getvalue()


@pytest.mark.parametrize("text", ["__import__('os').system('touch pwned')", "exec('1')", "x + 1", "1"])
def test_text_in_a_sympy_matrix_is_never_parsed(tmp_path, text):
    """sympy.Matrix parses strings with eval: a forged matrix of text must not reach it."""
    marker = tmp_path / "ran"
    forged = {"sympy_matrix": [[f"__import__('pathlib').Path({str(marker)!r}).touch() or 1", text]]}
    value = decode(json.loads(json.dumps(forged)))
    assert not marker.exists()
    assert isinstance(value, Opaque) and type(value).__name__ == "MutableDenseMatrix"


def test_decoded_values_are_data_of_known_kinds():
    forged = json.loads('[{"opaque": "os.system(\'echo hi\')"}, {"sympy_symbol": "__import__(\'os\')"}, '
                        '"2 + 2", {"ndarray": ["1", 2], "shape": [2], "kind": "f"}, '
                        '{"ndarray": [1, 2], "shape": [3], "kind": "f"}, {"complex": ["1", 0]}, '
                        '{"tuple": 5}, {"dict": [[1, 2], [3]]}, {"no tag": 1}]')
    symbol_value, text = decode(forged)[1:3]
    assert type(symbol_value) is sp.Symbol and str(symbol_value) == "__import__('os')"
    assert text == "2 + 2"                                            # strings stay strings
    kinds = [type(v).__name__ for v in decode(forged)]
    assert kinds == ["object", "Symbol", "str", "ndarray", "ndarray", "complex", "tuple", "dict", "object"]
    assert all(isinstance(v, Opaque) for i, v in enumerate(decode(forged)) if i in (0, 3, 4, 5, 6, 8))
    assert decode(forged)[7] == {1: 2}


def test_decoding_cost_is_linear_and_makes_no_class_per_object():
    """A 1 MB record of 250,000 empty objects once took 19 s and 680 MB (a class per object)."""
    record = json.loads("[" + ",".join(["{}"] * 250_000) + "]")
    tracemalloc.start()
    value = decode(record)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert len({type(v) for v in value if isinstance(v, Opaque)}) == 1
    assert peak < 64 * 2**20                          # 250,000 small objects, not 250,000 classes
    deep = json.loads("[" * 900 + "]" * 900)
    assert isinstance(decode(deep), (list, Opaque))   # deep nesting is data or opaque, never an error


def test_the_last_record_counts_behind_10000_records_and_64_mi_characters(tmp_path, monkeypatch):
    path = tmp_path / "answers.jsonl"
    wrong = json.dumps({"check": "check_msd_state_space", "args": {"A": [[1]], "B": [[1]], "C": [[1]]}})
    with open(path, "w", encoding="utf-8") as file:
        file.write((wrong + "\n") * 10_001)
        file.write(("x" * (MAX_LINE + 10) + "\n") * 2 + ("y" * 2**20 + "\n") * 64)   # 128 Mi characters
    monkeypatch.setenv(ANSWERS_ENV, str(path))
    assert _check("check_msd_state_space", *MSD_RIGHT)[0]
    assert _regrade(path, "check_msd_state_space")[0]


def test_records_of_other_checks_are_left_out_when_asked(tmp_path):
    path = tmp_path / "answers.jsonl"
    path.write_text('{"check": "a", "args": {}}\n{"check": "b", "args": {"x": 1}}\n{"check": "a", "args": '
                    '{"x": 2}}\n{"check": "a", "args": {"x": 3}\n', encoding="utf-8")   # last line cut off
    assert read_last_records(path) == {"a": {"x": 2}, "b": {"x": 1}}
    assert read_last_records(path, ["a"]) == {"a": {"x": 2}}
    assert read_last_records(tmp_path / "missing.jsonl") == {}


class Frame:
    """Stands for a pandas or xarray value: numbers behind ``__array__``."""

    def __init__(self, rows):
        self.rows = rows

    def __array__(self, dtype=None, copy=None):
        return np.array(self.rows, dtype=dtype)


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")      # np.matrix, as students use it
@pytest.mark.parametrize("kind", [np.matrix, Frame])
def test_array_like_answers_are_recorded_as_their_numbers(tmp_path, monkeypatch, kind):
    path = tmp_path / "answers.jsonl"
    monkeypatch.setenv(ANSWERS_ENV, str(path))
    answer = [kind(m) for m in MSD_RIGHT]
    assert _check("check_msd_state_space", *answer)[0]
    assert _regrade(path, "check_msd_state_space")[0]
    assert isinstance(encode(np.matrix([[1, 2]])), dict) and decode(encode(np.matrix([[1, 2]]))).shape == (1, 2)


def _pendulum_matrix(x, u):
    """The pendulum's f (exercise 1.3, right) returning np.matrix."""
    m, l, g, d = (ex.PENDULUM[k] for k in ("m", "l", "g", "d_theta"))
    return np.matrix([x[1], -g / l * np.sin(x[0]) - d / m * x[1] + u[0] / (m * l**2)])


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")
def test_the_recorder_never_changes_what_a_check_sees(tmp_path, monkeypatch):
    """A function returning np.matrix: the same verdict and feedback with and without recording,
    and the grader's replay agrees."""
    monkeypatch.delenv(ANSWERS_ENV, raising=False)
    plain = _check("check_pendulum_f", _pendulum_matrix)
    path = tmp_path / "answers.jsonl"
    monkeypatch.setenv(ANSWERS_ENV, str(path))
    recorded = _check("check_pendulum_f", _pendulum_matrix)
    assert recorded == plain == (True, recorded[1]) and recorded[1].startswith("Correct")
    assert _regrade(path, "check_pendulum_f") == plain


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")
def test_encode_never_raises():
    class Hostile:
        def __array__(self, *args, **kwargs):
            raise RuntimeError("no")

    assert encode(Hostile()) == {"opaque": "Hostile"}
    assert decode(encode([Hostile(), np.matrix([[1]])]))[1].tolist() == [[1]]


def test_a_replayed_function_raises_the_recorded_error_by_name():
    replay = decode({"function": "f", "calls": [{"args": [1], "raised": ["ZeroDivisionError", "no"]},
                                                 {"args": [2], "returned": 4}]})
    assert isinstance(replay, Replay) and replay(2) == 4
    with pytest.raises(Exception, match="no") as error:
        replay(1)
    assert type(error.value).__name__ == "ZeroDivisionError"
