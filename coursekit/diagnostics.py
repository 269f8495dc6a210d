"""How coursekit tells a user that something is off: warnings and wrapped errors.

* `AccuracyWarning`: a design or computation was carried out, but checking the
  result against its defining equation (the achieved poles, the Riccati
  residual, the boundary conditions of a trajectory, f(x*, u*) = 0) shows it
  missed by more than rounding explains. The message says what is off, by how
  much, and what to try. Every coursekit warning subclasses `CoursekitWarning`,
  so ``warnings.simplefilter("error", coursekit.CoursekitWarning)`` turns them
  all into errors.
* `UserFunctionError`: a function the user supplied (a model f, an output map
  h, an input u(t, x), a control law) raised, or returned NaN/inf, while
  coursekit called it. The message names the function, where it was called
  (time, state) and what it returned; the original exception is chained.
* `SimulationError`: `simulate` cannot reach the end of the time grid.
* `NotControllableError`, `NotObservableError`: an algorithm needs a
  controllable pair (A, B) (Kalman's rank condition (2.13)) or an observable pair
  (A, C) (its dual, chapter 4) and the pair is not one.

Every exception and warning class of coursekit is defined here, and this
module imports nothing from coursekit, so every other module may import it.
(Calling a user's function with this context, and issuing a warning, is `_validation`.)
"""

from __future__ import annotations

__all__ = ["CoursekitWarning", "AccuracyWarning", "UserFunctionError", "SimulationError",
           "NotControllableError", "NotObservableError"]


class CoursekitWarning(UserWarning):
    """Base class of every warning coursekit issues."""


class AccuracyWarning(CoursekitWarning):
    """A result misses its defining equation by more than rounding explains."""


class UserFunctionError(ValueError):
    """A user-supplied function raised or returned NaN/inf when coursekit called it."""


class SimulationError(ValueError, RuntimeError):
    """The simulation cannot reach the end of the time grid.

    Raised when the state overflows the float range (about 1.8e308: an
    unstable system simulated for too long, or a solution with a finite
    escape time) and when the ODE solver gives up. The message says at
    which time, why, and what to try. It is both a ValueError and a
    RuntimeError, so either catches it.
    """


class NotControllableError(ValueError):
    """Raised when an algorithm needs a controllable pair (A, B) and it is not."""


class NotObservableError(ValueError):
    """Raised when an algorithm needs an observable pair (A, C) and it is not."""


