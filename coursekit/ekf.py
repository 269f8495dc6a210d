"""The extended Kalman filter (section 4.7, (4.91)-(4.93)): `extended_kalman_filter`.

For a `NonlinearSystem`, the equations of `kalman_bucy` with A(t), C(t) the
Jacobians of f and h at the estimate x̂(t). Integrated with the RK4 steps of
`coursekit._filter_ode`. The numerical Jacobians call f and h once per
evaluation on a batch of perturbed states when they accept one (all
`coursekit.models` do). Q and R are intensities (see `coursekit.kalman`).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._arguments import as_system
from ._derivatives import difference_quotients, numerical_jacobian, perturbed_states
from ._filter_ode import checked_substeps, filter_setup, initial_estimate, records, run_filter
from ._validation import agrees_column_by_column, call_user_fast
from .diagnostics import UserFunctionError
from .kalman_bucy import KalmanResult

__all__ = ["extended_kalman_filter"]


def _ekf_rhs(model, Q, R, m: int):
    """rhs(x, P, w, t) -> (x̂', P', L, A - L C) of (4.91), (4.88), (4.87) at w = [u, y], time t.

    Products are written ``a.dot(b)``: the same numbers as ``a @ b``, with half
    the call overhead on these small arrays (rhs runs four times per RK4 step).
    """
    Rinv = np.linalg.inv(R)

    def rhs(x, P, w, t):
        u, y = w[:m], w[m:]
        fx, hx, A, C = model(x, u, t)
        # (4.87): L = P C^T R^{-1}
        L = P.dot(C.T).dot(Rinv)
        # (4.91): x̂' = f(x̂, u) + L (y - h(x̂, u))
        dx = fx + L.dot(y - hx)
        # (4.88): Ṗ = A P + P A^T - P C^T R^{-1} C P + Q = (A - L C) P + P A^T + Q
        M = A - L.dot(C)
        return dx, M.dot(P) + P.dot(A.T) + Q, L, M
    return rhs


def _accepts_batches(fun, x0: np.ndarray, u0: np.ndarray) -> bool:
    """True when fun(X, U), states and inputs as columns, agrees column by column with
    fun(x, u) on single states (within 1e-12), checked on the states of `perturbed_states(x0)`.

    The test of `simulation._check_batch`, but a function written for one state at a
    time (``float(x[0])``, ``if x[0] > 0``, ...) is an answer, not an error; so is a
    function that raises here (it is then called one state at a time, and an error it
    raises there is reported with its context).
    """
    X, _ = perturbed_states(x0)
    U = u0[:, None].repeat(X.shape[1], axis=1)
    try:
        batch = np.asarray(fun(X, U), dtype=float)
        return agrees_column_by_column(fun, X, U, batch)
    except Exception:                   # written for one state at a time
        return False


def _output_map(sys):
    """The user's h(x, u), or y = x when the system has none."""
    return sys.raw_output() or (lambda x, u: np.array(x, dtype=float))


def _at(t: float) -> str:
    return f"at t = {t:.6g}"


def _user(fun, name: str, *, batch: bool = False):
    """(x, u, t) -> fun(x, u) as a finite float array, or a `UserFunctionError` naming
    `name` and the time t (`_validation.call_user_fast`: the EKF calls f and h four times
    per RK4 step, so the common case costs one finiteness check)."""
    extra = " (on x̂ and its central-difference neighbours, as columns)" if batch else ""

    def call(x, u, t):
        return call_user_fast(fun, (x, u), name, where=lambda: _at(t) + extra)
    return call


def _user_jacobian(fun, name: str, shape: tuple[int, int], what: str):
    """(x, u, t) -> the user's Jacobian fun(x, u) of the given shape, checked like `_user`."""
    call = _user(fun, name)

    def jacobian(x, u, t):
        J = call(x, u, t)
        if J.size != shape[0] * shape[1]:
            raise UserFunctionError(f"{name} returned shape {J.shape} {_at(t)}; expected {shape} "
                                    f"({what}).")
        return J.reshape(shape)
    return jacobian


def _batched_model(f, h, n: int):
    """(x, u, t) -> (f, h, ∂f/∂x, ∂h/∂x) at (x, u) from one call of f and one of h on the
    batch of `perturbed_states(x)`: x and its 2n central-difference neighbours as columns."""
    cols = 2 * n + 1
    f, h = _user(f, "f", batch=True), _user(h, "h", batch=True)

    def model(x, u, t):
        X, step = perturbed_states(x)
        U = u[:, None].repeat(cols, axis=1)
        G = np.concatenate((f(X, U, t).reshape(-1, cols), h(X, U, t).reshape(-1, cols)))
        J = difference_quotients(G, step)
        return G[:n, -1], G[n:, -1], J[:n], J[n:]
    return model


def _ekf_model(sys, p: int, dfdx, dhdx, x0, u0):
    """(x, u, t) -> (f(x, u), h(x, u), A, C), A and C the Jacobians (4.92)-(4.93).

    dfdx and dhdx where given, else one central difference per state with
    step ~ eps^(1/3) max(1, |x_k|) (about 1e-8 relative: cheaper than the
    checked Ridders derivatives of `linearize`, which one step of a filter
    does not need). When both are numerical
    and f and h accept a batch of states (`_accepts_batches`, checked once
    here, as it holds for every `coursekit.models` system), each is called
    once per evaluation (`_batched_model`); otherwise once per perturbed state.
    Every call of f, h, dfdx, dhdx goes through `call_user`: an exception or
    NaN/inf is reported as a `UserFunctionError` naming the function and t.
    """
    for fun, name in ((dfdx, "dfdx"), (dhdx, "dhdx")):
        if fun is not None and not callable(fun):
            raise ValueError(f"{name} must be a function (x, u) -> Jacobian, or None for "
                             f"numerical differences: received {type(fun).__name__}.")
    n = sys.n
    f_raw, h_raw = sys.raw_field(), _output_map(sys)   # wrapped once, by _user, with the time
    if dfdx is None and dhdx is None and _accepts_batches(f_raw, x0, u0) \
            and _accepts_batches(h_raw, x0, u0):
        return _batched_model(f_raw, h_raw, n)
    f, h = _user(f_raw, "f"), _user(h_raw, "h")
    jf = _user_jacobian(dfdx, "dfdx", (n, n), "∂f/∂x (4.92), n x n") if dfdx else \
        (lambda x, v, t: numerical_jacobian(lambda z: f(z, v, t), x, refine=False))
    jh = _user_jacobian(dhdx, "dhdx", (p, n), "∂h/∂x (4.93), p x n") if dhdx else \
        (lambda x, v, t: numerical_jacobian(lambda z: h(z, v, t), x, refine=False))
    return lambda x, v, t: (f(x, v, t), h(x, v, t), jf(x, v, t), jh(x, v, t))


def extended_kalman_filter(sys, t, u, y, Q, R, P0, x0, *, dfdx: Callable | None = None,
                           dhdx: Callable | None = None, substeps: int = 1) -> KalmanResult:
    """Extended Kalman filter (4.91)-(4.93) for a continuous-time `NonlinearSystem`.

    x̂' = f(x̂, u) + L(t) (y - h(x̂, u)) (4.91), with L(t) and P(t) from
    (4.87)-(4.88) where A(t) = ∂f/∂x (4.92) and C(t) = ∂h/∂x (4.93) are
    evaluated at the estimate x̂(t). `dfdx(x, u)` -> (n, n) and
    `dhdx(x, u)` -> (p, n) may be supplied; by default they are computed by
    one central difference per state (step ~ eps^(1/3) max(1, |x_k|), about
    1e-8 relative; `linearize` uses the slower, checked Ridders derivatives).

    `u` (N, m) or None and `y` (N, p) are the recorded data on the grid `t`;
    Q, R are intensities, P0 > 0 the initial P, x0 the initial estimate.
    Unlike the linear filter, the EKF has no optimality guarantee and may
    diverge from a poor x0 or with badly chosen Q, R.

    Errors: every call of f, h, dfdx and dhdx is checked; an exception it
    raises, or NaN/inf it returns, becomes a `UserFunctionError` (a
    ValueError) naming the function and the time t. A divergent estimate
    (non-finite x̂ or P) raises RuntimeError with the time; the number of
    RK4 steps per sample interval is bounded, so no call can hang.
    """
    sys = as_system(sys, kind="nonlinear", time="continuous", hint="for a StateSpace use kalman_bucy.")
    t, u, y = records(t, u, y, sys.m)
    x0 = initial_estimate(x0, sys.n)
    _user(sys.raw_field(), "f")(x0, u[0], t[0])
    sys.check(x0, u[0])
    p_h = _user(_output_map(sys), "h")(x0, u[0], t[0]).size
    if p_h != y.shape[1]:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, expected "
                         f"{p_h} (the number of outputs of sys.h).")
    Q, R, P0, x0 = filter_setup(sys.n, p_h, Q, R, P0, x0)
    model = _ekf_model(sys, p_h, dfdx, dhdx, x0, u[0])
    xs, Ps, Ls = run_filter(_ekf_rhs(model, Q, R, sys.m), t, np.hstack([u, y]), P0, x0,
                            checked_substeps(substeps))
    return KalmanResult(t=t, x=xs, P=Ps, L=Ls)
