"""Equilibrium points of nonlinear systems, with and without input (section 3.4.1).

An equilibrium x* with its input u* solves f(x*, u*) = 0 in continuous time
(3.49), (3.55) and x* = f(x*, u*) in discrete time (3.53).

* `find_equilibria(f, u_eq, guesses)`: numerically, with `scipy.optimize.root`
  started from several points; the solutions are deduplicated;
* `equilibrium_input(f, x_eq)`: the input u* that holds a chosen x* (3.56)-(3.59);
* `symbolic_equilibria(f, unknowns)`: all solutions with `sympy.solve`.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._validation import (as_dt, as_integer, as_matrix, as_scalar, as_vector, call_user, foreign_library,
                          function_name, input_size_explained, sympy_column)
from .diagnostics import UserFunctionError
from .systems import NonlinearSystem, StateSpace

__all__ = ["find_equilibria", "equilibrium_input", "symbolic_equilibria"]


def _field(f, n=None, dt=None):
    """Return (func, name, n, m or None, dt) for a system or a bare function f(x, u)."""
    if foreign_library(f):
        f = as_system(f, "f")
    if isinstance(f, (NonlinearSystem, StateSpace)):
        return f.raw_field(), function_name(f.raw_field()), f.n, f.m, f.dt
    if not callable(f):
        raise ValueError(
            f"f must be a NonlinearSystem or a function f(x, u) returning dx/dt: received "
            f"{type(f).__name__}."
        )
    return f, function_name(f), n, None, dt


def _residual(func, name: str, dt, task: str, *, finite: bool = False):
    """r(x, u) = f(x, u) (3.49), or f(x, u) - x (3.53) in discrete time.

    f is called through `call_user`: an exception it raises becomes a
    `UserFunctionError` naming it, the point and the `task`. NaN and inf pass
    through unless `finite` (a solver may step outside the model's domain;
    `_is_zero` rejects such points).
    """
    def r(x, u):
        where = f"at x = {x.tolist()}, u = {u.tolist()} ({task})"
        value = np.ravel(call_user(func, (x, u), name, where=where, finite=finite))
        return value - x if dt is not None else value
    return r


def _is_zero(r: np.ndarray, tol: float, *sizes: np.ndarray) -> bool:
    """|r| <= tol max(1, |sizes|), written so that NaN or inf never passes."""
    scale = max([1.0] + [float(np.abs(v).max(initial=0.0)) for v in sizes])
    return bool(np.all(np.abs(r) <= tol * scale)) and bool(np.all(np.isfinite(r)))


def find_equilibria(f, u_eq=None, guesses=None, *, n=None, dt=None, bounds=(-5.0, 5.0),
                    count: int = 30, seed: int = 0, tol: float = 1e-9):
    """Equilibria x* of f for the fixed input u* (3.49), (3.53), (3.55).

    Parameters
    ----------
    f : NonlinearSystem or callable f(x, u)
    u_eq : (m,) array, optional
        The constant input; zero (or no input) by default.
    guesses : (k, n) array, optional
        Starting points for the solver. Default: `count` random points drawn
        uniformly in the box `bounds` (seeded by `seed`) -- a solver only finds
        the equilibria near its starting points, so give guesses that cover
        the region you care about.
    n : int
        Number of states; needed only when f is a bare function and no
        guesses are given.
    dt : float, optional
        Sampling period for a bare discrete-time function (x* = f(x*, u*)).

    Returns
    -------
    (k, n) array of distinct equilibria (rows), sorted by their entries.
    Each satisfies |f(x*, u*)| <= tol max(1, |x*|) (|f(x*, u*) - x*| in
    discrete time); a NaN or inf residual never counts. Points closer than
    ``1e-6 * max(1, |x|)`` count as the same equilibrium.

    An exception raised by f becomes a `UserFunctionError` (a ValueError)
    naming the function, the point and the guess the search started from.
    Before searching, f is evaluated at every guess: it must return n numbers
    (ValueError otherwise; for a bare function without `n`, n is the number
    of columns of `guesses`, and the message names both), and it must be
    finite at one guess at least (`UserFunctionError` otherwise; NaN at some
    guesses is the edge of f's domain, and those searches fail quietly).
    `n`, `count` (>= 1), `seed`, `bounds` (low < high) and `tol` (> 0) are
    checked, each ValueError naming its argument.
    """
    if n is not None:
        n = as_integer(n, "n", minimum=1, why="the number of states of the system")
    func, name, n_sys, m, sys_dt = _field(f, n, dt)
    dt = sys_dt if dt is None else as_dt(dt)
    tol = as_scalar(tol, "tol", positive=True)
    u = _input(u_eq, m)
    X0 = _guesses(guesses, n_sys, bounds, count, seed)
    task = "find_equilibria, searching from the guess {}"
    with input_size_explained(u_eq, u, "find_equilibria"):
        _check_at_guesses(func, name, dt, u, X0, task, inferred=n_sys is None)
    from scipy.optimize import root
    found = []
    for x0 in X0:
        residual = _residual(func, name, dt, task.format(x0.tolist()))
        # a guess outside the model's domain (a square root of a negative state) fails quietly
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            sol = root(lambda x: residual(x, u), x0, method="hybr", tol=1e-12)
            if np.all(np.isfinite(sol.x)) and _is_zero(residual(sol.x, u), tol, sol.x):
                found.append(sol.x)
    return _unique(found, X0.shape[1])


def _check_at_guesses(func, name: str, dt, u, X0, task: str, *, inferred: bool) -> None:
    """Refuse an f that returns the wrong number of values, or NaN/inf at every guess.

    NaN at some guesses is a model's domain (a square root of a negative state)
    and those searches fail quietly; NaN at all of them leaves nothing to search
    from. `inferred`: the number of states was read off the guesses' columns.
    """
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        values = [_residual(func, name, dt, task.format(x0.tolist()))(x0, u) for x0 in X0[:1]]
        n = X0.shape[1]
        if values[0].size != n:
            source = " (taken from the columns of guesses)" if inferred else ""
            raise ValueError(
                f"{name} returned {values[0].size} numbers at x = {X0[0].tolist()}; expected {n}, "
                f"one per state{source}: dx/dt has one entry per state. Check that f returns "
                "every component of dx/dt" + (" and that guesses has one column per state."
                                              if inferred else ".")
            )
        values += [_residual(func, name, dt, task.format(x0.tolist()))(x0, u) for x0 in X0[1:]]
    if not any(np.all(np.isfinite(v)) for v in values):
        raise UserFunctionError(
            f"{name} returned NaN or inf at every one of the {len(X0)} starting points (e.g. "
            f"{np.array2string(values[0], precision=4)} at x = {X0[0].tolist()}), so no search "
            f"can start. Look in {name} for a division by zero or a square root or logarithm of "
            "a negative number, or give guesses inside the region where f is defined."
        )


def _input(u_eq, m):
    if u_eq is None:
        return np.zeros(m or 0)
    return as_vector(u_eq, "u_eq", size=m, why="one per input of the system") if m is not None \
        else as_vector(u_eq, "u_eq")


def _guesses(guesses, n, bounds, count, seed) -> np.ndarray:
    if guesses is not None:
        return as_matrix(guesses, "guesses", cols=n, cols_why="one column per state",
                         rows=1 if np.ndim(guesses) == 1 else None)
    if n is None:
        raise ValueError("n is missing: with a bare function f(x, u) and no guesses, pass n= (the "
                         "number of states) so that starting points can be drawn.")
    lo, hi = as_vector(bounds, "bounds", size=2, why="(low, high)")
    if not hi > lo:
        raise ValueError(f"bounds must be (low, high) with low < high: received {bounds!r}.")
    count = as_integer(count, "count", minimum=1, why="the number of random starting points")
    rng = np.random.default_rng(as_integer(seed, "seed", minimum=0))
    return rng.uniform(lo, hi, size=(count, int(n)))


def _unique(points, n: int) -> np.ndarray:
    distinct: list[np.ndarray] = []
    for p in points:
        if not any(np.abs(p - q).max() <= 1e-6 * max(1.0, np.abs(q).max()) for q in distinct):
            distinct.append(p)
    if not distinct:
        return np.zeros((0, n))
    out = np.array(distinct)
    # clean tiny round-off (e.g. -1e-17 -> 0) so results print and sort neatly
    out[np.abs(out) < 1e-12] = 0.0
    return out[np.lexsort(out.T[::-1])]


def equilibrium_input(f, x_eq, *, m=None, u_guess=None, tol: float = 1e-9) -> np.ndarray:
    """The input u* that makes x* an equilibrium: solves f(x*, u*) = 0 for u* (3.56)-(3.59).

    Uses least squares (`scipy.optimize.least_squares`) from `u_guess`
    (default zero) and raises ValueError when no input achieves f(x*, u*) = 0,
    i.e. when x* cannot be held by any constant input (for the pendulum
    (3.55): any x* with x2* != 0); a NaN or inf residual never passes. `m` is
    needed only for a bare function. An exception raised by f, or NaN/inf it
    returns at the starting input, becomes a `UserFunctionError` (a
    ValueError) naming the function and the point. Without `m`, a bare
    function takes the number of inputs from the length of `u_guess`; f must
    return one number per entry of `x_eq` (ValueError naming both otherwise).
    """
    func, name, n, m_sys, dt = _field(f)
    tol = as_scalar(tol, "tol", positive=True)
    x = as_vector(x_eq, "x_eq", size=n)
    u0 = _input_guess(m_sys, m, u_guess)
    task = "equilibrium_input, solving f(x_eq, u) = 0 for u"
    # the starting point must be finite, or the search has nowhere to go
    f0 = _residual(func, name, dt, task + " from u_guess", finite=True)(x, u0)
    if f0.size != x.size:
        raise ValueError(
            f"{name} returned {f0.size} numbers at x_eq = {x.tolist()}; expected {x.size}, one "
            "per entry of x_eq (dx/dt has one entry per state). Check that x_eq lists every "
            "state and that f returns every component of dx/dt."
        )
    residual = _residual(func, name, dt, task)
    from scipy.optimize import least_squares
    sol = least_squares(lambda u: residual(x, u), u0, xtol=1e-14, ftol=1e-14, gtol=1e-14)
    r = residual(x, sol.x)
    if not _is_zero(r, tol, x, sol.x):
        raise ValueError(
            f"x_eq = {x.tolist()} is not an equilibrium for any constant input: the smallest "
            f"residual f(x*, u*) found is {np.array2string(r, precision=3)}. Pick x_eq so "
            "that the rows of f without input can vanish (e.g. zero velocities)."
        )
    return sol.x


def _input_guess(m_sys, m, u_guess) -> np.ndarray:
    """The starting input: u_guess checked against m, or zeros(m); m read off u_guess if not given."""
    if m_sys is None and m is not None:
        m = as_integer(m, "m", minimum=1, why="equilibrium_input solves for an input")
    elif m_sys is not None:
        m = m_sys
    if u_guess is not None:
        u0 = as_vector(u_guess, "u_guess", size=m, why="one per input of the system")
        if u0.size:
            return u0
    if m is None or m < 1:
        raise ValueError("m must be the number of inputs (>= 1): pass m= (or a u_guess with one "
                         "entry per input) for a bare function f(x, u); a system without input has "
                         "no u* to find.")
    return np.zeros(m)


def symbolic_equilibria(f, unknowns, *, discrete: bool = False):
    """All solutions of f = 0 (or x = f(x) in discrete time, with `discrete=True`) by sympy.

    `f` is a list of sympy expressions in the state (and input) symbols;
    `unknowns` lists the symbols to solve for -- the states for a system
    without input (3.52), or e.g. ``[x2, u]`` to find the input that holds a
    chosen angle (3.56). Returns a list of dicts symbol -> value. With
    `discrete=True` the first ``len(f)`` unknowns must be the states.
    Periodic solutions are listed once (sympy returns e.g. 0 and pi for
    sin(x) = 0, not every multiple of pi). Declare state symbols with
    ``real=True``, not ``positive=True``: a positivity assumption silently
    removes the solutions at 0.
    """
    import sympy as sp
    F = list(sympy_column(f, "f"))
    X = list(sympy_column(unknowns, "unknowns", allow_empty=True)) if unknowns is not None else []
    if not X or not all(isinstance(v, sp.Symbol) for v in X):
        raise ValueError(f"unknowns must be a non-empty list of sympy symbols: received {unknowns!r}.")
    if discrete:
        F = [fi - xi for fi, xi in zip(F, X)]
    # simplify=False: sympy's general simplification of the intermediate equations is the slow
    # part (about 0.2 s for the pendulum (3.50)) and gives the same solutions for the
    # equilibria of the notes; each solution is still checked by substitution
    try:
        return sp.solve(F, X, dict=True, simplify=False)
    except NotImplementedError:
        # transcendental equations such as -x + 10 sin(x) = 0 have no closed form
        equation = "x = f(x) (3.53)" if discrete else "f = 0 (3.52)"
        raise ValueError(
            f"f: sympy finds no closed-form solution of {equation} for {X} (received the equations "
            f"{F} = 0; one like x = 10 sin(x), which mixes x with a function of x, has none). Find "
            "the equilibria numerically with find_equilibria(f, n=...), f a Python function f(x, u) "
            f"(sympy.lambdify turns the expressions into one){', with dt=1 for x = f(x)' if discrete else ''}."
        ) from None
