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
* `call_user(func, args, name, where=...)` calls such a function with that
  context and returns its value as a finite float array.
"""

from __future__ import annotations

import warnings
from typing import Callable

import numpy as np

from ._validation import _is_complex

__all__ = ["CoursekitWarning", "AccuracyWarning", "UserFunctionError", "call_user"]


class CoursekitWarning(UserWarning):
    """Base class of every warning coursekit issues."""


class AccuracyWarning(CoursekitWarning):
    """A result misses its defining equation by more than rounding explains."""


class UserFunctionError(ValueError):
    """A user-supplied function raised or returned NaN/inf when coursekit called it."""


def _shapes(args) -> str:
    return ", ".join(str(np.shape(a)) for a in args)


def call_user(func: Callable, args: tuple, name: str, *, where: str = "",
              finite: bool = True) -> np.ndarray:
    """Call the user's `func(*args)`; return its value as a float array.

    Raises `UserFunctionError` (a ValueError) naming `name` and `where`
    ("at t = 0.3", "at x_eq") when the call raises, returns something that
    is not numbers, or (with `finite`) returns NaN or inf.
    """
    if not callable(func):
        raise TypeError(f"{name} must be a function: received {type(func).__name__}.")
    place = f" {where}" if where else ""
    try:
        out = func(*args)
    except Exception as err:  # the user's own code: say which function and where
        raise UserFunctionError(
            f"{name} raised {type(err).__name__}{place} (called with arguments of shapes "
            f"{_shapes(args)}): {err}"
        ) from err
    if out is None:
        raise UserFunctionError(f"{name} returned None{place}; did the function forget to return?")
    if _is_complex(out):
        raise UserFunctionError(f"{name} returned complex numbers{place}; expected real numbers.")
    try:
        arr = np.asarray(out, dtype=float)
    except (TypeError, ValueError) as err:
        raise UserFunctionError(
            f"{name} returned {type(out).__name__}{place}, which is not an array of real numbers ({err})."
        ) from None
    if finite and not np.all(np.isfinite(arr)):
        raise UserFunctionError(
            f"{name} returned NaN or inf{place}: {np.array2string(arr, precision=4)}. Look in "
            f"{name} for a division by zero, a square root or logarithm of a negative number, or a "
            "state that has grown without bound."
        )
    return arr


def call_user_fast(func: Callable, args: tuple, name: str, *, where: Callable[[], str]) -> np.ndarray:
    """`call_user` for hot loops (a model called at every solver or filter step).

    Finite real numbers are returned after one check. Anything else (an
    exception, None, complex, NaN/inf, not numbers) repeats the call through
    `call_user`, whose `UserFunctionError` explains it; `where()` builds the
    context string only then.
    """
    try:
        value = np.asarray(func(*args))
        if value.dtype.kind in "fiu" and np.isfinite(value).all():
            return value.astype(float, copy=False)
    except Exception:  # explained below, by the repeated call
        pass
    return call_user(func, args, name, where=where())


def warn_accuracy(message: str, *, stacklevel: int = 3) -> None:
    """Issue an `AccuracyWarning` pointing at the caller of the public function (internal)."""
    warnings.warn(message, AccuracyWarning, stacklevel=stacklevel)
