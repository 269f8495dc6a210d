"""System objects: linear state-space models and nonlinear vector fields.

`StateSpace` holds the matrices of (1.24), x' = A x + B u, y = C x + D u
(or x(t+1) = A x(t) + B u(t) in discrete time, when `dt` is set).
`NonlinearSystem` holds the vector field f of (1.32) and the output map h
of (1.33). Both expose `f(x, u)` and `h(x, u)` so that `simulate` treats
them alike.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._validation import as_matrix, as_scalar, as_square, check_function_output

__all__ = ["StateSpace", "NonlinearSystem"]


def _check_dt(dt, name: str = "dt") -> float | None:
    return None if dt is None else as_scalar(dt, name, positive=True)


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
        self.dt = _check_dt(dt)
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
        """Right-hand side A x + B u (dx/dt, or x(t+1) in discrete time)."""
        return self.A @ x + self.B @ u

    def h(self, x, u) -> np.ndarray:
        """Output C x + D u."""
        return self.C @ x + self.D @ u

    def poles(self) -> np.ndarray:
        """Eigenvalues of A, i.e. the poles of the system (section 3.2)."""
        return np.linalg.eigvals(self.A)

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

    # Bridges to python-control and SciPy (coursekit/bridges.py): exact copies of A, B, C, D, dt.

    @classmethod
    def from_control(cls, sys) -> "StateSpace":
        """The python-control ``StateSpace`` `sys` as a coursekit StateSpace (dt=0 -> continuous)."""
        from .bridges import from_control
        return from_control(sys)

    def to_control(self):
        """This system as a python-control ``StateSpace`` (continuous -> dt=0; needs `pip install control`)."""
        from .bridges import to_control
        return to_control(self)

    @classmethod
    def from_scipy(cls, sys) -> "StateSpace":
        """The ``scipy.signal.StateSpace`` `sys` (continuous or discrete) as a coursekit StateSpace."""
        from .bridges import from_scipy
        return from_scipy(sys)

    def to_scipy(self):
        """This system as a ``scipy.signal.StateSpace`` (continuous: dt=None; discrete: its dt)."""
        from .bridges import to_scipy
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
        self.dt = _check_dt(dt)
        self.name = str(name)
        self.params = dict(params or {})

    @property
    def is_discrete(self) -> bool:
        """True for a map x(t+1) = f(x(t), u(t))."""
        return self.dt is not None

    def f(self, x, u) -> np.ndarray:
        """Evaluate the vector field f(x, u)."""
        return np.asarray(self._f(x, u), dtype=float)

    def h(self, x, u) -> np.ndarray:
        """Evaluate the output map h(x, u) (x itself by default)."""
        if self._h is None:
            return np.asarray(x, dtype=float)
        return np.atleast_1d(np.asarray(self._h(x, u), dtype=float))

    def output_size(self, x, u) -> int:
        """Number of outputs, found by evaluating h once at (x, u)."""
        return self.h(np.asarray(x, float), np.asarray(u, float)).size

    def check(self, x, u) -> None:
        """Call f once at (x, u) and explain a wrong return shape (ValueError)."""
        word = "x(t+1)" if self.is_discrete else "dx/dt"
        check_function_output(self._f, (x, u), "f", size=self.n,
                              what=f"{word}, one entry per state for n={self.n}")

    def __repr__(self) -> str:
        kind = "continuous" if self.dt is None else f"discrete, dt={self.dt:g}"
        title = f" {self.name!r}" if self.name else ""
        extra = ", ".join(f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v!r}"
                          for k, v in self.params.items())
        return f"NonlinearSystem{title}: n={self.n}, m={self.m} ({kind})" + (f"; {extra}" if extra else "")
