"""Reproducible noisy data for the Kalman filters (section 4.7).

* `white_noise(t, intensity)` -- samples of continuous-time white noise;
* `simulate_with_noise(sys, t, u, x0, Q=..., R=...)` -- a simulation driven by
  process noise w of intensity Q, measured with noise v of intensity R;
* `van_loan(A, Q, dt)` -- the exact sampled model of x' = A x + w: A_d = e^{A dt}
  and the covariance Q_d = ∫_0^dt e^{A s} Q e^{A^T s} ds of the sampled noise
  (Van Loan's method: one matrix exponential).

Q and R are intensities (power spectral densities); see `coursekit.kalman`
for their units and why a sample of white noise has covariance intensity / dt.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._filter_ode import records
from ._stepping import check_finite, step_matrices
from ._validation import as_covariance, as_scalar, as_square, as_time_grid, as_vector, is_uniform
from .simulation import SimulationResult
from .systems import StateSpace

__all__ = ["white_noise", "simulate_with_noise", "van_loan"]


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
    W = as_square(intensity, "intensity")              # a number is 1x1; rejects text, complex
    W = as_covariance(W, "intensity", W.shape[0], definite=False)
    vals, vecs = np.linalg.eigh(W / dt)
    S = vecs * np.sqrt(np.maximum(vals, 0.0))          # S S^T = intensity / dt
    return _rng(seed).standard_normal((t.size, W.shape[0])) @ S.T


def van_loan(A, Q, dt) -> tuple[np.ndarray, np.ndarray]:
    """Exact sampling of x' = A x + w, w white noise of intensity Q: returns (A_d, Q_d).

    Over a step dt the solution formula (2.4) gives x(k+1) = A_d x(k) + w(k) with
    A_d = e^{A dt} and w(k) = ∫_0^dt e^{A s} w(t_k + dt - s) ds, whose covariance is
    Q_d = ∫_0^dt e^{A s} Q e^{A^T s} ds (≈ Q dt for small dt). Van Loan's method
    reads both off one matrix exponential: e^{M dt} with M = [[-A, Q], [0, A^T]] has
    the lower right block A_d^T and the upper right block A_d^{-1} Q_d, so
    Q_d = A_d (A_d^{-1} Q_d). Q_d is returned symmetrized. These are the sampled
    process model and the covariance Q of ``kalman_gain(A_d, C, Q_d, R_d, dt=dt)``
    and `discrete_kalman_filter`.

    A is square (n, n), Q (n, n) symmetric positive semidefinite (an intensity:
    see `coursekit.kalman`), dt a step > 0; ValueError naming the argument otherwise.
    """
    A = as_square(A, "A")
    n = A.shape[0]
    Q = as_covariance(Q, "Q", n, definite=False, why=f"one row and column per state, since A is {n}x{n}")
    dt = as_scalar(dt, "dt", positive=True)
    return _van_loan(A, Q, dt)


def _van_loan(A: np.ndarray, Q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """`van_loan` for checked arguments."""
    from scipy.linalg import expm
    n = A.shape[0]
    E = expm(np.block([[-A, Q], [np.zeros((n, n)), A.T]]) * dt)
    F = E[n:, n:].T                                     # A_d = e^{A dt}
    Qd = F @ E[:n, n:]
    return F, (Qd + Qd.T) / 2


def simulate_with_noise(sys, t, u=None, x0=None, *, Q, R, seed=None) -> SimulationResult:
    """Simulate x' = f(x, u) + w, y = h(x, u) + v with white noises w, v.

    w has intensity Q (n, n) and v intensity R (p, p) (units: the docstring of `coursekit.kalman`).
    Returns a `SimulationResult` whose ``x`` is the true state and ``y`` the
    *noisy* measurement, each sample of v having covariance R / dt.

    * `StateSpace`: exact in distribution: the step matrices of `simulate`
      (u linear between samples) plus a Gaussian increment with the
      covariance ∫ e^{A s} Q e^{A^T s} ds over a step (Van Loan's method);
    * `NonlinearSystem`: RK4 over each step with w held constant at a sample
      of covariance Q / dt (u linear between samples).

    `u` is None or an array (N, m); `t` must be uniform. Deterministic for a
    given `seed` (int or ``numpy.random.Generator``): w is drawn first, then v.
    A state that leaves the float range raises `SimulationError` (as in `simulate`).
    """
    sys = as_system(sys, time="continuous")
    t = as_time_grid(t, "t")
    dt = _uniform_step(t)
    n, N = sys.n, t.size
    x0 = np.zeros(n) if x0 is None else as_vector(x0, "x0", size=n, why="one per state")
    t, u, _ = records(t, u, np.zeros((N, 1)), sys.m)
    Q = as_covariance(Q, "Q", n, definite=False)
    rng = _rng(seed)
    x = np.empty((N, n))
    x[0] = x0
    if isinstance(sys, StateSpace):
        Ad, B0, B1 = step_matrices(sys.A, sys.B, dt)   # checked by StateSpace (B may have no columns)
        # white_noise samples have covariance intensity / dt, so intensity Qd dt gives Qd
        w = white_noise(t, _van_loan(sys.A, Q, dt)[1] * dt, rng)
        # everything but Ad x(k), for all k at once: B0 u(k) + B1 u(k+1) + w(k)
        forcing = u[:-1] @ B0.T + u[1:] @ B1.T + w[:-1]
        with np.errstate(over="ignore", invalid="ignore"):   # explained by check_finite below
            for k in range(N - 1):
                x[k + 1] = Ad @ x[k] + forcing[k]
    else:
        sys.check(x0, u[0])
        w = white_noise(t, Q, rng)
        for k in range(N - 1):
            x[k + 1] = _rk4_held(sys.f, x[k], u[k], u[k + 1], w[k], dt)
    # an unstable system leaves the float range: the error of simulate, with the time and the rate
    check_finite(sys, t, x)
    if isinstance(sys, StateSpace):
        y_clean = x @ sys.C.T + u @ sys.D.T                 # y = C x + D u at every sample
    else:
        y_clean = np.array([sys.h(xk, uk) for xk, uk in zip(x, u)]).reshape(N, -1)
    R = as_covariance(R, "R", y_clean.shape[1], definite=False)
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
