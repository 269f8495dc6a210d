"""System objects: linear state-space models and nonlinear vector fields.

`StateSpace` holds the matrices of (1.24), x' = A x + B u, y = C x + D u
(or x(t+1) = A x(t) + B u(t) in discrete time, when `dt` is set).
`NonlinearSystem` holds the vector field f of (1.32) and the output map h
of (1.33). Both expose `f(x, u)` and `h(x, u)` so that `simulate` treats
them alike.

`raw_field()` and `raw_output()` give the model's own f and h, without the checks, for
hot loops. A function that takes a system checks it with `_arguments.as_system`.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._validation import (as_dt, as_matrix, as_scalar, as_square, call_user, call_user_fast, checked_call,
                          float_array)

__all__ = ["StateSpace", "NonlinearSystem"]


def _finite(arr: np.ndarray, name: str) -> np.ndarray:
    """arr itself; NaN or inf entries raise ValueError naming `name`."""
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} contains NaN or inf: {np.array2string(arr, precision=4)}; "
                         f"pass finite numbers (a NaN usually comes from an earlier computation).")
    return arr


def _state_and_input(x, u, n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """x of shape (n,) or a batch (n, ...) of states, u of shape (m,) or (m, ...) to match.

    Raises ValueError naming x or u and the expected shape: a column x (n, 1)
    is a batch of one state and needs u of shape (m, 1) (with a flat u (m,)
    it would otherwise broadcast into an (n, n) result). NaN/inf entries and
    u = None raise ValueError too; with m = 0, u may be None or empty.
    """
    x = _finite(float_array(x, "x"), "x")
    if x.ndim == 0 or x.shape[0] != n:
        raise ValueError(f"x has shape {x.shape}: expected ({n},), one entry per state, or ({n}, k) "
                         "for a batch of k states as columns.")
    batch = x.shape[1:]
    if m == 0 and (u is None or np.size(u) == 0):
        return x, np.zeros((0,) + batch)
    u = _finite(float_array(u, "u"), "u")
    if x.ndim == 1 and u.size == m and u.ndim <= 1:
        return x, u.reshape(m)
    if u.shape != (m,) + batch:
        raise ValueError(f"u has shape {u.shape}: expected {(m,) + batch} for x of shape {x.shape} "
                         f"(one entry per input{', one column per state of the batch' if batch else ''}).")
    return x, u


def _at(x: np.ndarray, u: np.ndarray) -> str:
    """'at x = [1. 0.], u = [0.]' (the shapes, for a batch): where f or h was called."""
    if x.ndim > 1:
        return f"on the batch of states x of shape {x.shape} (u of shape {u.shape})"
    return f"at x = {np.array2string(x, precision=6)}, u = {np.array2string(u, precision=6)}"


def _evaluate(func: Callable, x: np.ndarray, u: np.ndarray, name: str) -> np.ndarray:
    """func(x, u) as a float array; a failure is explained naming `name` and the point (x, u)."""
    return call_user_fast(func, (x, u), name, where=lambda: _at(x, u))


class StateSpace:
    """A linear time-invariant system in state-space form (1.24).

    Parameters
    ----------
    A : (n, n) array
        State matrix.
    B : (n, m) array, optional
        Input matrix; default: no input (m = 0). A 1-D array of length n is
        taken as a single column.
    C : (p, n) array, optional
        Output matrix; default: the identity (every state is measured).
    D : (p, m) array, optional
        Feedthrough matrix; default: zeros.
    dt : float, optional
        None for continuous time (1.19); the sampling period for discrete
        time (1.18).
    name : str, optional
        Used in plots and in the repr.

    Examples
    --------
    The mass-spring-damper (1.57) with m = 1, d = 0.5, k = 2:

    >>> sys = StateSpace([[0, 1], [-2, -0.5]], [[0], [1]], [[1, 0]])
    >>> sys.n, sys.m, sys.p
    (2, 1, 1)
    """

    def __init__(self, A, B=None, C=None, D=None, dt=None, *, name: str = ""):
        self.A = as_square(A, "A")
        n = self.A.shape[0]
        why_n = f"one per state, since A is {n}x{n}"
        if B is None:
            self.B = np.zeros((n, 0))
        else:
            self.B = as_matrix(B, "B", rows=n, rows_why=why_n, cols=1 if np.ndim(B) == 1 else None)
        m = self.B.shape[1]
        self.C = np.eye(n) if C is None else as_matrix(
            C, "C", cols=n, cols_why=why_n, rows=1 if np.ndim(C) == 1 else None)
        p = self.C.shape[0]
        self.D = np.zeros((p, m)) if D is None else as_matrix(
            D, "D", rows=p, cols=m, rows_why=f"one per output, since C has {p} rows",
            cols_why=f"one per input, since B has {m} columns")
        self.dt = as_dt(dt, "dt")
        self.name = str(name)

    @property
    def n(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    @property
    def m(self) -> int:
        """Number of inputs."""
        return self.B.shape[1]

    @property
    def p(self) -> int:
        """Number of outputs."""
        return self.C.shape[0]

    @property
    def is_discrete(self) -> bool:
        """True for a difference equation x(t+1) = A x(t) + B u(t)."""
        return self.dt is not None

    def f(self, x, u) -> np.ndarray:
        """Right-hand side A x + B u (dx/dt, or x(t+1) in discrete time) (1.24).

        x is (n,) and u (m,), or a batch: x (n, k) and u (m, k), states and
        inputs as columns, giving (n, k); a column x (n, 1) is a batch of one
        and needs u (m, 1). Other shapes, None or NaN/inf raise ValueError
        naming x or u (u may be None or empty when m = 0).
        """
        x, u = _state_and_input(x, u, self.n, self.m)
        return self._apply(self.A, self.B, x, u)

    def h(self, x, u) -> np.ndarray:
        """Output C x + D u (1.24), with the shapes of `f`: (p,) or (p, k)."""
        x, u = _state_and_input(x, u, self.n, self.m)
        return self._apply(self.C, self.D, x, u)

    @staticmethod
    def _apply(M, N, x, u) -> np.ndarray:
        """M x + N u for one state or a batch (n, ...) of them."""
        flat_x = x.reshape(x.shape[0], -1)
        flat_u = u.reshape(u.shape[0], flat_x.shape[1])
        return (M @ flat_x + N @ flat_u).reshape((M.shape[0],) + x.shape[1:])

    def poles(self) -> np.ndarray:
        """Eigenvalues of A, i.e. the poles of the system (section 3.2)."""
        return np.linalg.eigvals(self.A)

    def raw_field(self) -> Callable:
        """f(x, u) = A x + B u (1.24) without the argument checks of `f`, for hot loops."""
        A, B = self.A, self.B
        return lambda x, u: A @ x + B @ u

    def raw_output(self) -> Callable:
        """h(x, u) = C x + D u (1.24) without the argument checks of `h`, for hot loops."""
        C, D = self.C, self.D
        return lambda x, u: C @ x + D @ u

    def __repr__(self) -> str:
        kind = "continuous" if self.dt is None else f"discrete, dt={self.dt:g}"
        title = f" {self.name!r}" if self.name else ""
        parts = [f"StateSpace{title}: n={self.n}, m={self.m}, p={self.p} ({kind})"]
        for label in "ABCD":
            mat = getattr(self, label)
            if mat.size:
                body = np.array2string(mat, precision=4, suppress_small=True, prefix="    ")
                parts.append(f"  {label} = {body}")
        return "\n".join(parts)

    # Bridges to python-control and SciPy (coursekit/_bridges.py): exact copies of A, B, C, D, dt.

    @classmethod
    def from_control(cls, sys) -> "StateSpace":
        """The python-control ``StateSpace`` `sys` as a coursekit StateSpace (dt=0 -> continuous)."""
        from ._bridges import from_control
        return from_control(sys, cls)

    def to_control(self):
        """This system as a python-control ``StateSpace`` (continuous -> dt=0; needs `pip install control`)."""
        from ._bridges import to_control
        return to_control(self)

    @classmethod
    def from_scipy(cls, sys) -> "StateSpace":
        """The ``scipy.signal.StateSpace`` `sys` (continuous or discrete) as a coursekit StateSpace."""
        from ._bridges import from_scipy
        return from_scipy(sys, cls)

    def to_scipy(self):
        """This system as a ``scipy.signal.StateSpace`` (continuous: dt=None; discrete: its dt)."""
        from ._bridges import to_scipy
        return to_scipy(self)


class NonlinearSystem:
    """A nonlinear system x' = f(x, u), y = h(x, u) (1.32)-(1.33).

    Parameters
    ----------
    f : callable
        ``f(x, u)`` returns dx/dt as n numbers (or x(t+1) when `dt` is set).
        `x` is a 1-D array of length n and `u` a 1-D array of length m
        (empty when m = 0).
    n : int
        Number of states.
    m : int
        Number of inputs (default 0).
    h : callable, optional
        ``h(x, u)`` returns the outputs; default ``y = x``.
    dt : float, optional
        None for continuous time, the sampling period for discrete time (1.27).
    name : str, optional
        Used in plots and in the repr.
    params : dict, optional
        The physical parameters the system was built with, for display.
    """

    def __init__(self, f: Callable, n: int, m: int = 0, h: Callable | None = None, dt=None,
                 *, name: str = "", params: dict | None = None):
        if not callable(f):
            raise ValueError(f"f must be a function f(x, u) returning dx/dt: received {type(f).__name__}.")
        if h is not None and not callable(h):
            raise ValueError(f"h must be a function h(x, u) returning y: received {type(h).__name__}.")
        self.n = int(as_scalar(n, "n", positive=True, integer=True))
        self.m = int(as_scalar(m, "m", integer=True))
        if self.m < 0:
            raise ValueError(f"m must be >= 0: received {m!r}.")
        self._f = f
        self._h = h
        self.dt = as_dt(dt, "dt")
        self.name = str(name)
        self.params = dict(params or {})

    @property
    def is_discrete(self) -> bool:
        """True for a map x(t+1) = f(x(t), u(t))."""
        return self.dt is not None

    def f(self, x, u) -> np.ndarray:
        """Evaluate the vector field f(x, u).

        x is (n,) and u (m,), or a batch (n, ...) and (m, ...) for a
        function written on the rows x[0], x[1], ...; other shapes, None or
        NaN/inf raise ValueError naming x or u (u may be None or empty when
        m = 0). When the user's f raises, or returns None, complex numbers
        or NaN/inf, `UserFunctionError` (a ValueError) names f and the point.
        """
        x, u = _state_and_input(x, u, self.n, self.m)
        return _evaluate(self._f, x, u, "f")

    def h(self, x, u) -> np.ndarray:
        """Evaluate the output map h(x, u) (x itself by default); shapes and errors as in `f`."""
        x, u = _state_and_input(x, u, self.n, self.m)
        if self._h is None:
            return x.copy()
        return np.atleast_1d(_evaluate(self._h, x, u, "h"))

    def check(self, x, u, *, where: str = "") -> None:
        """Call f, and h if given, once at (x, u) and explain what is wrong.

        Raises `UserFunctionError` (a ValueError) when either raises or
        returns None or NaN/inf, naming the function and `where` (e.g.
        "at t = 0, x = [1. 0.]"), and ValueError when f does not return n
        numbers.
        """
        word = "x(t+1)" if self.is_discrete else "dx/dt"
        checked_call(self._f, (x, u), "f", size=self.n, where=where,
                     what=f"{word}, one entry per state for n={self.n}")
        if self._h is not None:
            call_user(self._h, (x, u), "h", where=where)

    def raw_field(self) -> Callable:
        """The user's own f(x, u), without the checks and the error wrapping of `f`.

        For hot loops (`simulate`) and for callers that call it with context of their own
        ("at t = 0.4"), where `f` would wrap an already explained `UserFunctionError` again.
        """
        return self._f

    def raw_output(self) -> Callable | None:
        """The user's own h(x, u) as `raw_field` gives f, or None when y = x (no h given)."""
        return self._h

    def __repr__(self) -> str:
        kind = "continuous" if self.dt is None else f"discrete, dt={self.dt:g}"
        title = f" {self.name!r}" if self.name else ""
        extra = ", ".join(f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v!r}"
                          for k, v in self.params.items())
        return f"NonlinearSystem{title}: n={self.n}, m={self.m} ({kind})" + (f"; {extra}" if extra else "")


