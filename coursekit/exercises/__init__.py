"""Self-check exercises: the data of each exercise and a `check_*` that answers back.

One module per chapter (`ch1`, `ch2`, ..., found by their names); every name is also
available here::

    import coursekit.exercises as ex
    ex.MSD                              # the exercise's numbers (shown as matrices)
    ex.check_msd_state_space(A, B, C)   # prints "Correct: ..." or what is off

A check accepts the answer as a list, a nested list, a NumPy array or a sympy
Matrix, compares it with a tolerance suited to hand computation, prints
specific feedback (which entry, shape or sign is off, with the equation of
the notes to recheck), returns a result that is true exactly when the answer
is correct (so ``assert ex.check_...(...)`` works; Jupyter shows no ``Out[n]``
line for it), and never raises on a wrong answer or prints the solution.

The kit for writing an exercise is public here too (see docs/extending.md): `exercise`
declares a check, `ExerciseData` holds its numbers, `Report` collects the feedback and
`matrix_feedback`, `poles_feedback` and the ``read_*`` helpers compare an answer.

``ex.progress(1)`` shows the exercises of chapter 1 with the state of each in
this session (not tried, not yet, correct) and the section it belongs to.
"""

from .._chapters import chapter_modules as _chapter_modules

# the kit for writing an exercise (docs/extending.md), bound before the chapters import it
from ._catalog import chapter_exercises, exercise
from ._data import ExerciseData
from ._feedback import (CheckResult, Report, call_student_function, close, matrix_feedback, poles_feedback,
                        rank_decision_feedback, read_decision, read_matrix, read_numbers, read_poles)
from ._progress import progress

__all__ = ["progress", "chapter_exercises", "exercise", "ExerciseData", "CheckResult", "Report", "close",
           "read_matrix", "read_poles", "read_numbers", "read_decision", "matrix_feedback", "poles_feedback",
           "call_student_function", "rank_decision_feedback"]

# every chapter module chN (a new chapter's too), by N; its names are available here
for _module in _chapter_modules("exercises"):
    _name = _module.__name__.rsplit(".", 1)[1]
    globals()[_name] = _module
    globals().update({name: getattr(_module, name) for name in _module.__all__})
    __all__ += [_name, *_module.__all__]
