"""Input checks shared by every public function.

Each public function calls these on its first lines, passing the argument's
name, so that a student who passes the wrong thing reads *which* argument is
wrong, what was received and what was expected, e.g.::

    ValueError: B has the wrong number of rows: received shape (3, 1),
    expected 2 rows (one per state, since A is 2x2).
"""

from __future__ import annotations

import sys as _sys
import warnings
from contextlib import contextmanager
from typing import Callable

import numpy as np

from .diagnostics import AccuracyWarning, UserFunctionError

__all__ = ["MAX_SPAN", "as_matrix", "as_square", "as_vector", "as_series", "as_scalar", "as_time_grid", "is_uniform",
           "as_poles", "as_covariance", "as_integer", "as_dt", "as_text", "as_flag", "require_columns",
           "time_grid", "check_function_output", "call_user", "call_user_fast", "checked_call", "float_array",
           "is_complex", "is_text", "foreign_library", "type_name", "BRIDGES", "function_name",
           "input_size_explained", "sympy_column", "warn_accuracy", "agrees_column_by_column"]


def _describe(value) -> str:
    """A short description of what the user passed, for error messages."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, (list, tuple)):
        return f"a {type(value).__name__} of length {len(value)}"
    return f"{type(value).__name__} {value!r}"


def is_complex(value) -> bool:
    """True for complex numbers or arrays, even when their imaginary parts are zero.

    Covers Python and numpy complex scalars and arrays, lists of them, and
    sympy numbers or matrices whose entries are complex (e.g. ``1 + I``).
    """
    if isinstance(value, (complex, np.complexfloating)):
        return True
    if isinstance(value, np.ndarray) and value.dtype.kind != "O":
        return value.dtype.kind == "c"
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        return False
    if arr.dtype.kind == "c":
        return True
    if arr.dtype.kind == "O":
        # sympy numbers and matrices: complex when some entry has an imaginary part
        try:
            return bool(np.any(np.asarray(value, dtype=complex).imag != 0))
        except (TypeError, ValueError, OverflowError):
            return False
    return False


def is_text(value) -> bool:
    """True for a string, or a list/array of strings ("1.0" is text, not a number)."""
    if isinstance(value, (str, bytes)):
        return True
    if isinstance(value, (list, tuple, np.ndarray)):
        try:
            return np.asarray(value).dtype.kind in "US"
        except (TypeError, ValueError):
            return False
    return False


def type_name(value) -> str:
    """The full name of value's type, e.g. ``control.statesp.StateSpace``."""
    kind = type(value)
    return kind.__qualname__ if kind.__module__ == "builtins" else f"{kind.__module__}.{kind.__qualname__}"


def foreign_library(value) -> str | None:
    """"python-control" or "scipy.signal" when `value` is a system object of that library, else None.

    Only libraries already imported are looked at (an object of theirs cannot exist otherwise).
    """
    top = type(value).__module__.split(".")[0]
    control = _sys.modules.get("control") if top == "control" else None
    if control is not None and isinstance(value, getattr(control, "InputOutputSystem", ())):
        return "python-control"
    signal = _sys.modules.get("scipy.signal") if top == "scipy" else None
    if signal is not None and isinstance(value, (signal.lti, signal.dlti)):
        return "scipy.signal"
    return None


#: the StateSpace constructor that converts a system of each neighbouring library
BRIDGES = {"python-control": "StateSpace.from_control", "scipy.signal": "StateSpace.from_scipy"}


def _refuse_system_as_matrix(value, name: str) -> None:
    """A system passed where a matrix is wanted: say which matrix to take, or which bridge."""
    library = foreign_library(value)
    if library is None and type(value).__module__ == "coursekit.systems":
        library = "coursekit"
    if library is None:
        return
    bridge = f", or convert the system with {BRIDGES[library]}(sys)" if library in BRIDGES else ""
    raise ValueError(
        f"{name} must be a matrix: received a {library} system ({type_name(value)}); pass its "
        f"matrix, e.g. sys.{name if name in ('A', 'B', 'C', 'D') else 'A'}{bridge}."
    )


def _to_float_array(value, name: str) -> np.ndarray:
    if value is None:
        raise ValueError(f"{name} is missing: received None, expected a number or an array.")
    _refuse_system_as_matrix(value, name)
    if is_text(value):
        raise ValueError(
            f"{name} must contain real numbers: received the text {value!r}; type the numbers "
            "themselves, e.g. 0.5 or [[0, 1], [-2, -3]], without quotes."
        )
    if is_complex(value):
        raise ValueError(
            f"{name} must contain real numbers: received {_describe(value)} with complex "
            "entries; pass the real matrix (complex numbers are only accepted as poles)."
        )
    try:
        # sympy matrices, nested lists and numbers all pass through np.asarray
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError) as err:
        raise ValueError(
            f"{name} must contain real numbers: received {_describe(value)} "
            f"that cannot be converted to a float array ({err})."
        ) from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{name} contains NaN or infinite entries: received {arr.tolist()!r}; "
            "expected finite numbers (check the parameters it was built from)."
        )
    return arr


def as_matrix(value, name: str, *, rows: int | None = None, cols: int | None = None,
              rows_why: str = "", cols_why: str = "") -> np.ndarray:
    """Return `value` as a finite 2-D float array, checking its shape.

    A scalar becomes a 1x1 matrix. A 1-D array becomes a column when `cols`
    is 1 and a row when `rows` is 1; any other 1-D input is ambiguous and
    rejected. `rows_why` / `cols_why` explain where the expected size comes
    from ("one per state, since A is 2x2").
    """
    arr = _to_float_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1:
        if cols == 1 and rows != 1:
            arr = arr.reshape(-1, 1)
        elif rows == 1 or arr.size == 1:
            arr = arr.reshape(1, -1)
        else:
            raise ValueError(
                f"{name} must be a 2-D matrix: received a 1-D array of length {arr.size}; "
                f"write it as a list of rows, e.g. [[...], [...]], or as a column [[a], [b]]."
            )
    elif arr.ndim != 2:
        raise ValueError(f"{name} must be a 2-D matrix: received an array with {arr.ndim} dimensions.")
    for axis, want, why, word in ((0, rows, rows_why, "rows"), (1, cols, cols_why, "columns")):
        if want is not None and arr.shape[axis] != want:
            reason = f" ({why})" if why else ""
            raise ValueError(
                f"{name} has the wrong number of {word}: received shape {arr.shape}, "
                f"expected {want} {word}{reason}."
            )
    return arr


def as_square(value, name: str, *, size: int | None = None) -> np.ndarray:
    """Return `value` as a finite square float matrix (of `size` if given)."""
    arr = as_matrix(value, name)
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(
            f"{name} must be square: received shape {arr.shape}, expected (n, n)."
        )
    if size is not None and arr.shape[0] != size:
        raise ValueError(f"{name} has the wrong size: received shape {arr.shape}, expected ({size}, {size}).")
    if arr.shape[0] == 0:
        raise ValueError(f"{name} is empty: expected at least one state.")
    return arr


def as_vector(value, name: str, *, size: int | None = None, why: str = "") -> np.ndarray:
    """Return `value` as a finite 1-D float array (of length `size` if given).

    Row and column matrices (shape (1, k) or (k, 1)) are flattened.
    """
    arr = _to_float_array(value, name)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.ravel()
    elif arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a vector: received an array of shape {arr.shape}.")
    if size is not None and arr.size != size:
        reason = f" ({why})" if why else ""
        raise ValueError(
            f"{name} has the wrong length: received {arr.size} entries, expected {size}{reason}."
        )
    return arr


def as_series(value, name: str, *, samples: int, channels: int | None = None,
              samples_why: str = "one row per time in t", channels_why: str = "") -> np.ndarray:
    """Return a time series as a time-major (samples, channels) float matrix.

    A 1-D array is one channel sampled in time, so it becomes a column.
    """
    if np.ndim(value) == 1:
        value = np.reshape(np.asarray(value, dtype=float), (-1, 1))
    return as_matrix(value, name, rows=samples, cols=channels, rows_why=samples_why,
                     cols_why=channels_why)


def as_scalar(value, name: str, *, positive: bool = False, integer: bool = False,
              limit: float | None = None, limit_why: str = "") -> float:
    """Return `value` as a finite float, optionally checking it is > 0, whole, or at most
    `limit` in size (`limit_why` says why: "metres on a lecture-room floor")."""
    arr = _to_float_array(value, name)
    if arr.size != 1:
        raise ValueError(f"{name} must be a single number: received {_describe(value)}.")
    x = float(arr.reshape(()))
    if positive and not x > 0:
        raise ValueError(f"{name} must be positive: received {x!r}, expected a number > 0.")
    if integer and x != round(x):
        raise ValueError(f"{name} must be a whole number: received {x!r}.")
    if limit is not None and abs(x) > limit:
        reason = f" ({limit_why})" if limit_why else ""
        raise ValueError(f"{name} is out of range: received {x:g}, expected |{name}| <= {limit:g}{reason}.")
    return x


def as_dt(value, name: str = "dt") -> float | None:
    """A time base: None (continuous time) or a sampling period > 0.

    0 is refused with a pointer to None: python-control writes continuous time as
    dt=0, coursekit as dt=None.
    """
    if value is None:
        return None
    if as_scalar(value, name) == 0:
        raise ValueError(f"{name} must be positive: received 0.0, but a sampling period is > 0; for a "
                         f"continuous-time system pass {name}=None or leave {name} out (python-control "
                         "writes continuous time as dt=0, coursekit as dt=None).")
    return as_scalar(value, name, positive=True)


def as_integer(value, name: str, *, minimum: int | None = None, why: str = "") -> int:
    """Return `value` as an int, checking it is a finite whole number (>= `minimum`)."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be a whole number: received {value!r}.")
    if isinstance(value, (list, tuple, np.ndarray)) and np.ndim(value) > 0:
        # a count or an index: [0] is a list, not the number 0
        raise ValueError(f"{name} must be a single whole number: received {_describe(value)}; "
                         f"pass the number itself, e.g. {name}=0.")
    k = int(as_scalar(value, name, integer=True))
    if minimum is not None and k < minimum:
        reason = f" ({why})" if why else ""
        raise ValueError(f"{name} must be at least {minimum}: received {k}{reason}.")
    return k


def as_flag(value, name: str, *, hint: str = "") -> bool:
    """Return `value` as a bool: only True or False (numpy's too); "yes", None or 1 are refused."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False: received {type(value).__name__} {value!r}"
                         + (f"; {hint}" if hint else "") + ".")
    return bool(value)


def require_columns(shape: tuple, name: str = "B", *, each: str = "input") -> None:
    """Raise naming `name` when a matrix of this shape has no columns (an input matrix B of
    shape (n, 0): no input to act with, almost always a slip such as B[:, 1:] of one column)."""
    if shape[1] == 0:
        raise ValueError(f"{name} has no columns: received shape {tuple(shape)}, expected at least one "
                         f"column (one per {each}); look for a slice such as {name}[:, 1:] that "
                         "left none.")


def as_text(value, name: str, *, expected: str = "a string") -> str:
    """Return `value` when it is a string, else raise naming `name`."""
    if not isinstance(value, str):
        raise ValueError(f"{name} must be {expected}: received {_describe(value)}.")
    return value


#: the most samples `time_grid` allocates (8 MB), and the longest span it covers by default
MAX_SAMPLES = 10**6
MAX_SPAN = 1e6


def time_grid(t_end, samples, *, t_end_name: str = "t_end", max_span: float | None = MAX_SPAN) -> np.ndarray:
    """``np.linspace(0, t_end, samples)`` after checking 0 < t_end <= max_span and 2 <= samples <= 10^6.

    Each bound is checked before anything is allocated or integrated, and named
    (a huge `samples` ran out of memory, a t_end of 1e300 made the solvers work
    for ever); ``max_span=None`` for a span chosen elsewhere (a plan's horizon).
    """
    t_end = as_scalar(t_end, t_end_name, positive=True)
    samples = as_integer(samples, "samples", minimum=2, why="a time grid needs a start and an end")
    if samples > MAX_SAMPLES:
        raise ValueError(f"samples must be at most {MAX_SAMPLES:,}: received {samples:,}, which would "
                         f"need {8 * samples / 1e9:.3g} GB per curve; a figure shows no more than a few "
                         "thousand points, so pass e.g. samples=1000.")
    if max_span is not None and t_end > max_span:
        raise ValueError(f"{t_end_name} is too large: a time span of {t_end:g} exceeds {max_span:g}, the "
                         "longest these computations are meant for (seconds to minutes of motion); "
                         f"pass a smaller {t_end_name}, or call simulate yourself for a long horizon.")
    return np.linspace(0.0, t_end, samples)


def as_time_grid(t, name: str = "t", *, min_points: int = 2) -> np.ndarray:
    """Return `t` as a finite, strictly increasing 1-D time grid."""
    arr = as_vector(t, name)
    if arr.size < min_points:
        raise ValueError(
            f"{name} has too few points: received {arr.size}, expected at least {min_points} "
            "(e.g. np.linspace(0, 10, 1001))."
        )
    steps = np.diff(arr)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        raise ValueError(
            f"{name} must be strictly increasing: {name}[{k + 1}] = {arr[k + 1]!r} does not come "
            f"after {name}[{k}] = {arr[k]!r}; sort the grid or build it with np.linspace."
        )
    return arr


def is_uniform(t: np.ndarray, rtol: float = 1e-9) -> bool:
    """True when the grid `t` has (to rounding) a constant step."""
    steps = np.diff(t)
    return bool(np.all(np.abs(steps - steps[0]) <= rtol * max(abs(steps[0]), np.abs(t).max())))


def as_covariance(value, name: str, size: int, *, definite: bool, why: str = "") -> np.ndarray:
    """A symmetric (size x size) matrix, positive definite or semidefinite (Q, R, P0 of (4.88)).

    `why` says where `size` comes from ("one row and column per state, since A is 2x2").
    """
    M = as_square(value, name)
    if M.shape[0] != size:
        reason = f" ({why})" if why else ""
        raise ValueError(f"{name} has the wrong size: received shape {M.shape}, expected "
                         f"({size}, {size}){reason}.")
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * max(1.0, np.abs(M).max())):
        raise ValueError(f"{name} must be symmetric: received {M.tolist()!r}; use (M + M.T) / 2.")
    M = (M + M.T) / 2
    low = float(np.linalg.eigvalsh(M).min())
    scale = max(1.0, float(np.abs(M).max()))
    if definite and low <= 1e-12 * scale:
        raise ValueError(
            f"{name} must be positive definite: its smallest eigenvalue is {low:.3g}; "
            f"expected every eigenvalue > 0 (e.g. a diagonal matrix with positive entries)."
        )
    if not definite and low < -1e-10 * scale:
        raise ValueError(
            f"{name} must be positive semidefinite: its smallest eigenvalue is {low:.3g} < 0; "
            "expected a covariance-like matrix such as np.diag([q1, q2])."
        )
    return M


def as_poles(poles, name: str = "poles", *, count: int) -> np.ndarray:
    """Return `poles` as a complex array of length `count`, closed under conjugation.

    Complex poles must come with their conjugate, otherwise no real gain can
    place them.
    """
    if poles is None:
        raise ValueError(f"{name} is missing: received None; pass the poles as a list of numbers, "
                         "e.g. [-1, -2].")
    try:
        arr = np.atleast_1d(np.asarray(poles, dtype=complex)).ravel()
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name} must be a list of numbers: received {_describe(poles)}.") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite entries: received {arr.tolist()!r}.")
    if arr.size != count:
        raise ValueError(
            f"{name} has the wrong length: received {arr.size} poles, expected {count} "
            "(one per state)."
        )
    scale = max(1.0, float(np.abs(arr).max()))
    remaining = list(arr[np.abs(arr.imag) > 1e-12 * scale])
    while remaining:
        p = remaining.pop()
        match = [i for i, q in enumerate(remaining) if abs(q - np.conj(p)) <= 1e-9 * scale]
        if not match:
            raise ValueError(
                f"{name} has the complex pole {p} without its conjugate {np.conj(p)}; "
                "complex poles must come in conjugate pairs for a real gain."
            )
        remaining.pop(match[0])
    return arr


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
    if is_complex(out):
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


def check_function_output(func: Callable, args: tuple, name: str, *, size: int, what: str) -> np.ndarray:
    """Call a user function once and explain a wrong return value before integrating.

    `what` says what the value means ("dx/dt, one entry per state"). Raises
    `UserFunctionError` (a ValueError) naming `name` when the call raises or
    returns None, text, complex numbers, NaN or inf (see `call_user`),
    and ValueError when it returns the wrong number of values.
    """
    if not callable(func):
        raise ValueError(f"{name} must be a function: received {_describe(func)}; expected {what}.")
    arr = call_user(func, args, name, where="when called once as a check")
    if arr.ndim > 1 and not (arr.ndim == 2 and 1 in arr.shape) or arr.size != size:
        raise ValueError(f"{name} returned shape {arr.shape}; expected {size} numbers ({what}).")
    return arr.ravel()


def checked_call(func: Callable, args: tuple, name: str, *, size: int, what: str,
                 where: str = "") -> np.ndarray:
    """Call a user function once: an exception, None or NaN/inf is explained by
    `call_user` (naming `name` and `where`), a wrong return shape by
    `check_function_output`'s rule; returns the value as a flat float array."""
    value = call_user(func, args, name, where=where)
    try:
        return check_function_output(lambda *_: value, args, name, size=size, what=what)
    except ValueError as err:
        if not where:
            raise
        raise UserFunctionError(f"{err} This happened {where}.") from None


def float_array(value, name: str) -> np.ndarray:
    """value as a float array; None, complex or non-numeric values raise ValueError naming `name`."""
    if value is None:
        raise ValueError(f"{name} is None: expected an array of real numbers.")
    arr = np.asarray(value)
    if arr.dtype.kind == "f":
        return arr
    if arr.dtype.kind == "c":
        raise ValueError(f"{name} must contain real numbers: received complex entries; pass real numbers "
                         "(np.real(...) when the imaginary parts are only rounding).")
    try:
        return arr.astype(float, copy=False)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be an array of real numbers: received {type(value).__name__} "
                         f"({err}).") from None


def function_name(func: Callable, role: str = "f") -> str:
    """How error messages name a user function: its role, and its own name if it has one."""
    own = getattr(func, "__name__", "")
    return f"{role} ({own})" if own and own not in (role, "<lambda>") else role


@contextmanager
def input_size_explained(u_eq, u: np.ndarray, task: str):
    """Turn an IndexError of the user's f at the first call into "u_eq is missing / too short".

    f(x, u) that reads u[0] fails with the student's own IndexError when u_eq
    was left out (u is then empty); the message says which argument to pass.
    """
    try:
        yield
    except UserFunctionError as err:
        if not isinstance(err.__cause__, IndexError):
            raise
        state = "is missing" if u_eq is None else f"may be too short ({u.size} entries)"
        raise ValueError(
            f"u_eq {state}: {err}. Pass {task} the input u* with one entry per input that f reads "
            "(f uses u[0], u[1], ...), e.g. u_eq=[0.0]; if f reads no input, check that each state "
            "has its entry in x."
        ) from err


def sympy_column(values, name: str, *, allow_empty: bool = False):
    """`values` (a list or sympy Matrix of expressions) as a sympy column; text and (unless
    `allow_empty`) an empty list raise ValueError naming `name`."""
    import sympy as sp
    texts = [values] if isinstance(values, str) else \
        [v for v in values if isinstance(v, str)] if isinstance(values, (list, tuple)) else []
    if texts:
        raise ValueError(f"{name} must be a list of sympy expressions: received the text {texts[0]!r}; "
                         "build expressions from symbols, e.g. x1, x2 = sp.symbols('x1 x2').")
    try:
        M = sp.Matrix(values)
    except (TypeError, ValueError, NotImplementedError, sp.SympifyError):
        raise ValueError(f"{name} must be a list of sympy expressions: received {values!r}.") from None
    if len(M) == 0 and not allow_empty:
        raise ValueError(f"{name} is empty: expected at least one expression, e.g. [x1, x2] "
                         "from x1, x2 = sp.symbols('x1 x2').")
    if min(M.shape) > 1:
        raise ValueError(f"{name} must be a list (one row or one column): received a {M.shape[0]}x{M.shape[1]} "
                         f"matrix; list the entries one after the other, e.g. [x1, x2, x3, x4].")
    undefined = [v for v in (sp.nan, sp.zoo, sp.oo, -sp.oo) if M.has(v)]
    if undefined:
        raise ValueError(f"{name} contains {undefined[0]} (sympy's {'NaN' if undefined[0] is sp.nan else 'infinity'}): "
                         f"received {list(M)!r}; look for a division by zero or a NaN where {name} "
                         "was built, and pass finite expressions.")
    if M.shape[1] != 1:
        M = M.reshape(len(M), 1)
    return M


def warn_accuracy(message: str, *, stacklevel: int = 3) -> None:
    """Issue an `AccuracyWarning` pointing at the caller of the public function."""
    warnings.warn(message, AccuracyWarning, stacklevel=stacklevel)


def agrees_column_by_column(fun, X: np.ndarray, U: np.ndarray, batch: np.ndarray) -> bool:
    """True when `batch`, fun's answer for the states X and inputs U as columns, holds
    fun(X[:, j], U[:, j]) in column j for every j (within 1e-12)."""
    single = np.column_stack([np.ravel(fun(X[:, j], U[:, j])) for j in range(X.shape[1])])
    return batch.size == single.size and np.allclose(batch.reshape(single.shape), single,
                                                     rtol=1e-12, atol=1e-12)
