"""The Kalman filter in discrete time: predict and update on sampled data (section 4.7).

A computer runs the filter of (4.86)-(4.88) on samples. For the sampled model

    x(k+1) = A x(k) + B u(k) + w(k),      y(k) = C x(k) + D u(k) + v(k),

with independent Gaussian noises of covariances Q (w) and R (v) and the
prior x(0) ~ N(x0, P0), `discrete_kalman_filter` alternates two steps:

* update with y(k):  S = C P⁻ C^T + R,  M = P⁻ C^T S^{-1},
  x̂(k|k) = x̂(k|k-1) + M (y(k) - C x̂(k|k-1) - D u(k)),
  P(k|k) = (I - M C) P⁻ (I - M C)^T + M R M^T;
* predict:  x̂(k+1|k) = A x̂(k|k) + B u(k),  P⁻ = P(k+1|k) = A P(k|k) A^T + Q.

The correction M (y - ŷ) plays the part of L (y - ŷ) in (4.86), and the
recursion for P replaces the Riccati ODE (4.88). In the notes' observer form
x̂(k+1|k) = A x̂(k|k-1) + B u(k) + L(k) (y(k) - ŷ(k|k-1)) the gain is the
predictor gain L(k) = A M(k); for constant matrices it tends to the gain of
``kalman_gain(A, C, Q, R, dt=dt)`` and P(k+1|k) to its P.

Q and R here are covariances of the samples. For a continuous model with
intensities Q_c, R_c (the units of `coursekit.kalman`) sampled with period
dt: Q = ∫_0^dt e^{A_c s} Q_c e^{A_c^T s} ds ≈ Q_c dt and R = R_c / dt.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._filter_ode import initial_estimate
from ._validation import as_covariance, as_series
from .kalman_bucy import KalmanResult
from .systems import StateSpace

__all__ = ["discrete_kalman_filter"]


def _sampled_data(sys: StateSpace, y, u):
    """y (N, p) and u (N, m) as time-major float arrays, validated against sys."""
    N = np.shape(y)[0] if np.ndim(y) >= 1 else 1
    s = "s" if sys.p > 1 else ""
    y = as_series(y, "y", samples=N, channels=sys.p, samples_why="one row per sample k",
                  channels_why=f"one column per output, since C has {sys.p} row{s}")
    if N == 0:
        raise ValueError("y is empty: expected at least one sample (one row per sample k).")
    if u is None:
        return y, np.zeros((N, sys.m))
    if sys.m == 0:
        raise ValueError("u was given, but the system has no input (m = 0); leave u=None.")
    u = as_series(u, "u", samples=N, channels=sys.m,
                  samples_why=f"one row per sample of y, which has {N} rows; u and y must cover the "
                              "same samples, so check which of them is too short",
                  channels_why="one column per input")
    return y, u


def _weights(sys: StateSpace, Q, R, P0, x0):
    n, p = sys.n, sys.p
    state = f"one row and column per state, n = {n}"
    Q = as_covariance(Q, "Q", n, definite=False, why=state + " (covariance of w(k))")
    R = as_covariance(R, "R", p, definite=True,
                    why=f"one row and column per output, p = {p} (covariance of v(k))")
    P0 = as_covariance(P0, "P0", n, definite=False, why=state + " (covariance of x(0))")
    return Q, R, P0, initial_estimate(x0, n)


def _check_finite(k: int, dt: float, x: np.ndarray, P: np.ndarray) -> None:
    """RuntimeError naming sample k when x or P is no longer finite."""
    if not (np.isfinite(x).all() and np.isfinite(P).all()):
        raise RuntimeError(
            f"the discrete Kalman filter diverged at sample k = {k} (t = {k * dt:g}): the "
            "estimate or P is not finite; check the model A (an unstable mode with large "
            "data), the units of Q and R, and the data y.")


def discrete_kalman_filter(sys, y, u=None, *, Q, R, P0, x0) -> KalmanResult:
    """Discrete-time Kalman filter on the samples y(0), ..., y(N-1) (module docstring).

    `sys` is a discrete-time `StateSpace` (``sys.dt`` set: the sampling
    period). `y` (N, p) and `u` (N, m) or None are the recorded samples, u(k)
    acting from k to k + 1; Q (n, n) >= 0 and R (p, p) > 0 are the
    covariances of w(k) and v(k) (module docstring for the relation to the
    continuous intensities); x0, P0 >= 0 are the mean and covariance of x(0)
    before y(0) is seen.

    Returns a `KalmanResult` with t = k dt and, at every sample k:

    * ``x[k]`` the *filtered* estimate x̂(k|k), which has used y(0), ..., y(k);
      for Gaussian noises it is the exact conditional mean E[x(k) | y(0..k)];
    * ``P[k]`` = P(k|k), the covariance of x(k) - x̂(k|k);
    * ``M[k]`` the update gain and ``L[k]`` = A M[k] the predictor gain of the
      observer form (4.86), which tends to ``kalman_gain(A, C, Q, R, dt=dt)``.

    P(k|k) is updated in Joseph form, which keeps it symmetric positive
    semidefinite in floating point. Raises RuntimeError when the estimate or P
    stops being finite (an unstable model with huge data), naming the sample.
    """
    sys = as_system(sys, kind="linear", time="discrete",
                    hint="sample a continuous model first (exact: expm of A dt), or use "
                         "kalman_bucy for continuous time.")
    y, u = _sampled_data(sys, y, u)
    Q, R, P0, x0 = _weights(sys, Q, R, P0, x0)
    A, B, C, D = sys.A, sys.B, sys.C, sys.D
    N, n, p = y.shape[0], sys.n, sys.p
    xs, Ps, Ms = np.empty((N, n)), np.empty((N, n, n)), np.empty((N, n, p))
    x_pred, P_pred, I = x0, P0, np.eye(n)
    for k in range(N):
        # update: M = P⁻ C^T (C P⁻ C^T + R)^{-1}, x̂ = x̂⁻ + M (y - C x̂⁻ - D u)
        S = C @ P_pred @ C.T + R
        M = np.linalg.solve(S, C @ P_pred).T
        x = x_pred + M @ (y[k] - C @ x_pred - D @ u[k])
        J = I - M @ C
        P = J @ P_pred @ J.T + M @ R @ M.T                    # Joseph form of (I - M C) P⁻
        P = (P + P.T) / 2
        _check_finite(k, sys.dt, x, P)
        xs[k], Ps[k], Ms[k] = x, P, M
        # predict: x̂⁻ = A x̂ + B u, P⁻ = A P A^T + Q
        x_pred, P_pred = A @ x + B @ u[k], A @ P @ A.T + Q
        _check_finite(k + 1, sys.dt, x_pred, P_pred)
    return KalmanResult(t=np.arange(N) * sys.dt, x=xs, P=Ps, L=A @ Ms, M=Ms)
