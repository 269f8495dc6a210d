"""Linear approximation of a nonlinear system around an equilibrium (section 3.4.2).

* `linearize(f, x_eq, u_eq)` returns the Jacobians A = df/dx and B = df/du at
  (x*, u*) (3.80), computed numerically with central differences refined by
  Richardson extrapolation (error of order h^4, about 1e-10 relative for smooth f);
* `symbolic_jacobian(f, variables)` is the Jacobian matrix (3.65) of sympy
  expressions, and `linearize_symbolic(f, x, u, x_eq, u_eq)` evaluates it
  at an equilibrium, giving (A, B) as exact sympy matrices.

The linear model describes the deviations dx = x - x*, du = u - u* (3.61),
(3.77): d(dx)/dt = A dx + B du (3.79).
"""

from __future__ import annotations

from functools import cache
from typing import Callable

import numpy as np

from ._validation import as_scalar, as_vector
from .systems import NonlinearSystem, StateSpace

__all__ = ["linearize", "symbolic_jacobian", "linearize_symbolic"]


def _vector_field(f, x_eq, u_eq):
    """Return (g, x, u, n, m, dt): g(x, u) -> float array, whatever form f has."""
    if isinstance(f, (NonlinearSystem, StateSpace)):
        n, m, dt = f.n, f.m, f.dt
        x = as_vector(x_eq, "x_eq", size=n, why=f"one per state of the {n}-state system")
        u = np.zeros(m) if u_eq is None else as_vector(
            u_eq, "u_eq", size=m, why=f"one per input of the system with m={m}")
        if m == 0:
            u = np.zeros(0)
        return f.f, x, u, n, m, dt
    if not callable(f):
        raise ValueError(
            f"f must be a NonlinearSystem or a function f(x, u) returning dx/dt: received "
            f"{type(f).__name__}."
        )
    x = as_vector(x_eq, "x_eq")
    u = np.zeros(0) if u_eq is None else as_vector(u_eq, "u_eq")
    return (lambda xx, uu: np.asarray(f(xx, uu), dtype=float)), x, u, x.size, u.size, None


def _central(g: Callable, z: np.ndarray, h: np.ndarray, k: int) -> np.ndarray:
    """(g(z + h_k e_k) - g(z - h_k e_k)) / (2 h_k): one column of the Jacobian."""
    step = np.zeros_like(z)
    step[k] = h[k]
    return (g(z + step) - g(z - step)) / (2 * h[k])


_CBRT_EPS = float(np.cbrt(np.finfo(float).eps))


def _filter_steps(z: np.ndarray) -> np.ndarray:
    """The steps h_k ~ eps^(1/3) max(1, |z_k|) of the unrefined central difference."""
    return _CBRT_EPS * np.maximum(1.0, np.abs(z))


@cache
def _signs(n: int) -> np.ndarray:
    """[I, -I, 0], shape (n, 2n + 1), read-only: the pattern of `_perturbed`."""
    E = np.hstack([np.eye(n), -np.eye(n), np.zeros((n, 1))])
    E.flags.writeable = False
    return E


def _perturbed(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(Z, h): the states of the unrefined central difference as the columns of Z (n, 2n + 1).

    Column k is z + h_k e_k, column n + k is z - h_k e_k (the numbers
    `_jacobian(g, z, refine=False)` evaluates g at, one call each) and the
    last column is z itself; h = `_filter_steps(z)`.
    """
    h = _filter_steps(z)
    return z[:, None] + _signs(z.size) * h[:, None], h


def _quotients(G: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The Jacobian (q, n) from G (q, 2n + 1), g evaluated on the columns of `_perturbed`.

    Column k is (g(z + h_k e_k) - g(z - h_k e_k)) / (2 h_k), as in `_jacobian(g,
    z, refine=False)`, from one call of g on a batch instead of 2n calls.
    """
    n = h.size
    return (G[:, :n] - G[:, n:2 * n]) / (2 * h)


def _jacobian(g: Callable, z: np.ndarray, *, refine: bool = True) -> np.ndarray:
    """Numerical Jacobian of g at z by central differences.

    ``refine=True`` adds Richardson extrapolation (about 1e-10 relative, for
    `linearize`); ``refine=False`` is one central difference with step
    ~ eps^(1/3) (about 1e-8 relative, half the evaluations: for filters that
    need a Jacobian at every step).
    """
    if not refine:
        h = _filter_steps(z)
        return np.column_stack([np.ravel(_central(g, z, h, k)) for k in range(z.size)])
    J = np.empty((np.ravel(g(z)).size, z.size))
    # step ~ eps^(1/5) balances the h^4 truncation and the rounding error
    h = 1e-3 * np.maximum(1.0, np.abs(z))
    for k in range(z.size):
        D1 = _central(g, z, h, k)
        D2 = _central(g, z, h / 2, k)
        # Richardson: the h^2 error terms cancel in (4 D(h/2) - D(h)) / 3
        J[:, k] = np.ravel((4 * D2 - D1) / 3)
    return J


def linearize(f, x_eq, u_eq=None, *, dt=None, check_equilibrium: bool = True,
              tol: float = 1e-8):
    """Jacobians (A, B) of f at the equilibrium (x*, u*): implements (3.78)-(3.80).

    Parameters
    ----------
    f : NonlinearSystem or callable
        The system, or a function ``f(x, u)`` returning dx/dt (x(t+1) in
        discrete time) as n numbers.
    x_eq : (n,) array
        The equilibrium x*.
    u_eq : (m,) array, optional
        The input u* that holds x* (3.59); omit it for a system without input.
    dt : float, optional
        Only for a bare function in discrete time; a NonlinearSystem brings its own.
    check_equilibrium : bool
        If True (default), raise ValueError unless f(x*, u*) = 0 (continuous
        time) or f(x*, u*) = x* (discrete time, 3.53) to within `tol`
        relative: the linear model (3.79) needs an equilibrium.

    Returns
    -------
    A : (n, n) array  -- df/dx at (x*, u*)
    B : (n, m) array  -- df/du at (x*, u*) (m = 0 columns without input)

    The derivatives are central differences refined by Richardson
    extrapolation, accurate to about 1e-10 relative for smooth f.
    """
    g, x, u, n, m, sys_dt = _vector_field(f, x_eq, u_eq)
    dt = sys_dt if dt is None else as_scalar(dt, "dt", positive=True)
    f0 = np.ravel(g(x, u))
    if f0.size != n:
        raise ValueError(f"f returned {f0.size} numbers at x_eq; expected {n} (one per state).")
    if check_equilibrium:
        _check_equilibrium(f0, x, u, dt, tol)
    # (3.80): A = df/dx (x*, u*),  B = df/du (x*, u*)
    A = _jacobian(lambda z: g(z, u), x)
    B = _jacobian(lambda w: g(x, w), u) if m else np.zeros((n, 0))
    return A, B


def _check_equilibrium(f0, x, u, dt, tol) -> None:
    # (3.49) in continuous time, (3.53) in discrete time
    residual = f0 - x if dt is not None else f0
    scale = max(1.0, float(np.abs(x).max(initial=0)), float(np.abs(u).max(initial=0)))
    if np.abs(residual).max(initial=0) > tol * scale:
        rule = "f(x*, u*) = x* (3.53)" if dt is not None else "f(x*, u*) = 0 (3.49)"
        raise ValueError(
            f"x_eq, u_eq is not an equilibrium: {rule} fails with residual "
            f"{np.array2string(residual, precision=3)}. Find u* with equilibrium_input(f, x_eq) "
            "or x* with find_equilibria, or pass check_equilibrium=False to linearize "
            "around a point that is not an equilibrium."
        )


def symbolic_jacobian(f, variables):
    """The Jacobian matrix (3.65) of sympy expressions: entry (i, j) = d f_i / d v_j.

    `f` is a list (or sympy Matrix) of expressions, `variables` a list of symbols.
    """
    import sympy as sp
    F = _sympy_column(f, "f")
    V = _sympy_column(variables, "variables")
    if not all(isinstance(v, sp.Symbol) for v in V):
        raise ValueError(f"variables must be sympy symbols: received {list(V)!r}.")
    return F.jacobian(V)


def linearize_symbolic(f, x, u=None, x_eq=None, u_eq=None):
    """Exact (A, B) of sympy expressions f(x, u) at (x*, u*): (3.80) symbolically.

    `x` and `u` are lists of symbols; `x_eq` and `u_eq` are lists of values
    (numbers or expressions) of the same length. Returns sympy matrices,
    simplified; without `u` B has zero columns.
    """
    import sympy as sp
    X = _sympy_column(x, "x")
    U = _sympy_column(u, "u") if u is not None else sp.zeros(0, 1)
    if x_eq is None:
        raise ValueError("x_eq is missing: pass the equilibrium as a list, e.g. [sp.pi, 0].")
    subs = dict(zip(X, _values(x_eq, len(X), "x_eq")))
    if len(U):
        if u_eq is None:
            raise ValueError("u_eq is missing: pass the input u* that holds the equilibrium.")
        subs.update(zip(U, _values(u_eq, len(U), "u_eq")))
    A = sp.simplify(symbolic_jacobian(f, list(X)).subs(subs))
    B = sp.simplify(symbolic_jacobian(f, list(U)).subs(subs)) if len(U) else sp.zeros(len(X), 0)
    return A, B


def _sympy_column(values, name: str):
    import sympy as sp
    try:
        M = sp.Matrix(values)
    except (TypeError, ValueError, sp.SympifyError):
        raise ValueError(f"{name} must be a list of sympy expressions: received {values!r}.") from None
    if M.shape[1] != 1:
        M = M.reshape(len(M), 1)
    return M


def _values(values, size: int, name: str) -> list:
    vals = list(values) if isinstance(values, (list, tuple)) else list(np.ravel(values))
    if len(vals) != size:
        raise ValueError(f"{name} has the wrong length: received {len(vals)} values, expected {size}.")
    return vals
