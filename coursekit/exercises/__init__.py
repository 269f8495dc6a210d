"""Self-check exercises: the data of each exercise and a `check_*` that answers back.

One module per chapter (`ch1` ... `ch4`); every name is also available here::

    import coursekit.exercises as ex
    ex.MSD                              # the exercise's numbers (shown as matrices)
    ex.check_msd_state_space(A, B, C)   # prints "Correct: ..." or what is off

A check accepts the answer as a list, a nested list, a NumPy array or a sympy
Matrix, compares it with a tolerance suited to hand computation, prints
specific feedback (which entry, shape or sign is off, with the equation of
the notes to recheck), returns a result that is true exactly when the answer
is correct (so ``assert ex.check_...(...)`` works; Jupyter shows no ``Out[n]``
line for it), and never raises on a wrong answer or prints the solution.

``ex.progress(1)`` shows the exercises of chapter 1 with the state of each in
this session (not tried, not yet, correct) and the section it belongs to.
"""

from . import ch1, ch2, ch3, ch4
from .ch1 import *  # noqa: F401,F403
from .ch2 import *  # noqa: F401,F403
from .ch3 import *  # noqa: F401,F403
from .ch4 import *  # noqa: F401,F403
from ._progress import progress

__all__ = ["progress", "ch1", "ch2", "ch3", "ch4", *ch1.__all__, *ch2.__all__, *ch3.__all__, *ch4.__all__]
