"""Simulation of continuous- and discrete-time systems: `simulate`.

Three paths, chosen from the system and the input:

* continuous LTI with an array input (or none): exact. The input is taken as
  linear between samples (as `scipy.signal.lsim` and python-control do) and
  the solution formula (2.4) is evaluated over each step with one matrix
  exponential of an augmented matrix, so the result has no integration error
  and works for any `A`, diagonalizable or not. On a uniform grid the
  resulting recursion runs through a Schur form, one first-order recursion
  per eigenvalue (see `_recurse`), with no Python loop over samples;
* discrete-time systems (1.18), (1.27): the difference equation is iterated;
* everything else (nonlinear systems, inputs given as a function `u(t, x)`):
  `scipy.integrate.solve_ivp` with the DOP853 method and tight tolerances
  (rtol=1e-9, atol=1e-12 by default).

Nothing hangs and nothing fails silently: the options are checked before anything runs, the
user's functions are called once at the start and watched at every evaluation (`_Model`), and
the errors say when and why (`simulate`, Raises).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._arguments import as_system
from ._pairs import as_pair
from ._stepping import check_finite, overflow_error, step_matrices
from ._validation import (agrees_column_by_column, as_matrix, as_scalar, as_series, as_time_grid, as_vector,
                          call_user, checked_call, is_uniform)
from .diagnostics import SimulationError, UserFunctionError
from .systems import NonlinearSystem, StateSpace

__all__ = ["simulate", "simulate_batch", "SimulationResult", "lti_step_matrices"]

# the method names scipy.integrate.solve_ivp accepts
_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
# solve_ivp raises a smaller rtol to 100 eps (with only a warning); coursekit refuses it instead
_RTOL_MIN = 100 * np.finfo(float).eps
# beyond sqrt(largest float) ~ 1.3e154 the square of a state entry overflows: any model with
# a quadratic term returns inf there, which is the state's growth, not a bug in the model
_HUGE = float(np.sqrt(np.finfo(float).max))


@dataclass(repr=False)
class SimulationResult:
    """What `simulate` returns; every series is time-major.

    Attributes
    ----------
    t : (N,) array      -- the time grid
    x : (N, n) array    -- the state at each time
    y : (N, p) array    -- the output at each time
    u : (N, m) array    -- the input that was applied at each time
    system : StateSpace or NonlinearSystem -- the simulated system
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    system: object

    def __repr__(self) -> str:
        name = getattr(self.system, "name", "") or type(self.system).__name__
        return (f"SimulationResult of {name}: {self.t.size} samples from t={self.t[0]:g} "
                f"to t={self.t[-1]:g}; x {self.x.shape}, y {self.y.shape}, u {self.u.shape}")

    def plot(self, *, which: str = "xu", **kwargs):
        """Plot the response (see `coursekit.plotting.plot_response`); returns the figure."""
        from .plotting import plot_response
        return plot_response(self, which=which, **kwargs)


def simulate(sys, t, u=None, x0=None, *, rtol: float = 1e-9, atol: float = 1e-12,
             method: str = "DOP853") -> SimulationResult:
    """Simulate `sys` on the time grid `t`.

    Parameters
    ----------
    sys : StateSpace or NonlinearSystem
    t : (N,) array
        Strictly increasing times. For a discrete-time system the grid must
        step by ``sys.dt`` (e.g. ``np.arange(N) * dt``).
    u : None, (N, m) array or callable, optional
        None means zero input. An array gives the input at each time; in
        continuous time it is taken as linear between samples. A callable
        ``u(t, x)`` returns the m inputs at time t and state x: open-loop
        signals ignore x, state feedback ``u = K x`` uses it (3.17).
    x0 : (n,) array, optional
        Initial state (default zero).
    rtol, atol, method :
        Tolerances and method of `scipy.integrate.solve_ivp`, used for
        nonlinear systems and callable inputs only; the exact LTI path
        ignores them, but they are checked on every path. `rtol` is a number
        in [2.2e-14, 1) (100 machine epsilons is the smallest solve_ivp
        works with), `atol` a number > 0 or one per state (in the states'
        units), `method` one of "RK45", "RK23", "DOP853", "Radau", "BDF",
        "LSODA" or an `OdeSolver` subclass. Pick "LSODA" or "Radau" for a
        stiff system.

    Returns
    -------
    SimulationResult with ``t, x, y, u`` (time-major) and ``.plot()``.
    Every number in it is finite.

    Raises
    ------
    ValueError
        A bad argument, named: a shape, NaN, a tolerance or a method.
    UserFunctionError (a ValueError)
        f, h or u raised, returned NaN/inf or the wrong number of values,
        at the start or at any later time; the message names the function,
        the time t and the state x.
    SimulationError (a ValueError and a RuntimeError)
        The state left the float range, or the ODE solver stopped early; the
        message gives the time and, for a StateSpace, the growth rate from the
        eigenvalues of A (section 3.2.2). This is an error, not a warning: a
        result holding inf/NaN plots as a curve that silently stops, and
        whatever is computed from it is meaningless; the error says up to
        which time the simulation is meaningful. Also raised, naming `method`,
        when the work would be unbounded: an explicit method on a stiff system
        (refused before starting, or as soon as the stiffness appears on the
        way) or more than a million evaluations of f.
    """
    sys = as_system(sys, hint="build one with StateSpace(A, B, C, D) or NonlinearSystem(f, n, m).")
    t = as_time_grid(t, "t", min_points=1 if sys.is_discrete else 2)
    x0 = np.zeros(sys.n) if x0 is None else as_vector(
        x0, "x0", size=sys.n, why=f"one per state of the {sys.n}-state system")
    options = _solver_options(rtol, atol, method, sys.n)
    u_arr, u_fun, u_user = _input(sys, t, u, x0)
    model = _Model(sys, u_fun, u_user)
    if isinstance(sys, NonlinearSystem):
        sys.check(x0, u_fun(t[0], x0) if u_fun else u_arr[0], where=_where(t[0], x0))
    if sys.is_discrete:
        _check_discrete_grid(t, sys.dt)
    # numpy's overflow warnings would only precede the SimulationError that explains them
    with np.errstate(over="ignore"):
        if sys.is_discrete:
            x, u_arr = _iterate(model, t, x0, u_arr)
        elif isinstance(sys, StateSpace) and u_fun is None:
            x = _lti_exact(sys, t, x0, u_arr)
        else:
            x = _integrate(model, t, x0, options)
            u_arr = _inputs_on_grid(model, t, x)
    check_finite(sys, t, x, feedback=u_user is not None)
    return SimulationResult(t=t, x=x, y=_outputs(sys, t, x, u_arr), u=u_arr, system=sys)


def simulate_batch(sys, t, x0s, u=None, *, rtol: float = 1e-9, atol: float = 1e-12,
                   method: str = "DOP853") -> np.ndarray:
    """Simulate many initial states at once as one stacked ODE.

    Much faster than a loop of `simulate` calls when a figure needs dozens of
    trajectories (a region of attraction, a fan of initial angles), because
    the solver runs once on the stacked state.

    Parameters
    ----------
    sys : StateSpace or continuous NonlinearSystem
        For a NonlinearSystem, ``f(x, u)`` must also accept a batch: `x` of
        shape (n, k) and `u` of shape (m, k), returning (n, k). Functions
        written with numpy operations on the rows ``x[0], x[1], ...`` do
        (all of `coursekit.models` do); this is checked once before integrating.
    t : (N,) array
    x0s : (k, n) array
        One initial state per row.
    u : callable, optional
        ``u(t, X)`` with X of shape (n, k) returning (m, k), e.g.
        ``lambda t, X: K @ X`` for state feedback; default zero input.
    rtol, atol, method :
        As in `simulate` (atol may give one value per state).

    Returns
    -------
    x : (N, k, n) array -- ``x[:, j]`` is the trajectory from ``x0s[j]``.

    Raises the errors of `simulate`, with the same guards: f and u are
    checked at the start (each initial state on its own, then the batch)
    and at every evaluation; a failure names the function, the time and
    the trajectory.
    """
    sys = as_system(sys, time="continuous", hint="simulate_batch integrates an ODE; for a "
                    "discrete-time system call simulate once per initial state.")
    t = as_time_grid(t, "t")
    X0 = as_matrix(x0s, "x0s", cols=sys.n, cols_why="one column per state")
    n, k, m = sys.n, X0.shape[0], sys.m
    options = _solver_options(rtol, atol, method, n, copies=k)
    if u is not None and not callable(u):
        raise ValueError(f"u must be a function u(t, X) returning ({m}, k) inputs for the batch X "
                         f"(n, k) of states, or None: received {type(u).__name__}.")
    u_batch = (lambda tk, X: np.zeros((m, X.shape[1]))) if u is None else u
    model = _Model(sys, None, u_batch)
    _check_batch(model, t[0], X0.T)
    with np.errstate(over="ignore"):   # the SimulationError explains an overflow
        x = _integrate_batch(model, t, X0.T, options)
    check_finite(sys, t, x.reshape(t.size, n * k), feedback=u is not None)
    return x.reshape(t.size, n, k).transpose(0, 2, 1)


def _integrate_batch(model, t: np.ndarray, X0: np.ndarray, options: dict) -> np.ndarray:
    """The stacked ODE X' = f(X, u(t, X)), guarded and bounded like `_integrate`; (N, n k) on the grid t."""
    from scipy.integrate import solve_ivp
    (n, k), m = X0.shape, model.sys.m
    f, u, last, calls = model.f, model.u_user, [t[0], X0], [0]
    def first(z):  # the first initial state as a batch of one
        return np.ravel(f(z[:, None], np.asarray(u(t[0], z[:, None]), dtype=float).reshape(m, 1)))

    _check_explicit_work(first, t, X0[:, 0], options)

    def rhs(tk, flat):
        X = last[1] = flat.reshape(n, k)
        last[0] = tk
        calls[0] += 1
        if calls[0] % _RECHECK_EVERY == 0:
            _recheck(calls[0], lambda z: np.ravel(f(z[:, None], np.asarray(u(tk, z[:, None]), dtype=float)
                                                    .reshape(m, 1))), t, X[:, 0].copy(), options, tk)
        try:
            F = np.asarray(f(X, np.asarray(u(tk, X), dtype=float).reshape(m, k)), dtype=float)
            if F.size == n * k and _screen(F):
                return F.reshape(-1)
        except Exception as err:
            model.fail_batch(tk, X, err)
        if F.size == n * k and np.isfinite(F).all():   # the screen's sum overflowed
            return F.reshape(-1)
        model.fail_batch(tk, X)

    sol = solve_ivp(rhs, (t[0], t[-1]), X0.ravel(), t_eval=t, **options)
    if not sol.success or np.size(sol.t) != t.size:
        raise _solver_failure(model.sys, sol, last)
    return sol.y.T


def _check_batch(model, t0: float, X: np.ndarray) -> None:
    """Check once that f and u accept a batch and agree with column-by-column calls.

    Each initial state is checked on its own first (`NonlinearSystem.check`:
    an exception, NaN/inf or a wrong shape named with x0s[j]), then the batch.
    """
    sys = model.sys
    U = _batch_input(model.u_user, t0, X, sys.m)
    if isinstance(sys, NonlinearSystem):
        for j in range(X.shape[1]):
            sys.check(X[:, j], U[:, j], where=f"{_where(t0, X[:, j])} (x0s[{j}])")
    try:
        F = np.asarray(sys.f(X, U), dtype=float)
    except Exception as err:
        raise ValueError(f"f cannot be evaluated on a batch of states (shape {X.shape}): {err}; "
                         "write f with numpy operations on the rows x[0], x[1], ... "
                         "or use simulate for one initial state at a time.") from err
    if not agrees_column_by_column(sys.f, X, U, F):
        raise ValueError("f gives different results on a batch of states than one state at a time; "
                         "use simulate for one initial state at a time.")


def _batch_input(u, tk: float, X: np.ndarray, m: int) -> np.ndarray:
    """u(t, X) for a batch X (n, k), checked: finite and of shape (m, k)."""
    U = call_user(u, (tk, X), "u", where=f"at t = {tk:.6g} on the batch X of shape {X.shape}")
    if U.shape != (m, X.shape[1]):
        raise ValueError(f"u returned shape {U.shape} for a batch X of shape {X.shape}; "
                         f"expected ({m}, {X.shape[1]}), one column per initial state.")
    return U


def _solver_options(rtol, atol, method, n: int, copies: int = 1) -> dict:
    """rtol, atol and method for solve_ivp, checked before anything runs.

    A NaN or zero tolerance makes solve_ivp shrink its step for ever (with
    atol = 0 a state that passes through zero asks for unreachable accuracy),
    so they are refused here with the option's name. `copies` repeats a
    per-state atol for the stacked state of `simulate_batch`.
    """
    if (isinstance(rtol, float) and isinstance(atol, float) and _RTOL_MIN <= rtol < 1
            and 0 < atol < math.inf and method in _METHODS):
        return dict(rtol=rtol, atol=atol, method=method)   # the usual case, without array checks
    rtol = as_scalar(rtol, "rtol")
    if not _RTOL_MIN <= rtol < 1:
        raise ValueError(
            f"rtol must be between {_RTOL_MIN:.2g} (100 machine epsilons, the smallest relative "
            f"tolerance solve_ivp works with) and 1: received {rtol!r}; the default 1e-9 suits "
            "most systems."
        )
    atol = as_vector(atol, "atol")
    if atol.size not in (1, n):
        raise ValueError(f"atol must be one number or one per state ({n}): received {atol.size} entries.")
    if not np.all(atol > 0):
        raise ValueError(
            f"atol must be > 0: received {np.array2string(atol)}. With atol = 0 a state passing "
            "through zero asks for an accuracy the solver cannot reach; use a small positive value "
            "in the state's units (the default is 1e-12), one per state if their scales differ."
        )
    atol = float(atol[0]) if atol.size == 1 else np.repeat(atol, copies)
    return dict(rtol=rtol, atol=atol, method=_method(method))


def _method(method):
    """`method` if solve_ivp knows it (a name of `_METHODS` or an OdeSolver subclass)."""
    if isinstance(method, str) and method in _METHODS:
        return method
    if isinstance(method, type):
        from scipy.integrate import OdeSolver
        if issubclass(method, OdeSolver):
            return method
    close = [name for name in _METHODS if isinstance(method, str) and name.lower() == method.lower()]
    hint = f" (did you mean {close[0]!r}? the names are case-sensitive)" if close else ""
    raise ValueError(
        f"method must be one of {', '.join(map(repr, _METHODS))} (the methods of "
        f"scipy.integrate.solve_ivp) or an OdeSolver subclass: received {method!r}{hint}."
    )


def _where(tk, xk) -> str:
    """'at t = 0.5, x = [1. 2.]': where a user function was called, for error messages."""
    return f"at t = {float(tk):.6g}, x = {np.array2string(np.asarray(xk), precision=6)}"


class _Model:
    """x' = f(x, u(t, x)) (or x(t+1) = ...) as `simulate` evaluates it, failures explained.

    The hot paths (`input`, `step`, the solver's right-hand sides in
    `_integrate` and `_integrate_batch`) make plain calls and one finiteness
    test. On the first exception, NaN/inf or wrong size, `fail` repeats the
    calls through `call_user` and raises a `UserFunctionError` naming the
    function, the time and the state -- or a `SimulationError` when the state
    itself has left the float range.

    `u_fun(t, x)` is the input as the simulation uses it (the user's function
    with its value flattened, an interpolation or zero), `u_user` the user's
    own function (None for an array input).
    """

    def __init__(self, sys, u_fun, u_user=None):
        self.sys, self.u_fun, self.u_user = sys, u_fun, u_user
        self.f = sys.raw_field()

    def input(self, tk, xk) -> np.ndarray:
        """u(t, x), finite."""
        try:
            uk = self.u_fun(tk, xk)
            if _screen(uk):
                return uk
        except Exception as err:
            self.fail(tk, xk, err)
        return self.settle(tk, xk, uk, uk.size)

    def step(self, tk, xk, uk) -> np.ndarray:
        """f(x, u): dx/dt or x(t+1), n finite numbers."""
        try:
            value = self.f(xk, uk)
            if isinstance(value, np.ndarray) and value.shape == (self.sys.n,) and _screen(value):
                return value
        except Exception as err:
            self.fail(tk, xk, err, uk=uk)
        return self.settle(tk, xk, value, self.sys.n, uk=uk)

    def settle(self, tk, xk, value, size: int, *, uk=None) -> np.ndarray:
        """The slow path after the fast test failed: `value` as a flat float array when
        it is `size` finite numbers (a list, an (n, 1) answer, a sum that overflowed),
        else `fail`."""
        try:
            flat = np.asarray(value, dtype=float).reshape(-1)
            if flat.size == size and np.isfinite(flat).all():
                return flat
        except (TypeError, ValueError) as err:
            self.fail(tk, xk, err, uk=uk)
        self.fail(tk, xk, uk=uk)

    def fail(self, tk, xk, err=None, *, uk=None):
        """Raise the error that explains why u or f failed at time tk and state xk
        (`uk`: the input there when it is a sample of an array, not a function)."""
        where = _where(tk, xk)
        self._check_range(tk, xk)
        if self.u_fun is not None:
            uk = self._checked_input(tk, xk, where)
        self._check_state(tk, xk, uk, where)
        raise UserFunctionError(
            f"the model failed {where}, but u and f returned finite values when called again "
            "there: do they change between calls (a counter, random numbers)?") from err

    def _checked_input(self, tk, xk, where: str) -> np.ndarray:
        """u(t, x) through `call_user` and the shape check, for the user's function."""
        if self.u_user is None:
            return self.u_fun(tk, xk)
        m = self.sys.m
        return checked_call(self.u_user, (tk, xk), "u", size=m, where=where,
                            what=f"the {m} input(s) at time t and state x")

    def fail_batch(self, tk, X, err=None):
        """`fail` for a batch X (n, k): u once on the batch, then f trajectory by trajectory."""
        self._check_range(tk, X)
        U = _batch_input(self.u_user, tk, X, self.sys.m)
        for j in range(X.shape[1]):
            self._check_state(tk, X[:, j], U[:, j], f"{_where(tk, X[:, j])} (trajectory {j}, from x0s[{j}])")
        raise UserFunctionError(
            f"the model failed at t = {tk:.6g} on the batch of states, but u and f returned finite "
            "values when called again there: do they change between calls?") from err

    def _check_state(self, tk, xk, uk, where: str) -> None:
        """Return if f(xk, uk) gives n finite numbers; else raise: SimulationError when
        the state has left the float range, the error of `NonlinearSystem.check` otherwise."""
        try:
            value = np.asarray(self.f(xk, uk), dtype=float)
            if value.size == self.sys.n and np.isfinite(value).all():
                return
        except Exception:
            pass
        self._check_range(tk, xk)
        if isinstance(self.sys, StateSpace):
            raise overflow_error(self.sys, f"A x + B u left it {where}", feedback=self.u_user is not None)
        self.sys.check(xk, uk, where=where)

    def _check_range(self, tk, xk) -> None:
        """Raise `overflow_error` when the state is not finite or beyond `_HUGE`: then the
        failure is the state's growth, whatever u or f make of such a state."""
        if _out_of_range(xk):
            raise overflow_error(self.sys, f"the state reached {np.array2string(np.asarray(xk), precision=3)} "
                            f"at t = {tk:.6g}", feedback=self.u_user is not None)


def _out_of_range(x) -> bool:
    """True when x has inf/NaN entries or entries beyond `_HUGE`."""
    return not np.isfinite(x).all() or np.abs(x).max(initial=0.0) > _HUGE


def _screen(a: np.ndarray) -> bool:
    """Fast test that a holds no NaN/inf: its sum is finite (a few times cheaper than
    ``np.isfinite(a).all()`` on the small arrays of a right-hand side). A sum can
    also overflow from finite entries: callers settle a False with the exact test."""
    return math.isfinite(sum(a.reshape(-1).tolist()) if a.size <= 64 else a.sum())


def _solver_failure(sys, sol, last: list) -> SimulationError:
    """The error for solve_ivp stopping early; `last` is the (t, x) of its last
    evaluation of f (a trial step, so x is only shown when it has overflowed)."""
    tk, xk = last
    if _out_of_range(xk):
        return overflow_error(sys, f"the state reached {np.array2string(np.asarray(xk), precision=3)} "
                         f"at t = {tk:.6g}")
    reached = (f"the last sample it reached is t = {sol.t[-1]:.6g}, x = "
               f"{np.array2string(sol.y[:, -1], precision=4)}" if np.size(sol.t) else
               "it could not complete a first step")
    return SimulationError(
        f"the ODE solver stopped at t = {tk:.6g} ({reached}): {sol.message} Near this time the "
        "solution may grow without bound (a finite escape time) or change too fast for the "
        "method: for a stiff system try method='Radau' or method='LSODA'."
    )


def _input(sys, t: np.ndarray, u, x0: np.ndarray):
    """Return (u_arr, u_fun, u_user): the input as samples, or as a function u(t, x)
    (a callable u checked once at (t0, x0)), and the user's own function or None."""
    m = sys.m
    if u is None:
        zero = None if isinstance(sys, StateSpace) else (lambda tk, xk: np.zeros(m))
        return np.zeros((t.size, m)), zero, None
    if callable(u):
        checked_call(u, (t[0], x0), "u", size=m, where=_where(t[0], x0),
                     what=f"the {m} input(s) at time t and state x")

        def u_fun(tk, xk):
            value = np.asarray(u(tk, xk), dtype=float).reshape(-1)
            if value.size != m:
                raise ValueError(f"u returned {value.size} numbers, expected {m}")
            return value
        return None, u_fun, u
    if m == 0:
        raise ValueError("u was given, but the system has no input (m = 0); leave u=None.")
    u_arr = as_series(u, "u", samples=t.size, channels=m, channels_why="one column per input")
    if isinstance(sys, StateSpace) or sys.is_discrete:
        return u_arr, None, None

    def interpolated(tk, xk):
        return np.array([np.interp(tk, t, u_arr[:, j]) for j in range(m)])
    return u_arr, interpolated, None


def _check_discrete_grid(t: np.ndarray, dt: float) -> None:
    if t.size > 1 and not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
        raise ValueError(
            f"t must step by the system's sampling period dt={dt:g} for a discrete-time "
            f"system: received steps between {np.diff(t).min():g} and {np.diff(t).max():g}; "
            f"use t = np.arange(N) * {dt:g}."
        )


def _iterate(model, t, x0, u_arr):
    """Iterate x(k+1) = f(x(k), u(k)) (1.18) / (1.27), one step at a time, exactly as
    written; each step guarded (`_Model.input`, `_Model.step`)."""
    N, n, m = t.size, model.sys.n, model.sys.m
    x = np.empty((N, n))
    u_out = np.empty((N, m))
    x[0] = x0
    for k in range(N):
        u_out[k] = model.input(t[k], x[k]) if model.u_fun else u_arr[k]
        if k + 1 < N:
            x[k + 1] = model.step(t[k], x[k], u_out[k])
    return x, u_out


def lti_step_matrices(A, B, h):
    """Exact one-step matrices for x' = A x + B u with u linear over a step h.

    Returns ``(Ad, B0, B1)`` with ``x(k+1) = Ad x(k) + B0 u(k) + B1 u(k+1)``,
    from the matrix exponential of the augmented matrix
    ``[[A h, B h, 0], [0, 0, I], [0, 0, 0]]`` -- the integral in (2.4)
    evaluated in closed form for a piecewise-linear input.

    Raises ValueError for a non-square A, a B without one row per state, or
    a step h that is not a finite number > 0; `SimulationError` when
    e^(A h) is beyond the float range (an unstable A and a long step).
    """
    A, B = as_pair(A, B)
    return step_matrices(A, B, as_scalar(h, "h", positive=True))


def _lti_exact(sys: StateSpace, t: np.ndarray, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Exact response of a continuous LTI system to a piecewise-linear input."""
    if is_uniform(t):
        Ad, B0, B1 = step_matrices(sys.A, sys.B, t[1] - t[0])
        return _recurse(Ad, x0, [(B0, u[:-1]), (B1, u[1:])])
    x = np.empty((t.size, sys.n))
    x[0] = x0
    cache = {}
    for k, h in enumerate(np.diff(t)):
        key = round(float(h), 12)
        if key not in cache:
            cache[key] = step_matrices(sys.A, sys.B, h)
        Ad, B0, B1 = cache[key]
        x[k + 1] = Ad @ x[k] + B0 @ u[k] + B1 @ u[k + 1]
    return x


def _recurse(Ad: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """Run x(k+1) = Ad x(k) + w(k) from x(0) = x0, with w(k) = sum of Bj uj(k).

    `terms` is a list of pairs ``(Bj, uj)``, each `uj` with one row per step.
    Fast and exact for any Ad, diagonalizable or not: in a Schur basis
    Ad = Z S Z^T (S block upper triangular) the coordinates z = Z^T x obey
    z_i(k+1) = S_ii z_i(k) + [v_i(k) + sum_{j>i} S_ij z_j(k)], v = Z^T w.
    The last block depends on nothing else; solving the blocks from the last
    to the first, each is a recursion of order one (a real eigenvalue) or two
    (a complex pair) solved over the whole time axis at once by
    `_first_order`, with no Python loop over samples.
    """
    from scipy.linalg import schur
    S, Z = schur(Ad, output="real")
    blocks = _schur_blocks(S)
    pairs = {i: _pair_modes(S[i:i + 2, i:i + 2]) for i, size in blocks if size == 2}
    if any(mode is None for mode in pairs.values()):
        return _recurse_complex(Ad, x0, terms)
    z = _projected_input(Z, x0, terms)
    for i, size in reversed(blocks):
        _solve_block(S, z, i, size, pairs.get(i))
    _to_original_basis(Z, z)
    x = z.T  # time-major view of the (n, N) array: columns contiguous, no copy
    x[0] = x0  # exactly, not after a round trip through the Schur basis
    return x


def _schur_blocks(S: np.ndarray) -> list:
    """(start, size) of the 1x1 and 2x2 diagonal blocks of a real Schur form."""
    blocks, i, n = [], 0, S.shape[0]
    while i < n:
        size = 2 if i + 1 < n and S[i + 1, i] != 0.0 else 1
        blocks.append((i, size))
        i += size
    return blocks


def _pair_modes(M: np.ndarray):
    """Eigen-decomposition (lambda, p, r) of a 2x2 block with a complex pair, or None.

    With M = P diag(lambda, conj(lambda)) P^-1, p the first column of P and r the
    first row of P^-1, a real recursion y(k+1) = M y(k) + e(k) is
    y = 2 Re(p q) with q(k+1) = lambda q(k) + r e(k): one complex first-order
    filter. In closed form, for M = [[a, b], [c, d]] with a complex pair
    lambda = (a + d)/2 + i w: p = [b, lambda - a], r = [conj(lambda) - a, -b] / (-2 i w b).
    None when P is badly conditioned (cond > 1e4: a nearly repeated eigenvalue).
    """
    (a, b), (c, d) = M
    half = 0.5 * (a - d)
    w = np.sqrt(-(half * half + b * c))
    lam = complex(0.5 * (a + d), w)
    p = np.array([b, lam - a])
    # P = [p, conj(p)]: its squared singular values are |p|^2 +- |p^T p|
    norm2, overlap = float(np.vdot(p, p).real), abs(p @ p)
    if norm2 - overlap <= 1e-8 * (norm2 + overlap):
        return None
    r = np.array([lam.conjugate() - a, -b]) / (-2j * w * b)
    return lam, p, r


def _projected_input(Z: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """z(0) = Z^H x0 and z(k+1) slots holding v(k) = Z^H w(k), as an (n, N) array.

    One matrix product writes all the inputs' contributions into place:
    ``[Z^H B1, Z^H B2, ...]`` times the inputs side by side, transposed.
    """
    ZH = Z.conj().T
    N = terms[0][1].shape[0] + 1
    z = np.empty((x0.size, N), dtype=np.result_type(Z, x0))
    z[:, 0] = ZH @ x0
    G = ZH @ np.hstack([Bj for Bj, _ in terms])
    W = np.hstack([uj for _, uj in terms])
    np.matmul(G, W.T, out=z[:, 1:])
    return z


def _to_original_basis(Z: np.ndarray, z: np.ndarray) -> None:
    """Overwrite z (n, N) with x = Z z, a slab of time samples at a time.

    Each sample transforms on its own, so working in place through slabs of
    about 128 kB needs no second n-by-N array (whose fresh pages would cost
    as much as the product itself).
    """
    width = max(1, 16384 // z.shape[0])
    for start in range(0, z.shape[1], width):
        slab = z[:, start:start + width]
        slab[...] = Z @ slab


def _solve_block(S: np.ndarray, z: np.ndarray, i: int, size: int, modes) -> None:
    """Replace rows i..i+size-1 of z (input on entry) by the block's solution."""
    k = i + size
    if k < S.shape[0]:
        z[i:k, 1:] += S[i:k, k:] @ z[k:, :-1]
    if size == 1:
        # y(0) = z_i(0), y(k+1) = S_ii y(k) + input(k)
        z[i] = _first_order(S[i, i], z[i])
        return
    lam, p, r = modes
    q = _first_order(lam, r[0] * z[i] + r[1] * z[i + 1])
    for row, pj in zip((i, i + 1), 2.0 * p):  # z_row = 2 Re(p_j q), without complex temporaries
        np.multiply(pj.real, q.real, out=z[row])
        z[row] -= pj.imag * q.imag


def _first_order(a, v: np.ndarray) -> np.ndarray:
    """y(0) = v(0), y(k) = a y(k-1) + v(k) for all k, as one forward substitution.

    The recursion is the unit lower-bidiagonal system y(k) - a y(k-1) = v(k);
    LAPACK's banded triangular solve (?tbtrs, no pivoting) runs it in compiled
    code -- the same operations as ``scipy.signal.lfilter([1], [1, -a], v)``,
    without importing scipy.signal (most of a second) for it. `v` may be
    overwritten.
    """
    from scipy.linalg import lapack
    cplx = np.iscomplexobj(v) or np.iscomplexobj(a)
    dtype = complex if cplx else float
    band = np.empty((2, v.size), dtype=dtype)  # band storage: diagonal row, then the row below
    band[0] = 1.0
    band[1] = -a
    solve = lapack.ztbtrs if cplx else lapack.dtbtrs
    y, _ = solve(band, np.asarray(v, dtype=dtype)[:, None], uplo="L", diag="U", overwrite_b=1)
    return y[:, 0]


def _recurse_complex(Ad: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """`_recurse` through the complex Schur form: triangular, so robust when
    eigenvalues nearly coincide, at about twice the cost."""
    from scipy.linalg import schur
    S, Z = schur(Ad, output="complex")
    z = _projected_input(Z, x0, terms)
    for i in range(x0.size - 1, -1, -1):
        _solve_block(S, z, i, 1, None)
    x = (z.real.T @ Z.real.T) - (z.imag.T @ Z.imag.T)
    x[0] = x0
    return x


# The solver's work is bounded without a clock. An explicit method on a stiff system takes
# steps of about R / |lambda| (R: the method's stability interval on the negative real axis)
# and evaluates f a fixed number of times per step, so its work is about
# _EVALUATIONS_PER_UNIT * |lambda| * span evaluations of f, |lambda| the fastest rate of the
# Jacobian. A run whose estimate at x0 exceeds _MAX_EVALUATIONS is refused before starting. The
# stiffness can also appear later on the trajectory (the Van der Pol oscillator from x0 = [1, 0]),
# so the estimate is repeated every _RECHECK_EVERY evaluations at the current state over the time
# still to go, against the evaluations left; any run is stopped after _MAX_EVALUATIONS
# evaluations of f whatever happens (about six seconds of a cheap f).
#: evaluations per step / R, rounded down (the estimate errs on the side of running)
_EVALUATIONS_PER_UNIT = {"RK23": 3 / 2.5, "RK45": 6 / 3.3, "DOP853": 12 / 6}
_MAX_EVALUATIONS = 1_000_000
_RECHECK_EVERY = 10_000


def _fastest_rate(field, x: np.ndarray) -> float:
    """|lambda|max of the Jacobian of `field` at x; NaN when it cannot be estimated there."""
    from ._derivatives import numerical_jacobian
    try:
        with np.errstate(all="ignore"):
            J = numerical_jacobian(field, x, refine=False)
            return float(np.abs(np.linalg.eigvals(J)).max()) if np.isfinite(J).all() else math.nan
    except Exception:  # f fails near x: the guarded integration reports it
        return math.nan


def _check_explicit_work(field, t: np.ndarray, x0: np.ndarray, options: dict, *,
                         tk: float | None = None, calls: int = 0) -> None:
    """Refuse an explicit method whose stability limit alone asks for more evaluations of f than
    are left of `_MAX_EVALUATIONS` (`calls` made so far).

    `field(x)` is dx/dt (with the input applied) at t[0], or at `tk` when the test is
    repeated during the run at the current state x0; its Jacobian gives |lambda|. A rate that
    cannot be estimated (NaN: f fails near x) refuses nothing: the guarded evaluations of f
    report the failure, and the bound on evaluations still holds.
    """
    per_unit = _EVALUATIONS_PER_UNIT.get(options["method"])
    if per_unit is None:   # an implicit method or the user's own OdeSolver
        return
    rate = _fastest_rate(field, x0)
    span = float(t[-1] - (t[0] if tk is None else tk))
    work = per_unit * rate * span
    if not work > _MAX_EVALUATIONS - calls:   # NaN compares false
        return
    where = "at x0" if tk is None else f"at t = {tk:.6g}, x = {np.array2string(x0, precision=4)},"
    became = "" if tk is None else (f" The system became stiff on the way (after {calls:,} evaluations "
                                    "of f).")
    raise SimulationError(
        f"method={options['method']!r} cannot finish in bounded work: the fastest mode of f {where} "
        f"has rate |lambda| = {rate:.3g}, so an explicit method needs steps of about 1/|lambda|, "
        f"roughly {work:.2g} evaluations of f over the {span:.3g} time units "
        f"{'of t' if tk is None else 'still to go'}, more than the {_MAX_EVALUATIONS - calls:,} left of "
        f"the {_MAX_EVALUATIONS:,} a run may take.{became} If that mode decays fast (a stiff "
        "system), pass method='Radau' or method='LSODA' (implicit methods), which take large "
        "steps there; if it oscillates, simulate a shorter time span."
    )


def _recheck(calls: int, field, t: np.ndarray, xk: np.ndarray, options: dict, tk: float) -> None:
    """Every `_RECHECK_EVERY` evaluations: the stiffness test at the current state, then the bound."""
    if calls >= _MAX_EVALUATIONS:
        raise _work_exceeded(options, tk, t)
    _check_explicit_work(field, t, xk, options, tk=tk, calls=calls)


def _work_exceeded(options: dict, tk: float, t: np.ndarray) -> SimulationError:
    return SimulationError(
        f"the ODE solver (method={options['method']!r}) evaluated f {_MAX_EVALUATIONS:,} times "
        f"and reached only t = {tk:.6g} of {t[-1]:.6g}: the system is stiff or very fast there. "
        "Pass method='Radau' or method='LSODA' for a stiff system, or simulate a shorter time span."
    )


def _integrate(model, t, x0, options: dict) -> np.ndarray:
    """Integrate x' = f(x, u(t, x)) with solve_ivp, returning x on the grid t.

    Every evaluation is guarded (a plain call and one finiteness test, see
    `_Model`): NaN/inf would otherwise make the solver shrink its step for ever.
    The work is bounded (`_check_explicit_work`, `_MAX_EVALUATIONS`).
    """
    from scipy.integrate import solve_ivp
    f, u_fun, n, last = model.f, model.u_fun, model.sys.n, [t[0], x0]
    shape, ndarray, isfinite = (n,), np.ndarray, math.isfinite
    _check_explicit_work(lambda z: f(z, u_fun(t[0], z)), t, x0, options)
    calls = [0]

    def rhs(tk, xk):
        last[0], last[1] = tk, xk
        calls[0] += 1
        if calls[0] % _RECHECK_EVERY == 0:
            _recheck(calls[0], lambda z: f(z, u_fun(tk, z)), t, np.array(xk), options, tk)
        try:
            dx = f(xk, u_fun(tk, xk))
            # the fast test of `_screen`, inlined: this runs at every evaluation
            if type(dx) is ndarray and dx.shape == shape and isfinite(sum(dx.tolist())):
                return dx
        except Exception as err:
            model.fail(tk, xk, err)
        return model.settle(tk, xk, dx, n)

    sol = solve_ivp(rhs, (t[0], t[-1]), x0, t_eval=t, **options)
    if not sol.success or np.size(sol.t) != t.size:
        raise _solver_failure(model.sys, sol, last)
    return sol.y.T


def _inputs_on_grid(model, t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """u(t_k, x_k) at every sample (N, m), checked once at the end (`_Model.input`
    explains the first bad sample)."""
    u_fun, m = model.u_fun, model.sys.m
    try:
        u = np.array([u_fun(tk, xk) for tk, xk in zip(t, x)], dtype=float).reshape(t.size, m)
        if np.isfinite(u).all():
            return u
    except Exception:
        pass
    return np.array([model.input(tk, xk) for tk, xk in zip(t, x)]).reshape(t.size, m)


def _outputs(sys, t: np.ndarray, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """y at every sample: C x + D u, x itself, or the model's h, checked once at the
    end (`_output_failure` explains the first bad sample)."""
    if isinstance(sys, StateSpace):
        y = x @ sys.C.T + u @ sys.D.T
        check_finite(sys, t, y)
        return y
    h, rows = sys.raw_output(), []
    if h is None:
        return x.copy()
    try:
        for xk, uk in zip(x, u):
            rows.append(np.asarray(h(xk, uk), dtype=float).reshape(-1))
        y = np.array(rows)
        if y.ndim == 2 and np.isfinite(y).all():
            return y
    except Exception:
        pass
    for k in range(t.size):
        _output_failure(sys, t[k], x[k], u[k], rows[0].size if rows else None)
    raise UserFunctionError("h failed during the simulation, but returned finite values at every "
                            "sample when called again: does it change between calls?")


def _output_failure(sys, tk, xk, uk, size) -> None:
    """Raise the error that explains why h fails at time tk, if it does (call_user's wording)."""
    where = _where(tk, xk)
    value = call_user(sys.raw_output(), (xk, uk), "h", where=where)
    if size is not None and value.size != size:
        raise UserFunctionError(f"h returned {value.size} numbers {where}, but {size} at the start; "
                                "h must return the same number of outputs at every time.")
