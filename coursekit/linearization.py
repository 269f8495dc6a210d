"""Linear approximation of a nonlinear system around an equilibrium (section 3.4.2).

* `linearize(f, x_eq, u_eq)` returns the Jacobians A = df/dx and B = df/du at
  (x*, u*) (3.80), computed numerically: exact to rounding along the directions
  in which f is affine; elsewhere central differences over a ladder of
  steps, refined by Richardson extrapolation, the most accurate one chosen by
  its error estimate (Ridders' method), so the accuracy does not depend on
  where the equilibrium lies (a pendulum that has turned 1000 times);
* `symbolic_jacobian(f, variables)` is the Jacobian matrix (3.65) of sympy
  expressions, and `linearize_symbolic(f, x, u, x_eq, u_eq)` evaluates it
  at an equilibrium, giving (A, B) as exact sympy matrices.

The linear model describes the deviations dx = x - x*, du = u - u* (3.61),
(3.77): d(dx)/dt = A dx + B du (3.79).

The numerical derivatives are `_derivatives`, shared with `simulate` and the EKF.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._derivatives import checked_jacobian
from ._validation import (as_dt, as_flag, as_scalar, as_vector, call_user, foreign_library, function_name,
                          input_size_explained, is_complex, is_text, sympy_column)
from .systems import NonlinearSystem, StateSpace

__all__ = ["linearize", "symbolic_jacobian", "linearize_symbolic"]


def _vector_field(f, x_eq, u_eq):
    """Return (func, name, x, u, n, m, dt): the user's f(x, u), how to name it, and the checked point."""
    if foreign_library(f):
        f = as_system(f, "f")
    if isinstance(f, (NonlinearSystem, StateSpace)):
        n, m, dt = f.n, f.m, f.dt
        x = as_vector(x_eq, "x_eq", size=n, why=f"one per state of the {n}-state system")
        u = np.zeros(m) if u_eq is None else as_vector(
            u_eq, "u_eq", size=m, why=f"one per input of the system with m={m}")
        if m == 0:
            u = np.zeros(0)
        return f.raw_field(), function_name(f.raw_field()), x, u, n, m, dt
    if not callable(f):
        raise ValueError(
            f"f must be a NonlinearSystem or a function f(x, u) returning dx/dt: received "
            f"{type(f).__name__}."
        )
    x = as_vector(x_eq, "x_eq")
    u = np.zeros(0) if u_eq is None else as_vector(u_eq, "u_eq")
    return f, function_name(f), x, u, x.size, u.size, None


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
        relative to max(1, |x*|, |u*|): the linear model (3.79) needs an
        equilibrium. A NaN or inf residual never passes.

    Returns
    -------
    A : (n, n) array  -- df/dx at (x*, u*)
    B : (n, m) array  -- df/du at (x*, u*) (m = 0 columns without input)

    Accuracy: a column along which f is affine (a straight line: linear
    dynamics, a bilinear term, an input that enters linearly) is exact to
    rounding at any scale of the coefficients: the central difference is then
    the same at every step, which four steps at the scale of (x*, u*) check
    (`_affine_column`), and the largest is taken. Every other column is the
    central difference (f(x + h e_k) - f(x - h e_k)) / 2h over a ladder of 30 steps halving from h = 1/4 (and, for
    |x_k| > 16, a second ladder from |x_k| / 4, used where it agrees),
    extrapolated (Richardson, up to h^12) and chosen by its error estimate
    (Ridders' method), which is cross-checked against a second ladder on
    other points (a noisy or kinked f makes the two disagree; where the
    largest steps alone disagree, as on a fast oscillation they cannot
    resolve, they are left out). The step does not grow with |x*|: for
    smooth f the result is accurate to about 1e-10 relative to each column's size,
    wherever x* lies (the pendulum at 1000 turns as at 0), and for
    polynomials and exponentials of large arguments as well. A column whose
    error estimate exceeds 1e-7 of its size gives an `AccuracyWarning` saying
    which one; a column that is NaN at every step raises ValueError. Steps at
    which f raises or returns NaN (outside its domain) are skipped.

    Errors raised by f itself, and NaN/inf it returns at (x*, u*), become a
    `UserFunctionError` (a ValueError) naming the function and the point.
    """
    func, name, x, u, n, m, sys_dt = _vector_field(f, x_eq, u_eq)
    dt = sys_dt if dt is None else as_dt(dt)
    tol = as_scalar(tol, "tol", positive=True)
    check_equilibrium = as_flag(check_equilibrium, "check_equilibrium",
                                hint="pass check_equilibrium=False to linearize around any point")

    def checked(xx, uu, where):
        return np.ravel(call_user(func, (xx, uu), name, where=where))

    with input_size_explained(u_eq, u, "linearize"):
        f0 = checked(x, u, f"at x_eq = {x.tolist()}, u_eq = {u.tolist()}")
    if f0.size != n:
        raise ValueError(f"{name} returned {f0.size} numbers at x_eq; expected {n} (one per state).")
    if check_equilibrium:
        _check_equilibrium(f0, x, u, dt, tol, name)
    # (3.80): A = df/dx (x*, u*),  B = df/du (x*, u*); straight lines are tried at the point's scale
    scale = max(1.0, float(np.abs(x).max(initial=0)), float(np.abs(u).max(initial=0)))
    A = checked_jacobian(lambda z: func(z, u), x, n, symbol="A", variable="x", name=name,
                          checked=lambda z, where: checked(z, u, where), scale=scale)
    B = (checked_jacobian(lambda w: func(x, w), u, n, symbol="B", variable="u", name=name,
                           checked=lambda w, where: checked(x, w, where), scale=scale)
         if m else np.zeros((n, 0)))
    return A, B


def _check_equilibrium(f0, x, u, dt, tol, name: str = "f") -> None:
    # (3.49) in continuous time, (3.53) in discrete time
    residual = f0 - x if dt is not None else f0
    scale = max(1.0, float(np.abs(x).max(initial=0)), float(np.abs(u).max(initial=0)))
    # written so that a NaN residual fails: NaN <= anything is False
    if not np.all(np.abs(residual) <= tol * scale):
        rule = "f(x*, u*) = x* (3.53)" if dt is not None else "f(x*, u*) = 0 (3.49)"
        raise ValueError(
            f"x_eq, u_eq is not an equilibrium of {name}: {rule} fails with residual "
            f"{np.array2string(residual, precision=3)}. Find u* with equilibrium_input(f, x_eq) "
            "or x* with find_equilibria, or pass check_equilibrium=False to linearize "
            "around a point that is not an equilibrium."
        )


def symbolic_jacobian(f, variables):
    """The Jacobian matrix (3.65) of sympy expressions: entry (i, j) = d f_i / d v_j.

    `f` is a list (or sympy Matrix) of expressions, `variables` a list of symbols.
    """
    import sympy as sp
    F = sympy_column(f, "f")
    V = sympy_column(variables, "variables")
    if not all(isinstance(v, sp.Symbol) for v in V):
        raise ValueError(f"variables must be sympy symbols: received {list(V)!r}.")
    return F.jacobian(V)


def linearize_symbolic(f, x, u=None, x_eq=None, u_eq=None):
    """Exact (A, B) of sympy expressions f(x, u) at (x*, u*): (3.80) symbolically.

    `x` and `u` are lists of symbols; `x_eq` and `u_eq` are lists of real
    values (numbers or expressions) of the same length; complex values raise
    ValueError. Returns sympy matrices,
    simplified; without `u` B has zero columns.
    """
    import sympy as sp
    X = sympy_column(x, "x")
    U = sympy_column(u, "u", allow_empty=True) if u is not None else sp.zeros(0, 1)
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


def _values(values, size: int, name: str) -> list:
    if is_text(values) or isinstance(values, (list, tuple)) and any(isinstance(v, str) for v in values):
        # sympy would read a text as a new symbol ("a" -> a): never passed on
        raise ValueError(f"{name} must contain numbers or sympy expressions: received the text {values!r}; "
                         "write the values themselves, e.g. [0] or [sp.pi, 0], without quotes.")
    vals = list(values) if isinstance(values, (list, tuple)) else list(np.ravel(values))
    if is_complex(vals):
        raise ValueError(f"{name} must contain real values: received {vals!r} with complex entries; "
                         "an equilibrium of a real system is real.")
    if len(vals) != size:
        raise ValueError(f"{name} has the wrong length: received {len(vals)} values, expected {size}.")
    return vals
