"""The Kalman filter seen as an observer (section 4.7).

* `kalman_gain(A, C, Q, R)` -- the steady-state gain: L = P C^T R^{-1} (4.87)
  with P the constant solution of the Riccati equation (4.88) (Ṗ = 0, the
  *algebraic* Riccati equation). It is the dual of the LQR equation: SciPy's
  ``solve_continuous_are(a, b, q, r)`` solves a^T X + X a - X b r^{-1} b^T X + q = 0,
  and with a = A^T, b = C^T this is exactly 0 = A P + P A^T - P C^T R^{-1} C P + Q.
* `kalman_bucy` -- the time-varying filter: the observer (4.86) run on
  recorded data with the gain (4.87) and the Riccati ODE (4.88) integrated
  alongside the estimate.
* `extended_kalman_filter` -- the EKF (4.91)-(4.93) for a `NonlinearSystem`:
  the same equations with A(t), C(t) the Jacobians of f and h at x̂(t).
* `white_noise` and `simulate_with_noise` -- reproducible noisy data.

Units of the noise (read this once). In continuous time, white noise w(t)
with *intensity* (power spectral density) Q satisfies
E[w(t) w(s)^T] = Q δ(t - s): its variance is infinite and only its integral
is meaningful, ∫_t^{t+dt} w ds having covariance Q dt. A sequence of samples
that stands for w(t) on a grid with step dt, held constant over each step,
must therefore have covariance **Q / dt**: halving the step doubles the
variance of the samples. Conversely a sensor whose samples have variance σ²
at the sampling period dt corresponds to the intensity **R = σ² dt**. Q and
R in this module are intensities: Q in (state unit)²/s, R in (output unit)²·s.
In the deterministic view of the notes Q and R are simply tuning matrices:
only their ratio matters for the steady-state gain.

Integration: both filters use the classical fixed-step Runge-Kutta method
(RK4) between the samples of the grid, with u and y linear between samples
(as `simulate` does). A step is split automatically when the Riccati
equation is fast compared with the grid (large P or small R), so the filter
stays stable on coarse grids.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._validation import as_scalar, as_series, as_square, as_time_grid, as_vector, is_uniform
from .linearization import _jacobian
from .observability import _obs_pair
from .simulation import SimulationResult, lti_step_matrices
from .systems import NonlinearSystem, StateSpace

__all__ = [
    "kalman_gain",
    "kalman_bucy",
    "extended_kalman_filter",
    "KalmanResult",
    "white_noise",
    "simulate_with_noise",
]


def _covariance(value, name: str, size: int, *, definite: bool) -> np.ndarray:
    """A symmetric (size x size) matrix, positive definite or semidefinite."""
    M = as_square(value, name, size=size)
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * max(1.0, np.abs(M).max())):
        raise ValueError(f"{name} must be symmetric: received {M.tolist()!r}; use (M + M.T) / 2.")
    M = (M + M.T) / 2
    low = float(np.linalg.eigvalsh(M).min())
    scale = max(1.0, float(np.abs(M).max()))
    if definite and low <= 1e-12 * scale:
        raise ValueError(
            f"{name} must be positive definite: its smallest eigenvalue is {low:.3g}; "
            f"expected every eigenvalue > 0 (e.g. a diagonal matrix with positive entries)."
        )
    if not definite and low < -1e-10 * scale:
        raise ValueError(
            f"{name} must be positive semidefinite: its smallest eigenvalue is {low:.3g} < 0; "
            "expected a covariance-like matrix such as np.diag([q1, q2])."
        )
    return M


def kalman_gain(A, C, Q, R) -> tuple[np.ndarray, np.ndarray]:
    """Steady-state Kalman gain L (n, p) and Riccati solution P (n, n).

    P is the symmetric positive semidefinite solution of the algebraic
    Riccati equation, the equilibrium of (4.88):

        0 = A P + P A^T - P C^T R^{-1} C P + Q,

    solved by duality with the LQR equation (``solve_continuous_are(A^T, C^T, Q, R)``),
    and L = P C^T R^{-1} (4.87). The observer error then obeys
    x̃' = (A - L C) x̃ with A - L C stable. python-control's ``lqe(A, I, C, Q, R)``
    returns the same L (no sign flip: the observer convention is the same).

    Q (n, n) >= 0 is the process-noise intensity, R (p, p) > 0 the
    measurement-noise intensity (see the module docstring for units).
    Needs (A, C) detectable and (A, Q^{1/2}) without uncontrollable modes on
    the imaginary axis; otherwise a ValueError says so.
    """
    A, C = _obs_pair(A, C)
    n, p = A.shape[0], C.shape[0]
    Q = _covariance(Q, "Q", n, definite=False)
    R = _covariance(R, "R", p, definite=True)
    from scipy.linalg import solve_continuous_are
    try:
        # ARE (4.88 with Ṗ = 0): A P + P A^T - P C^T R^{-1} C P + Q = 0
        P = solve_continuous_are(A.T, C.T, Q, R)
    except (np.linalg.LinAlgError, ValueError) as err:
        raise ValueError(
            f"the algebraic Riccati equation has no stabilizing solution ({err}). Check that "
            "every unstable mode of A is observable through C (is_observable) and that Q "
            "excites every mode on the imaginary axis (try Q = np.eye(n))."
        ) from None
    P = (P + P.T) / 2
    # (4.87): L = P C^T R^{-1}
    L = np.linalg.solve(R, C @ P).T
    return L, P


@dataclass(repr=False)
class KalmanResult:
    """What the Kalman-Bucy filter and the EKF return (time-major).

    Attributes
    ----------
    t : (N,) array      -- the time grid
    x : (N, n) array    -- the estimate x̂ at each time
    P : (N, n, n) array -- the solution of the Riccati equation (4.88)
    L : (N, n, p) array -- the gain L(t) = P C^T R^{-1} (4.87)
    """

    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    L: np.ndarray

    @property
    def sigma(self) -> np.ndarray:
        """sqrt(diag P(t)), shape (N, n): the filter's own error standard deviations."""
        return np.sqrt(np.maximum(np.diagonal(self.P, axis1=1, axis2=2), 0.0))

    def __repr__(self) -> str:
        n, p = self.L.shape[1:]
        return (f"KalmanResult: {self.t.size} samples from t={self.t[0]:g} to t={self.t[-1]:g}; "
                f"x {self.x.shape}, P (N, {n}, {n}), L (N, {n}, {p})")


def _records(t, u, y, m: int):
    """Validate the recorded grid, input (N, m) and measurement (N, p)."""
    t = as_time_grid(t, "t")
    N = t.size
    u = np.zeros((N, m)) if u is None else as_series(u, "u", samples=N, channels=m,
                                                     channels_why="one column per input")
    return t, u, as_series(y, "y", samples=N)


def _riccati_rate(A: np.ndarray, L: np.ndarray, C: np.ndarray) -> float:
    """How fast (4.88) moves near P: its linearization is dP' = (A - L C) dP + dP (A - L C)^T,
    whose eigenvalues are sums of two eigenvalues of A - L C."""
    return 2.0 * float(np.abs(np.linalg.eigvals(A - L @ C)).max())


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


def _step_length(A: np.ndarray, L: np.ndarray, C: np.ndarray, h_max: float) -> float:
    """min(h_max, 0.5 / rate) with the rate of `_riccati_rate`.

    The eigenvalues are only computed when they can matter: when even an
    upper bound of the rate allows h_max, the rate itself does too, and h_max
    is returned as is.
    """
    if 4.0 * h_max * _radius_bound(A - L @ C) >= 1.0:
        return min(h_max, 0.5 / max(_riccati_rate(A, L, C), 1e-300))
    return h_max


def _finite(x: np.ndarray, P: np.ndarray) -> bool:
    """True when no entry of x or P is inf or nan (a sum is finite only then)."""
    return bool(np.isfinite(x.sum() + P.sum()))


_MAX_STEPS = 100_000


def _rk4_interval(rhs, x, P, cur, u0, u1, y0, y1, dt: float, substeps: int):
    """RK4 from one sample to the next, with u and y linear in between.

    The step is at most dt / substeps and at most 0.5 / rate, the rate of
    (4.88) at the current P, so a fast start (large P0, small R) takes many
    short steps that lengthen as P settles. `cur` is rhs at the start; the
    value at the end is returned for the next interval.
    """
    tau, steps = 0.0, 0
    du, dy = u1 - u0, y1 - y0
    while tau < dt:
        _, _, L, A, C = cur
        h = _step_length(A, L, C, min(dt - tau, dt / substeps))
        if dt - tau - h < 1e-9 * dt:
            h = dt - tau
        # u and y linear over the interval: u0 + s (u1 - u0) at s = (tau + h/2)/dt and (tau + h)/dt
        s_mid, s_end = (tau + h / 2) / dt, (tau + h) / dt
        um, ue = u0 + s_mid * du, u0 + s_end * du
        ym, ye = y0 + s_mid * dy, y0 + s_end * dy
        k1 = cur[:2]
        k2 = rhs(x + h / 2 * k1[0], P + h / 2 * k1[1], um, ym)[:2]
        k3 = rhs(x + h / 2 * k2[0], P + h / 2 * k2[1], um, ym)[:2]
        k4 = rhs(x + h * k3[0], P + h * k3[1], ue, ye)[:2]
        x = x + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        P = P + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        P = (P + P.T) / 2
        if not _finite(x, P):
            break                                   # the caller reports the divergence
        steps += 1
        if steps > _MAX_STEPS:
            raise RuntimeError(
                f"the Riccati equation (4.88) needs more than {_MAX_STEPS} RK4 steps between two "
                "samples (its rate is huge): check the units of Q and R (module docstring), or "
                "start from a smaller P0.")
        tau = dt if h == dt - tau else tau + h
        cur = rhs(x, P, ue, ye)
    return x, P, cur


def _run_filter(f, h, dfdx, dhdx, t, u, y, Q, R, P0, x0, substeps: int) -> KalmanResult:
    """Integrate (4.86)/(4.91) and (4.87)-(4.88) with RK4 on the grid t."""
    n, N = x0.size, t.size
    Rinv = np.linalg.inv(R)

    def rhs(x, P, uk, yk):
        A, C = dfdx(x, uk), dhdx(x, uk)
        # (4.87): L = P C^T R^{-1}
        L = P @ C.T @ Rinv
        # (4.86), (4.91): x̂' = f(x̂, u) + L (y - h(x̂, u))
        dx = f(x, uk) + L @ (yk - h(x, uk))
        # (4.88): Ṗ = A P + P A^T - P C^T R^{-1} C P + Q
        dP = A @ P + P @ A.T - L @ C @ P + Q
        return dx, dP, L, A, C

    xs, Ps, Ls = np.empty((N, n)), np.empty((N, n, n)), np.empty((N, n, y.shape[1]))
    x, P = x0.copy(), P0.copy()
    cur = rhs(x, P, u[0], y[0])
    for k in range(N):
        xs[k], Ps[k], Ls[k] = x, P, cur[2]
        if k + 1 == N:
            break
        x, P, cur = _rk4_interval(rhs, x, P, cur, u[k], u[k + 1], y[k], y[k + 1],
                                  t[k + 1] - t[k], substeps)
        if not _finite(x, P):
            raise RuntimeError(
                f"the filter diverged at t={t[k + 1]:g} (non-finite estimate or P); check the "
                "model, the units of Q and R, and try substeps=10.")
    return KalmanResult(t=t, x=xs, P=Ps, L=Ls)


def _substeps(substeps) -> int:
    return int(as_scalar(substeps, "substeps", positive=True, integer=True))


def _filter_setup(n: int, p: int, Q, R, P0, x0):
    Q = _covariance(Q, "Q", n, definite=False)
    R = _covariance(R, "R", p, definite=True)
    P0 = _covariance(P0, "P0", n, definite=True)
    x0 = as_vector(x0, "x0", size=n, why="the initial estimate x̂(0), one entry per state")
    return Q, R, P0, x0


def kalman_bucy(sys, t, u, y, Q, R, P0, x0, *, substeps: int = 1) -> KalmanResult:
    """Time-varying Kalman(-Bucy) filter (4.86)-(4.88) on recorded data.

    Runs the observer x̂' = A x̂ + B u + L(t) (y - C x̂ - D u) (4.86) with
    L(t) = P(t) C^T R^{-1} (4.87) and the Riccati ODE (4.88) from
    P(0) = P0, x̂(0) = x0. `sys` is a continuous-time `StateSpace`; `u`
    (N, m) or None and `y` (N, p) are the recorded input and measurement on
    the grid `t`. Q (n, n) >= 0 and R (p, p) > 0 are intensities (module
    docstring). As t grows P(t) tends to the solution of `kalman_gain`.

    Returns a `KalmanResult` (estimate, P(t), L(t)). `substeps` RK4 steps
    (at least) are taken between samples.
    """
    if not isinstance(sys, StateSpace) or sys.is_discrete:
        raise ValueError(f"sys must be a continuous-time StateSpace: received {sys!r}; "
                         "for a NonlinearSystem use extended_kalman_filter.")
    t, u, y = _records(t, u, y, sys.m)
    if y.shape[1] != sys.p:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, "
                         f"expected {sys.p} (one per output, since C has {sys.p} rows).")
    Q, R, P0, x0 = _filter_setup(sys.n, sys.p, Q, R, P0, x0)
    A, B, C, D = sys.A, sys.B, sys.C, sys.D
    return _run_filter(lambda x, v: A @ x + B @ v, lambda x, v: C @ x + D @ v,
                       lambda x, v: A, lambda x, v: C, t, u, y, Q, R, P0, x0,
                       _substeps(substeps))


def extended_kalman_filter(sys, t, u, y, Q, R, P0, x0, *, dfdx: Callable | None = None,
                           dhdx: Callable | None = None, substeps: int = 1) -> KalmanResult:
    """Extended Kalman filter (4.91)-(4.93) for a continuous-time `NonlinearSystem`.

    x̂' = f(x̂, u) + L(t) (y - h(x̂, u)) (4.91), with L(t) and P(t) from
    (4.87)-(4.88) where A(t) = ∂f/∂x (4.92) and C(t) = ∂h/∂x (4.93) are
    evaluated at the estimate x̂(t). `dfdx(x, u)` -> (n, n) and
    `dhdx(x, u)` -> (p, n) may be supplied; by default they are computed by
    central differences (step ~ eps^(1/3); the helper `linearize` uses, without its refinement).

    `u` (N, m) or None and `y` (N, p) are the recorded data on the grid `t`;
    Q, R are intensities, P0 > 0 the initial P, x0 the initial estimate.
    Unlike the linear filter, the EKF has no optimality guarantee and may
    diverge from a poor x0 or with badly chosen Q, R.
    """
    if not isinstance(sys, NonlinearSystem) or sys.is_discrete:
        raise ValueError(f"sys must be a continuous-time NonlinearSystem: received {sys!r}; "
                         "for a StateSpace use kalman_bucy.")
    t, u, y = _records(t, u, y, sys.m)
    Q, R, P0, x0 = _filter_setup(sys.n, y.shape[1], Q, R, P0, x0)
    p_h = sys.output_size(x0, u[0])
    if p_h != y.shape[1]:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, expected "
                         f"{p_h} (the number of outputs of sys.h).")
    for fun, name in ((dfdx, "dfdx"), (dhdx, "dhdx")):
        if fun is not None and not callable(fun):
            raise ValueError(f"{name} must be a function (x, u) -> Jacobian, or None for "
                             f"numerical differences: received {type(fun).__name__}.")
    jf = (lambda x, v: np.asarray(dfdx(x, v), float).reshape(sys.n, sys.n)) if dfdx else \
        (lambda x, v: _jacobian(lambda z: sys.f(z, v), x, refine=False))
    jh = (lambda x, v: np.asarray(dhdx(x, v), float).reshape(p_h, sys.n)) if dhdx else \
        (lambda x, v: _jacobian(lambda z: sys.h(z, v), x, refine=False))
    return _run_filter(sys.f, sys.h, jf, jh, t, u, y, Q, R, P0, x0, _substeps(substeps))


def _rng(seed) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None or isinstance(seed, (int, np.integer)):
        return np.random.default_rng(seed)
    raise ValueError(f"seed must be an int, None or a numpy Generator: received {type(seed).__name__}.")


def _uniform_step(t: np.ndarray) -> float:
    if not is_uniform(t):
        raise ValueError("t must be uniformly spaced to sample white noise (the sample variance "
                         "is intensity / dt); build it with np.linspace or np.arange.")
    return float(t[1] - t[0])


def white_noise(t, intensity, seed=None) -> np.ndarray:
    """Samples of continuous-time white noise of the given intensity on the grid `t`.

    Returns an (N, k) array of independent Gaussian samples with covariance
    ``intensity / dt`` each (dt the step of the uniform grid `t`), the
    sampled stand-in for white noise of power spectral density `intensity`
    (k x k, or a number for k = 1): integrated over a step it has covariance
    ``intensity * dt``, as the continuous noise does. `seed` is an int, None
    or a ``numpy.random.Generator``.
    """
    t = as_time_grid(t, "t")
    dt = _uniform_step(t)
    W = np.atleast_2d(np.asarray(intensity, dtype=float)) if np.ndim(intensity) < 2 else intensity
    W = _covariance(W, "intensity", np.shape(W)[0], definite=False)
    vals, vecs = np.linalg.eigh(W / dt)
    S = vecs * np.sqrt(np.maximum(vals, 0.0))          # S S^T = intensity / dt
    return _rng(seed).standard_normal((t.size, W.shape[0])) @ S.T


def _van_loan(A: np.ndarray, Q: np.ndarray, dt: float) -> np.ndarray:
    """Covariance ∫_0^dt e^{A s} Q e^{A^T s} ds of the exact sampled process noise."""
    from scipy.linalg import expm
    n = A.shape[0]
    E = expm(np.block([[-A, Q], [np.zeros((n, n)), A.T]]) * dt)
    F = E[n:, n:].T
    Qd = F @ E[:n, n:]
    return (Qd + Qd.T) / 2


def simulate_with_noise(sys, t, u=None, x0=None, *, Q, R, seed=None) -> SimulationResult:
    """Simulate x' = f(x, u) + w, y = h(x, u) + v with white noises w, v.

    w has intensity Q (n, n) and v intensity R (p, p) (module docstring).
    Returns a `SimulationResult` whose ``x`` is the true state and ``y`` the
    *noisy* measurement, each sample of v having covariance R / dt.

    * `StateSpace`: exact in distribution: the step matrices of `simulate`
      (u linear between samples) plus a Gaussian increment with the
      covariance ∫ e^{A s} Q e^{A^T s} ds over a step (Van Loan's method);
    * `NonlinearSystem`: RK4 over each step with w held constant at a sample
      of covariance Q / dt (u linear between samples).

    `u` is None or an array (N, m); `t` must be uniform. Deterministic for a
    given `seed` (int or ``numpy.random.Generator``): w is drawn first, then v.
    """
    if not isinstance(sys, (StateSpace, NonlinearSystem)) or sys.is_discrete:
        raise ValueError(f"sys must be a continuous-time StateSpace or NonlinearSystem: received {sys!r}.")
    t = as_time_grid(t, "t")
    dt = _uniform_step(t)
    n, N = sys.n, t.size
    x0 = np.zeros(n) if x0 is None else as_vector(x0, "x0", size=n, why="one per state")
    t, u, _ = _records(t, u, np.zeros((N, 1)), sys.m)
    Q = _covariance(Q, "Q", n, definite=False)
    rng = _rng(seed)
    x = np.empty((N, n))
    x[0] = x0
    if isinstance(sys, StateSpace):
        Ad, B0, B1 = lti_step_matrices(sys.A, sys.B, dt)
        # white_noise samples have covariance intensity / dt, so intensity Qd dt gives Qd
        w = white_noise(t, _van_loan(sys.A, Q, dt) * dt, rng)
        # everything but Ad x(k), for all k at once: B0 u(k) + B1 u(k+1) + w(k)
        forcing = u[:-1] @ B0.T + u[1:] @ B1.T + w[:-1]
        for k in range(N - 1):
            x[k + 1] = Ad @ x[k] + forcing[k]
    else:
        sys.check(x0, u[0])
        w = white_noise(t, Q, rng)
        for k in range(N - 1):
            x[k + 1] = _rk4_held(sys.f, x[k], u[k], u[k + 1], w[k], dt)
    if isinstance(sys, StateSpace):
        y_clean = x @ sys.C.T + u @ sys.D.T                 # y = C x + D u at every sample
    else:
        y_clean = np.array([sys.h(xk, uk) for xk, uk in zip(x, u)]).reshape(N, -1)
    R = _covariance(R, "R", y_clean.shape[1], definite=False)
    y = y_clean + white_noise(t, R, rng)
    return SimulationResult(t=t, x=x, y=y, u=u, system=sys)


def _rk4_held(f, x, u0, u1, w, dt):
    """One RK4 step of x' = f(x, u) + w with u linear over the step and w constant."""
    um = (u0 + u1) / 2
    k1 = f(x, u0) + w
    k2 = f(x + dt / 2 * k1, um) + w
    k3 = f(x + dt / 2 * k2, um) + w
    k4 = f(x + dt * k3, u1) + w
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
