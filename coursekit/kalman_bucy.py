"""The Kalman(-Bucy) filter seen as an observer (section 4.7): `kalman_bucy`.

`kalman_bucy` runs the time-varying filter on recorded data: the observer
(4.86) with the gain (4.87) and the Riccati ODE (4.88) integrated alongside the
estimate. `KalmanResult` is what every Kalman filter of coursekit returns
(also `extended_kalman_filter` and `discrete_kalman_filter`). Q and R are
intensities (see `coursekit.kalman` for their units).

Integration (`coursekit._filter_ode`, shared with the EKF): both filters use the classical fixed-step Runge-Kutta method
(RK4) between the samples of the grid, with u and y linear between samples
(as `simulate` does). A step is split automatically when the Riccati
equation is fast compared with the grid (large P or small R), so the filter
stays stable on coarse grids. For the linear filter (4.88) does not involve
the data: P(t) is integrated first, then the estimate, whose RK4 steps are
affine maps built for all steps at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._arguments import as_system
from ._filter_ode import advance, all_finite, checked_substeps, diverged, filter_setup, next_step, records

__all__ = ["kalman_bucy", "KalmanResult"]


@dataclass(repr=False)
class KalmanResult:
    """What the Kalman filters return (time-major).

    Attributes
    ----------
    t : (N,) array      -- the time grid (k dt for `discrete_kalman_filter`)
    x : (N, n) array    -- the estimate x̂ at each time (in discrete time the
                           filtered estimate x̂(k|k), given y(0), ..., y(k))
    P : (N, n, n) array -- its error covariance: the solution of the Riccati
                           equation (4.88), in discrete time P(k|k)
    L : (N, n, p) array -- the observer gain: L(t) = P C^T R^{-1} (4.87); in
                           discrete time the predictor gain L(k) = A M(k)
    M : (N, n, p) array or None -- discrete time only: the update gain M(k),
                           x̂(k|k) = x̂(k|k-1) + M(k) (y(k) - ŷ(k|k-1))
    """

    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    L: np.ndarray
    M: np.ndarray | None = None

    @property
    def sigma(self) -> np.ndarray:
        """sqrt(diag P(t)), shape (N, n): the filter's own error standard deviations."""
        return np.sqrt(np.maximum(np.diagonal(self.P, axis1=1, axis2=2), 0.0))

    def __repr__(self) -> str:
        return (f"KalmanResult: {self.t.size} samples from t={self.t[0]:g} to t={self.t[-1]:g}; "
                f"x {self.x.shape}, P {self.P.shape}, L {self.L.shape}"
                + ("" if self.M is None else f", M {self.M.shape}"))


def _riccati_interval(riccati, P, cur, dt: float, substeps: int):
    """RK4 on (4.88) alone over one sample interval, with the steps of `rk4_interval`.

    `cur` = riccati(P) = (P', A - L C) at the start. Returns (P, cur, steps)
    at the end, cur None if P stopped being finite, and for each step
    (s_mid, s_end, h, P1, P2, P3, P4): the stage positions as fractions of
    the interval, the length and P at the four stages.
    """
    tau, count, steps = 0.0, 0, []
    while tau < dt:
        k1, M = cur
        h = next_step(tau, dt, substeps, M)
        P2 = P + h / 2 * k1
        k2 = riccati(P2)[0]
        P3 = P + h / 2 * k2
        k3 = riccati(P3)[0]
        P4 = P + h * k3
        k4 = riccati(P4)[0]
        steps.append(((tau + h / 2) / dt, (tau + h) / dt, h, P, P2, P3, P4))
        P = P + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        P = (P + P.T) / 2
        if not all_finite(P):
            return P, None, steps
        tau, count = advance(tau, h, dt, count)
        cur = riccati(P)
    return P, cur, steps


def _riccati_pass(A, C, Q, G, t, P0, substeps: int):
    """P(t) of (4.88) on the grid t and the RK4 steps taken, for constant A and C.

    (4.88) does not involve the data, so it is integrated first, alone; the
    gain is L = P G (4.87), G = C^T R^{-1}.
    Returns P at the samples (N, n, n) and the steps as
    (k, s_mid, s_end, h, P1, P2, P3, P4), k the sample interval (`_riccati_interval`).
    (4.88) is autonomous: an interval depends on P and dt only, and once P
    has settled to a fixed point of the RK4 step (to the last bit) the
    interval is reused instead of recomputed.
    """
    S, AT = G @ C, A.T.copy()

    def riccati(P):
        M = A - P.dot(S)                                # A - L C, with L = P C^T R^{-1} (4.87)
        return M.dot(P) + P.dot(AT) + Q, M              # (4.88) = (A - L C) P + P A^T + Q

    Ps, steps, settled = np.empty((t.size,) + P0.shape), [], {}
    P, cur = P0.copy(), riccati(P0)
    for k, dt in enumerate(np.diff(t).tolist()):
        Ps[k] = P
        key = (dt, P.tobytes())
        P, cur, taken = settled.get(key) or _riccati_interval(riccati, P, cur, dt, substeps)
        if cur is None:
            raise diverged(t[k + 1])
        if key[1] == P.tobytes():
            settled[key] = P, cur, taken
        steps += [(k,) + step for step in taken]
    Ps[-1] = P
    return Ps, steps


def _rk4_affine(M: np.ndarray, g: np.ndarray, h: np.ndarray):
    """(Φ, c) with x + (RK4 step of x' = M_i x + g_i) = Φ x + c, for many steps at once.

    M (J, 4, n, n) and g (J, 4, n) are the matrix and the forcing at the four
    stages of each of J steps of lengths h (J,); returns Φ (J, n, n), c (J, n).
    Each stage derivative k_i = K_i x + d_i is affine in the state x at the
    start of the step, and so is the stage state x + a h k_i of the next one.
    """
    I, H = np.eye(M.shape[-1]), h[:, None, None]
    E, e = I, np.zeros_like(g[:, 0])                    # stage state E x + e, first x itself
    K_sum, d_sum = 0.0, 0.0
    for i, weight in enumerate((1.0, 2.0, 2.0, 1.0)):
        K = M[:, i] @ E                                 # k_i = K x + d
        d = np.einsum("jab,jb->ja", M[:, i], e) + g[:, i]
        K_sum, d_sum = K_sum + weight * K, d_sum + weight * d
        if i < 3:                                       # next stage state x + a h k_i
            a = (0.5, 0.5, 1.0)[i] * H
            E, e = I + a * K, a[:, 0] * d
    # x + h/6 (k1 + 2 k2 + 2 k3 + k4)
    return I + H / 6 * K_sum, H[:, 0] / 6 * d_sum


def _estimate_pass(sys, G, w, x0, steps):
    """x̂ of (4.86) at the samples (N, n), through the RK4 steps of `_riccati_pass`.

    With the gain L_i of each stage, (4.86) is x̂' = M_i x̂ + g_i, M_i = A - L_i C,
    g_i = B u_i + L_i (y_i - D u_i): affine, so each RK4 step is x̂ <- Φ x̂ + c
    (`_rk4_affine`). Φ and c are built for all steps at once; the loop then
    does one product per step.
    """
    k, s_mid, s_end, h, *stages = (np.array(column) for column in zip(*steps))
    L = np.stack(stages, axis=1) @ G                  # (4.87) at the stages, (J, 4, n, p)
    w0, dw = w[k], (w[1:] - w[:-1])[k]
    w_mid, w_end = w0 + s_mid[:, None] * dw, w0 + s_end[:, None] * dw
    # stage 1 sees w where the previous step ended (w[0] for the first step)
    W = np.stack([np.vstack([w[:1], w_end[:-1]]), w_mid, w_mid, w_end], axis=1)
    u, y = W[..., :sys.m], W[..., sys.m:]
    g = u @ sys.B.T + np.einsum("jiab,jib->jia", L, y - u @ sys.D.T)
    Phi, c = _rk4_affine(sys.A - L @ sys.C, g, h)
    x, after = x0, np.empty((k.size, x0.size))
    for j in range(k.size):
        x = Phi[j].dot(x) + c[j]
        after[j] = x
    last = np.append(k[1:] != k[:-1], True)                       # the last step of each interval
    return np.vstack([x0, after[last]])


def kalman_bucy(sys, t, u, y, Q, R, P0, x0, *, substeps: int = 1) -> KalmanResult:
    """Time-varying Kalman(-Bucy) filter (4.86)-(4.88) on recorded data.

    Runs the observer x̂' = A x̂ + B u + L(t) (y - C x̂ - D u) (4.86) with
    L(t) = P(t) C^T R^{-1} (4.87) and the Riccati ODE (4.88) from
    P(0) = P0, x̂(0) = x0. `sys` is a continuous-time `StateSpace`; `u`
    (N, m) or None and `y` (N, p) are the recorded input and measurement on
    the grid `t`. Q (n, n) >= 0 and R (p, p) > 0 are intensities (units:
    `coursekit.kalman`). As t grows P(t) tends to the solution of `kalman_gain`.

    Returns a `KalmanResult` (estimate, P(t), L(t)). `substeps` RK4 steps
    (at least; 1 to 1000, ValueError beyond) are taken between samples.
    """
    sys = as_system(sys, kind="linear", time="continuous",
                    hint="for a NonlinearSystem use extended_kalman_filter.")
    t, u, y = records(t, u, y, sys.m)
    if y.shape[1] != sys.p:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, "
                         f"expected {sys.p} (one per output, since C has {sys.p} rows).")
    Q, R, P0, x0 = filter_setup(sys.n, sys.p, Q, R, P0, x0)
    G = sys.C.T @ np.linalg.inv(R)                      # L = P G (4.87)
    Ps, steps = _riccati_pass(sys.A, sys.C, Q, G, t, P0, checked_substeps(substeps))
    xs = _estimate_pass(sys, G, np.hstack([u, y]), x0, steps)
    finite = np.isfinite(xs).all(axis=1)
    if not finite.all():
        raise diverged(t[np.argmin(finite)])
    return KalmanResult(t=t, x=xs, P=Ps, L=Ps @ G)
