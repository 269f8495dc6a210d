"""The exercises of each chapter, and what happens around every call of a check.

Each ``check_*`` of the chapter modules is declared with `exercise`::

    @exercise("1.1", "the mass-spring-damper in state-space form", section="1.6 Bridges")
    def check_msd_state_space(A, B, C) -> CheckResult: ...

which gives it its `Exercise` record as the attribute ``exercise`` (the chapter comes from
the label; `coursekit._chapters`, the course's one registry, finds the checks of every chapter
module by it) and wraps it so that every call

* appends the answer to the grader's answers file when one is set
  (`coursekit.exercises._answers.append_record`, before the check runs, so an
  answer counts even when the kernel dies afterwards; a function given as an
  answer is recorded after the check, with the calls the check made to it);
* keeps the verdict for this session in `STATE` (read by
  `coursekit.exercises.progress`): the last answer counts.

A call with the exercise's untouched placeholder (every argument ``None``, a list of ``None``
such as ``[None, None, None, None]``, or a function whose body only returns None, as the
notebook's answer cells hold them before a student types anything) is not an answer: the check
still prints what to do, but the call is neither recorded nor kept, so Run All on a fresh
chapter leaves its exercises "not tried" in `progress` and unanswered for the grader.

The wrapped function keeps the check's name, docstring and signature
(`functools.wraps`); the course's own check is its ``__wrapped__``, which the
grader calls. A check the student replaces in the notebook records nothing.
"""

from __future__ import annotations

import functools
import inspect
from dataclasses import dataclass
from typing import Callable

from .._chapters import exercises
from ._answers import Tape, append_record

__all__ = ["Exercise", "STATE", "exercise", "chapter_exercises", "chapters"]


@dataclass(frozen=True)
class Exercise:
    """One exercise: "1.1", its title, the section of the notes it practises, and its check."""

    label: str
    title: str
    section: str
    check: str

    @property
    def chapter(self) -> int:
        return int(self.label.split(".")[0])


#: name of a check -> True (last answer correct) or False (not yet), for the checks called this session
STATE: dict[str, bool] = {}


def _record(name: str, bound: inspect.BoundArguments, functions: dict) -> None:
    """Append the answer to the answers file; never disturbs the check the student runs."""
    try:
        append_record(name, {**bound.arguments, **functions})
    except Exception:  # an answer that cannot be written (full disk, odd object) is not recorded
        pass


def _wrap(check: Callable) -> Callable:
    signature = inspect.signature(check)

    @functools.wraps(check)
    def recorded(*args, **kwargs):
        try:
            bound = signature.bind(*args, **kwargs)
        except TypeError:
            return check(*args, **kwargs)          # raises the same TypeError for the student
        if bound.arguments and all(map(_placeholder, bound.arguments.values())):
            return check(*args, **kwargs)          # not tried yet: its feedback, no answer kept
        tapes = {k: Tape(v) for k, v in bound.arguments.items() if callable(v) and not _is_data(v)}
        if not tapes:
            _record(check.__name__, bound, {})
        try:
            result = check(*(tapes.get(k, v) for k, v in bound.arguments.items()))
        finally:
            if tapes:
                _record(check.__name__, bound, tapes)
        STATE[check.__name__] = bool(result)
        return result

    return recorded


def _returns_none():
    return None      # the body of an answer cell's untouched function


def _placeholder(value) -> bool:
    """True for an answer cell's untouched placeholder: None (or ``...``), a non-empty list or
    tuple of placeholders, or a function whose code only returns None (``return None``, ``pass``)."""
    if value is None or value is Ellipsis:
        return True
    if isinstance(value, (list, tuple)):
        return bool(value) and all(map(_placeholder, value))
    if not inspect.isfunction(value):
        return False
    code, nothing = value.__code__, _returns_none.__code__
    return code.co_code == nothing.co_code and code.co_consts == nothing.co_consts and not code.co_names


def _is_data(value) -> bool:
    """Callable objects that are answers as data (sympy matrices and expressions are callable)."""
    return type(value).__module__.split(".")[0] in ("sympy", "numpy")


def exercise(label: str, title: str, *, section: str) -> Callable[[Callable], Callable]:
    """Declare a check as the check of exercise `label` (see the module docstring)."""
    def declare(check: Callable) -> Callable:
        recorded = _wrap(check)
        recorded.exercise = Exercise(label, title, section, check.__name__)
        return recorded
    return declare


def chapters() -> list[int]:
    """The chapters that have exercises, in order."""
    return list(exercises())


def chapter_exercises(chapter) -> list[Exercise]:
    """The exercises of `chapter` (1, 2, ...), in order; ValueError/TypeError for a bad chapter."""
    if isinstance(chapter, bool) or not isinstance(chapter, int):
        raise TypeError(f"chapter must be a chapter number such as 1, received {chapter!r}; "
                        f"the chapters with exercises are {chapters()}.")
    found = exercises()
    if chapter not in found:
        raise ValueError(f"chapter {chapter} has no exercises: pass one of {list(found)}.")
    return found[chapter]
