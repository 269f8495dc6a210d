"""How the continuous-time Kalman filters integrate their equations (internal).

`kalman_bucy` (coursekit.kalman_bucy) and `extended_kalman_filter` (coursekit.ekf)
both integrate the observer (4.86) / (4.91) together with the Riccati ODE (4.88)
and the gain (4.87) between the samples of a recorded grid, with the classical
fixed-step Runge-Kutta method (RK4) and u, y linear between samples. A step is
split automatically when (4.88) is fast compared with the grid (large P or
small R), so the filters stay stable on coarse grids; the number of steps per
sample interval is bounded, so no call can hang.

The names without an underscore are shared by those two modules:

* `records`, `initial_estimate`, `filter_setup`, `checked_substeps` -- the checks of
  the recorded data, of Q, R, P0 and x̂(0), and of `substeps`;
* `next_step`, `advance`, `all_finite`, `diverged` -- the adaptive RK4 step and
  its bounds;
* `rk4_interval`, `run_filter` -- RK4 on (4.91) and (4.88) for a right-hand side
  ``rhs(x, P, w, t) -> (x̂', P', L, A - L C)``.
"""

from __future__ import annotations

import math

import numpy as np

from ._validation import as_covariance, as_scalar, as_series, as_time_grid, as_vector

__all__ = ["records", "initial_estimate", "filter_setup", "checked_substeps", "next_step", "advance",
           "all_finite", "diverged", "rk4_interval", "run_filter"]


def records(t, u, y, m: int):
    """Validate the recorded grid, input (N, m) and measurement (N, p)."""
    t = as_time_grid(t, "t")
    N = t.size
    u = np.zeros((N, m)) if u is None else as_series(u, "u", samples=N, channels=m,
                                                     channels_why="one column per input")
    return t, u, as_series(y, "y", samples=N)


def _riccati_rate(M: np.ndarray) -> float:
    """How fast (4.88) moves near P, from M = A - L C: its linearization is
    dP' = M dP + dP M^T, whose eigenvalues are sums of two eigenvalues of M."""
    return 2.0 * float(np.abs(np.linalg.eigvals(M)).max())


def _radius_bound(M: np.ndarray) -> float:
    """An upper bound of max |eigenvalue of M|, cheap to evaluate.

    For 2 x 2 (the usual case here) the eigenvalues tr/2 +- sqrt(tr^2/4 - det)
    in closed form, enlarged by 1e-6 relative against rounding; otherwise the
    largest absolute row sum, which bounds every eigenvalue.
    """
    if M.shape == (2, 2):
        a, b, c, d = M.ravel().tolist()
        half_trace, det = (a + d) / 2, a * d - b * c
        disc = half_trace * half_trace - det
        radius = abs(half_trace) + math.sqrt(disc) if disc >= 0 else math.sqrt(abs(det))
        return radius * (1 + 1e-6) + 1e-300
    return float(np.abs(M).sum(axis=1).max())


def _step_length(M: np.ndarray, h_max: float) -> float:
    """min(h_max, 0.5 / rate) with the rate of `_riccati_rate`, from M = A - L C.

    The eigenvalues are only computed when they can matter: when even an
    upper bound of the rate allows h_max, the rate itself does too, and h_max
    is returned as is.
    """
    if 4.0 * h_max * _radius_bound(M) >= 1.0:
        return min(h_max, 0.5 / max(_riccati_rate(M), 1e-300))
    return h_max


def all_finite(a: np.ndarray, b: np.ndarray | None = None) -> bool:
    """True when no entry of a (and b) is inf or nan (a sum is finite only then)."""
    total = np.add.reduce(a, None)
    return math.isfinite(total if b is None else total + np.add.reduce(b, None))


_MAX_STEPS = 100_000


def next_step(tau: float, dt: float, substeps: int, M: np.ndarray) -> float:
    """Length of the RK4 step from tau inside a sample interval of length dt.

    At most dt / substeps and at most 0.5 / rate (`_step_length`, the rate of
    (4.88) at the current P, M = A - L C); stretched to the end of the
    interval when within 1e-9 dt of it.
    """
    h = _step_length(M, min(dt - tau, dt / substeps))
    return dt - tau if dt - tau - h < 1e-9 * dt else h


def advance(tau: float, h: float, dt: float, steps: int) -> tuple[float, int]:
    """(tau, steps) after a step of length h; RuntimeError past _MAX_STEPS steps."""
    steps += 1
    if steps > _MAX_STEPS:
        raise RuntimeError(
            f"the Riccati equation (4.88) needs more than {_MAX_STEPS} RK4 steps between two "
            "samples (its rate is huge): check the units of Q and R (docstring of "
            "coursekit.kalman), or start from a smaller P0.")
    return (dt if h == dt - tau else tau + h), steps


def diverged(t_k: float) -> RuntimeError:
    return RuntimeError(
        f"the filter diverged at t={t_k:g} (non-finite estimate or P); check the "
        "model, the units of Q and R, and try substeps=10.")


def rk4_interval(rhs, x, P, cur, w0, w1, t0: float, dt: float, substeps: int):
    """RK4 on (4.91) and (4.88) from t0 to the next sample t0 + dt, w = [u, y] linear in between.

    The step is at most dt / substeps and at most 0.5 / rate, the rate of
    (4.88) at the current P, so a fast start (large P0, small R) takes many
    short steps that lengthen as P settles. `cur` is rhs at the start; the
    value at the end is returned for the next interval, or None when x or P
    stopped being finite (the caller reports the divergence).
    """
    tau, steps, dw = 0.0, 0, w1 - w0
    while tau < dt:
        k1x, k1P, _, M = cur
        h = next_step(tau, dt, substeps, M)
        # w linear over the interval: w0 + s (w1 - w0) at s = (tau + h/2)/dt and (tau + h)/dt
        w_mid, w_end = w0 + (tau + h / 2) / dt * dw, w0 + (tau + h) / dt * dw
        t_mid, t_end = t0 + tau + h / 2, t0 + tau + h
        k2x, k2P, _, _ = rhs(x + h / 2 * k1x, P + h / 2 * k1P, w_mid, t_mid)
        k3x, k3P, _, _ = rhs(x + h / 2 * k2x, P + h / 2 * k2P, w_mid, t_mid)
        k4x, k4P, _, _ = rhs(x + h * k3x, P + h * k3P, w_end, t_end)
        x = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        P = P + h / 6 * (k1P + 2 * k2P + 2 * k3P + k4P)
        P = (P + P.T) / 2
        if not all_finite(x, P):
            return x, P, None
        tau, steps = advance(tau, h, dt, steps)
        cur = rhs(x, P, w_end, t_end)
    return x, P, cur


def run_filter(rhs, t, w, P0, x0, substeps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Integrate (4.91) and (4.87)-(4.88) with RK4 on the grid t (w = [u, y] per sample).

    Returns the estimate (N, n), P (N, n, n) and the gain L (N, n, p) at the samples.
    """
    N = t.size
    x, P = x0.copy(), P0.copy()
    cur = rhs(x, P, w[0], t[0])
    xs, Ps, Ls = np.empty((N,) + x.shape), np.empty((N,) + P.shape), np.empty((N,) + cur[2].shape)
    for k, dt in enumerate(np.diff(t).tolist()):
        xs[k], Ps[k], Ls[k] = x, P, cur[2]
        x, P, cur = rk4_interval(rhs, x, P, cur, w[k], w[k + 1], t[k], dt, substeps)
        if cur is None:
            raise diverged(t[k + 1])
    xs[-1], Ps[-1], Ls[-1] = x, P, cur[2]
    return xs, Ps, Ls


# RK4's error falls like h^4: 1000 steps per sample interval are 1e-12 of one step's error, and
# more only cost time in proportion (10^9 of them made the filters run for hours)
_MAX_SUBSTEPS = 1000


def checked_substeps(substeps) -> int:
    """`substeps` checked: a whole number from 1 to _MAX_SUBSTEPS."""
    k = int(as_scalar(substeps, "substeps", positive=True, integer=True))
    if k > _MAX_SUBSTEPS:
        raise ValueError(
            f"substeps must be at most {_MAX_SUBSTEPS}: received {k}. RK4's error falls like the "
            f"fourth power of the step, so {_MAX_SUBSTEPS} steps per sample are already exact to "
            "rounding for any smooth model, and more only cost time; the step also shrinks by "
            "itself where P changes fast. For a finer estimate, sample y on a finer grid t."
        )
    return k


def initial_estimate(x0, n: int) -> np.ndarray:
    return as_vector(x0, "x0", size=n, why="the initial estimate x̂(0), one entry per state")


def filter_setup(n: int, p: int, Q, R, P0, x0):
    """Validate the weights (sizes explained from n and p) and the initial P0, x̂(0)."""
    Q = as_covariance(Q, "Q", n, definite=False, why=f"one row and column per state, n = {n}")
    R = as_covariance(R, "R", p, definite=True, why=f"one row and column per output, p = {p}")
    P0 = as_covariance(P0, "P0", n, definite=True, why=f"one row and column per state, n = {n}")
    return Q, R, P0, initial_estimate(x0, n)
