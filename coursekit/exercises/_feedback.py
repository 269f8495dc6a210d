"""Compare a student's answer with the expected one and say what is off.

Every ``check_*`` function of the chapter modules goes through these helpers,
so the feedback reads the same everywhere:

* `read_matrix` / `read_poles` / `read_decision` turn whatever the student
  typed (list, nested list, NumPy array, sympy Matrix or number, a 1-D list
  where a row or column is expected) into a float array, or into a message
  that explains why it could not (a string, a symbol left in a sympy matrix,
  ``None`` because the cell was not filled in);
* `matrix_feedback` compares shapes, then looks for the classic mistakes
  (transposed, whole sign flipped, a known wrong variant such as the MATLAB
  sign of K) and finally names the entries that are off;
* `Report` collects the messages and prints them once, starting with
  "Correct" or "Not yet", and returns a `CheckResult`: true exactly when the
  answer is correct, so ``assert ex.check_...(...)`` works, and silent in
  Jupyter (no ``Out[n]:`` line under the feedback it just printed).
  `feedback_to` sends what `Report` prints to a stream of the caller's in the
  current thread only (the grader checks several students' answers at once).

Nothing here raises on a wrong answer and nothing prints the expected values.
"""

from __future__ import annotations

import contextlib
import contextvars
from dataclasses import dataclass, field
from typing import IO, Any, Callable, Iterator, Sequence

import numpy as np

from .._validation import is_complex

__all__ = ["CheckResult", "Report", "feedback_to", "close", "read_matrix", "read_poles", "read_numbers",
           "read_decision", "matrix_feedback", "poles_feedback", "call_student_function",
           "rank_decision_feedback"]

#: where `Report.show` prints in this thread or task (None: standard output)
_STREAM: contextvars.ContextVar[IO[str] | None] = contextvars.ContextVar("coursekit_feedback", default=None)


@contextlib.contextmanager
def feedback_to(stream: IO[str]) -> Iterator[IO[str]]:
    """Within the block, what the checks print goes to `stream` instead of standard output.

    The redirection holds for the current thread (or asyncio task) only, so
    threads that check different answers at once keep their feedback apart;
    ``sys.stdout`` is never touched.
    """
    token = _STREAM.set(stream)
    try:
        yield stream
    finally:
        _STREAM.reset(token)


#: relative tolerance for answers worked out by hand (0.333 for 1/3 is accepted)
RTOL = 1e-3


def close(answer: np.ndarray, expected: np.ndarray, rtol: float = RTOL) -> np.ndarray:
    """Entry-wise "equal up to hand-computation rounding": |a - e| <= rtol max(1, |e|)."""
    return np.abs(answer - expected) <= rtol * np.maximum(1.0, np.abs(expected))


class CheckResult:
    """What a ``check_*`` returns: true exactly when the answer is correct.

    The feedback has already been printed when a check returns, so in Jupyter
    the result shows nothing: a check called on the last line of a cell leaves
    no ``Out[n]:`` line. A plain Python prompt shows the short `repr`.
    """

    __slots__ = ("exercise", "correct")

    def __init__(self, exercise: str, correct: bool):
        self.exercise = exercise
        self.correct = bool(correct)

    def __bool__(self) -> bool:
        return self.correct

    def __repr__(self) -> str:
        return f"CheckResult(exercise={self.exercise!r}, correct={self.correct})"

    def _ipython_display_(self) -> None:
        # IPython calls this instead of formatting the object; showing nothing sends no
        # execute_result (the printed feedback above is the whole answer)
        return None


@dataclass
class Report:
    """The feedback of one check: a list of problems, printed in one go."""

    name: str
    problems: list[str] = field(default_factory=list)

    def add(self, message: str) -> None:
        self.problems.append(message)

    @property
    def ok(self) -> bool:
        return not self.problems

    def show(self, praise: str) -> CheckResult:
        """Print "Correct: praise" or the problems; the result is true when correct."""
        lines = ([f"Correct: {praise}"] if self.ok
                 else [f"Not yet ({self.name}):", *(f"  - {message}" for message in self.problems)])
        print("\n".join(lines), file=_STREAM.get())
        return CheckResult(self.name, self.ok)


def _is_sympy(value) -> bool:
    # detect sympy objects without importing sympy
    return type(value).__module__.split(".")[0] == "sympy"


def _has_text(value) -> bool:
    """True when some entry of `value` is a string ("1" is text, not the number 1)."""
    try:
        entries = np.ravel(np.asarray(value, dtype=object))
    except (TypeError, ValueError):
        return False
    return any(isinstance(v, (str, bytes)) for v in entries)


#: imaginary parts up to this fraction of the largest entry (at least 1) are rounding: what
#: np.linalg.eig-based work leaves on a real answer (about 1e-16 of it, grown by a few products)
IMAG_RTOL = 1e-10


def _real_part(value) -> np.ndarray | None:
    """The real part of a complex answer whose imaginary parts are all zero to rounding, else None."""
    try:
        z = np.asarray(value, dtype=complex)
    except (TypeError, ValueError, OverflowError):
        return None
    if not np.isfinite(z).all():
        return None
    scale = max(1.0, float(np.abs(z).max(initial=0.0)))
    return z.real.copy() if np.all(np.abs(z.imag) <= IMAG_RTOL * scale) else None


def _to_array(value, name: str, report: Report, *, dtype=float) -> np.ndarray | None:
    """`value` as an array of numbers, or None with a message explaining why not.

    With the default real `dtype`, complex entries are reported (never dropped):
    the answers of these exercises are real matrices. A complex array whose
    imaginary parts are all zero to rounding (`IMAG_RTOL` of its largest entry),
    as np.linalg.eig-based work gives, is the real answer and is read as such.
    """
    if value is None or value is Ellipsis:
        report.add(f"{name} is empty (None): replace the placeholder with your answer.")
        return None
    if isinstance(value, (str, bytes)):
        report.add(f"{name} is the text {value!r}: type numbers, e.g. [[1, 2], [3, 4]], not a string.")
        return None
    if callable(value) and not _is_sympy(value):
        report.add(f"{name} is a function: call it and pass its result (numbers), not the function.")
        return None
    if dtype is float and is_complex(value):
        real = _real_part(value)
        if real is None:
            report.add(f"{name} contains complex numbers: the answer is real. If the imaginary parts are "
                       "rounding noise from a computation (e.g. np.linalg.eig), pass np.real(...) of it; "
                       "otherwise recheck the computation.")
            return None
        value = real
    if _has_text(value):
        report.add(f"{name} contains text: type numbers, e.g. [[1, 2], [3, 4]], not strings.")
        return None
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError):
        if _is_sympy(value) or any(_is_sympy(v) for v in np.ravel(np.asarray(value, dtype=object))):
            report.add(f"{name} still contains symbols: substitute the numbers of the exercise "
                       "(e.g. M.subs({m: 2, k: 8})) so that every entry is a number.")
        else:
            report.add(f"{name} could not be read as numbers: received {type(value).__name__}; "
                       "write it as a list of rows, e.g. [[1, 2], [3, 4]], or a NumPy array.")
        return None
    if not np.all(np.isfinite(arr)):
        report.add(f"{name} contains NaN or infinite entries: check the computation that built it.")
        return None
    return arr


def read_matrix(value, name: str, shape: tuple[int, int], report: Report, *,
                vector: bool = False) -> np.ndarray | None:
    """The student's matrix as a float array, keeping its own shape (for the shape feedback).

    A 1-D list or a scalar is accepted where a row or a column is expected
    (it is reshaped); anything else keeps its shape and `matrix_feedback`
    explains a mismatch. With `vector` a list of numbers is expected, and a
    row or a column of the right length are both accepted.
    """
    arr = _to_array(value, name, report)
    if arr is None:
        return None
    rows, cols = shape
    if vector and arr.ndim <= 2 and arr.size == rows * cols and (arr.ndim < 2 or 1 in arr.shape):
        return arr.reshape(shape)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1 and (rows == 1 or cols == 1) and arr.size == rows * cols:
        arr = arr.reshape(shape)
    elif arr.ndim == 1:
        arr = arr.reshape(1, -1)
    elif arr.ndim > 2:
        report.add(f"{name} has {arr.ndim} dimensions: a matrix is a list of rows (2 dimensions).")
        return None
    return arr


def _describe_shape(shape: tuple[int, int]) -> str:
    rows, cols = shape
    if cols == 1 and rows > 1:
        return f"a column ({rows} x 1)"
    if rows == 1 and cols > 1:
        return f"a row (1 x {cols})"
    return f"{rows} x {cols}"


def _entries(mask: np.ndarray) -> str:
    """The 1-based positions where `mask` is True, as the notes index matrices."""
    rows, cols = np.nonzero(mask)
    if mask.shape[0] == 1 or mask.shape[1] == 1:
        return ", ".join(str(i + 1) for i in np.flatnonzero(mask))
    return ", ".join(f"({r + 1}, {c + 1})" for r, c in zip(rows, cols))


def _at(mask: np.ndarray) -> str:
    """ "the entry at (2, 1) has" / "the entries at 1, 3 have", for the feedback sentences."""
    if mask.sum() == 1:
        return f"the entry at {_entries(mask)} has"
    return f"the entries at {_entries(mask)} have"


def matrix_feedback(answer, expected, name: str, report: Report, *,
                    known_mistakes: Sequence[tuple[Any, str]] = (),
                    shape_hint: str = "", entry_hint: str = "", vector: bool = False) -> bool:
    """Compare the student's `answer` with `expected` and add what is off to `report`.

    `known_mistakes` pairs a typical wrong answer (an array of `expected`'s
    shape) with the message to show when the student's answer equals it, e.g.
    ``(-K, "your K has the MATLAB sign ...")``. `shape_hint` explains where the
    shape comes from, `entry_hint` which equation to recheck for wrong entries;
    `vector` accepts a row or a column alike (a list of coefficients).
    Returns True when the answer is correct.
    """
    expected = np.asarray(expected, dtype=float)
    arr = read_matrix(answer, name, expected.shape, report, vector=vector)
    if arr is None:
        return False
    want = _describe_shape(expected.shape)
    if arr.shape != expected.shape:
        if arr.shape == expected.T.shape and np.all(close(arr.T, expected)):
            report.add(f"{name} is transposed: it must be {want}, yours is "
                       f"{_describe_shape(arr.shape)}. {shape_hint}".strip())
        else:
            report.add(f"{name} has the wrong shape: it must be {want}, yours is "
                       f"{_describe_shape(arr.shape)}. {shape_hint}".strip())
        return False
    if np.all(close(arr, expected)):
        return True
    for mistake, message in known_mistakes:
        mistake = np.asarray(mistake, dtype=float)
        if mistake.shape == arr.shape and np.all(close(arr, mistake)):
            report.add(message)
            return False
    if np.any(expected != 0) and np.all(close(-arr, expected)):
        report.add(f"{name} has the opposite sign in every entry. {entry_hint}".strip())
        return False
    if arr.shape[0] == arr.shape[1] and np.all(close(arr.T, expected)):
        report.add(f"{name} is transposed: rows and columns are swapped. {shape_hint}".strip())
        return False
    wrong = ~close(arr, expected)
    flipped = wrong & close(-arr, expected)
    other = wrong & ~flipped
    parts = []
    if flipped.any():
        parts.append(f"{_at(flipped)} the wrong sign")
    if other.any():
        parts.append(f"{_at(other).replace(' has', ' is').replace(' have', ' are')} off")
    # positions are counted from 1, as the notes index matrices; the hint is given once
    report.add(f"{name}: {' and '.join(parts)} (counted from 1). {entry_hint}".strip())
    return False


def read_poles(value, name: str, count: int, report: Report) -> np.ndarray | None:
    """A list of `count` (possibly complex) numbers, or None with a message."""
    return _read_list(value, name, count, report, dtype=complex)


def read_numbers(value, name: str, count: int, report: Report) -> np.ndarray | None:
    """A list of `count` real numbers (a single number for count 1), or None with a message."""
    return _read_list(value, name, count, report, dtype=float)


def _read_list(value, name: str, count: int, report: Report, *, dtype) -> np.ndarray | None:
    arr = _to_array(value, name, report, dtype=dtype)
    if arr is None:
        return None
    arr = arr.ravel()
    if arr.size != count:
        report.add(f"{name} must list {count} numbers (with repetitions), yours has {arr.size}.")
        return None
    return arr


def _match(values: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """For each target, True when one of `values` (each used once) matches it."""
    free = list(values)
    found = np.zeros(targets.size, dtype=bool)
    for i, t in enumerate(targets):
        for j, v in enumerate(free):
            if abs(v - t) <= RTOL * max(1.0, abs(t)):
                found[i] = True
                free.pop(j)
                break
    return found


def poles_feedback(answer, expected, name: str, report: Report, *, hint: str = "") -> bool:
    """Compare two lists of numbers as multisets (order does not matter)."""
    expected = np.asarray(expected, dtype=complex).ravel()
    arr = read_poles(answer, name, expected.size, report)
    if arr is None:
        return False
    found = _match(arr, expected)
    if found.all():
        return True
    report.add(f"{name}: {int((~found).sum())} of the {expected.size} values do not match. {hint}".strip())
    return False


_YES = {"yes", "y", "true", "controllable", "observable", "stable"}
_NO = {"no", "n", "false", "not controllable", "uncontrollable", "not observable",
       "unobservable", "not stable", "unstable"}


def read_decision(value, name: str, report: Report) -> bool | None:
    """A yes/no answer: True/False, 1/0, or the words yes/no, else None with a message."""
    if isinstance(value, str):
        word = value.strip().lower()
        if word in _YES:
            return True
        if word in _NO:
            return False
    elif isinstance(value, (bool, np.bool_)) or (
            isinstance(value, (int, np.integer)) and value in (0, 1)):
        return bool(value)
    elif _is_sympy(value) and str(value) in ("True", "False"):
        return str(value) == "True"
    report.add(f"{name} must be True or False (yes or no): received {value!r}.")
    return None


def call_student_function(func: Callable, args: tuple, name: str, size: int,
                          report: Report) -> np.ndarray | None:
    """Call the student's function once; its result as `size` floats, or None with a message."""
    if not callable(func):
        report.add(f"{name} must be a Python function (def {name}(...): ... return ...), "
                   f"received {type(func).__name__}.")
        return None
    try:
        out = func(*args)
    except Exception as err:  # the student's own bug: say what happened
        report.add(f"calling {name} raised {type(err).__name__}: {err}. "
                   "Test it on one input first.")
        return None
    inner = Report(name)
    arr = _to_array(out, f"the value returned by {name}", inner)
    if arr is None:
        report.add(inner.problems[0] if out is not None else
                   f"{name} returned None: did it forget the return statement?")
        return None
    arr = arr.ravel()
    if arr.size != size:
        report.add(f"{name} returned {arr.size} numbers, expected {size}.")
        return None
    return arr


def _rank_feedback(rank, true_rank: int, report: Report, rank_hint: str) -> None:
    inner = Report("rank")
    value = _to_array(rank, "rank", inner)
    if value is None or value.size != 1 or value.ravel()[0] != round(value.ravel()[0]):
        shown = inner.problems[0] if inner.problems else f"received {rank!r}"
        report.add(f"rank must be a whole number (np.linalg.matrix_rank): {shown}")
    elif value.ravel()[0] != true_rank:
        report.add(f"the rank is off: {rank_hint}")


def rank_decision_feedback(rank, decision, true_rank: int, n: int, report: Report, *,
                           word: str, rank_hint: str, decision_hint: str) -> None:
    """Check a rank and the yes/no decision "rank = n" of a Kalman criterion (W_c or W_o)."""
    if isinstance(rank, (str, bytes)):
        # the exercise asks for a number, not words: "2" is refused, saying so plainly
        report.add(f"rank must be a whole number, not text: received the string {rank!r}; type the number "
                   "without quotes, or compute it with np.linalg.matrix_rank.")
    else:
        _rank_feedback(rank, true_rank, report, rank_hint)
    answer = read_decision(decision, word, report)
    if answer is not None and answer != (true_rank == n):
        report.add(f"the decision does not follow the criterion: {decision_hint}")
