"""The Kalman filter seen as an observer (section 4.7).

* `kalman_gain(A, C, Q, R)` -- the steady-state gain: L = P C^T R^{-1} (4.87)
  with P the constant solution of the Riccati equation (4.88) (Ṗ = 0, the
  *algebraic* Riccati equation). It is the dual of the LQR equation: SciPy's
  ``solve_continuous_are(a, b, q, r)`` solves a^T X + X a - X b r^{-1} b^T X + q = 0,
  and with a = A^T, b = C^T this is exactly 0 = A P + P A^T - P C^T R^{-1} C P + Q.
  With ``dt=Ts`` the same for a sampled model x(k+1) = A x(k) + w(k): the
  discrete algebraic Riccati equation and the predictor gain of python-control's
  ``dlqe``. Either way the result is checked (residual, P >= 0, A - L C stable).
  The discrete-time *filter* is `coursekit.kalman_discrete.discrete_kalman_filter`.
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
only their ratio matters for the steady-state gain. In discrete time
(``kalman_gain(..., dt=Ts)``, `discrete_kalman_filter`) Q and R are instead
the *covariances* of the sampled noises w(k), v(k): R_d = R / Ts for a sensor
of intensity R sampled every Ts, and Q_d = ∫_0^Ts e^{A s} Q e^{A^T s} ds ≈ Q Ts
for process noise of intensity Q.

Integration: both filters use the classical fixed-step Runge-Kutta method
(RK4) between the samples of the grid, with u and y linear between samples
(as `simulate` does). A step is split automatically when the Riccati
equation is fast compared with the grid (large P or small R), so the filter
stays stable on coarse grids. For the linear filter (4.88) does not involve
the data: P(t) is integrated first, then the estimate, whose RK4 steps are
affine maps built for all steps at once. The EKF's numerical Jacobians call
f and h once per evaluation on a batch of perturbed states when they accept
one (all `coursekit.models` do).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._validation import (as_dt, as_scalar, as_series, as_square, as_time_grid, as_vector, call_user_fast,
                          is_uniform)
from .diagnostics import UserFunctionError, warn_accuracy
from .linearization import _jacobian, _perturbed, _quotients
from .observability import _obs_pair
from .simulation import SimulationResult, _agrees_column_by_column, lti_step_matrices
from .systems import StateSpace, as_system, _raw_field, _raw_output

__all__ = [
    "kalman_gain",
    "kalman_bucy",
    "extended_kalman_filter",
    "KalmanResult",
    "white_noise",
    "simulate_with_noise",
]


def _covariance(value, name: str, size: int, *, definite: bool, why: str = "") -> np.ndarray:
    """A symmetric (size x size) matrix, positive definite or semidefinite.

    `why` says where `size` comes from ("one row and column per state, since A is 2x2").
    """
    M = as_square(value, name)
    if M.shape[0] != size:
        reason = f" ({why})" if why else ""
        raise ValueError(f"{name} has the wrong size: received shape {M.shape}, expected "
                         f"({size}, {size}){reason}.")
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


def _state_why(n: int) -> str:
    return f"one row and column per state, since A is {n}x{n}"


def _output_why(p: int) -> str:
    return (f"one row and column per output, since C has {p} row{'s' if p > 1 else ''}; "
            "if the system has another number of outputs, check C")


def _gain_inputs(A, C, Q, R):
    """Validate in the order the sizes come from: A (n), C (p rows), then Q (n x n), R (p x p)."""
    A, C = _obs_pair(A, C)
    n, p = A.shape[0], C.shape[0]
    Q = _covariance(Q, "Q", n, definite=False, why=_state_why(n))
    R = _covariance(R, "R", p, definite=True, why=_output_why(p))
    return A, C, Q, R


#: Relative Riccati residual above which kalman_gain warns (`_riccati_residual`). A
#: well-posed equation solved by SciPy's Schur method lands orders of magnitude below
#: (typically 1e-15..1e-10); above 1e-6 fewer than about six digits of P can be trusted.
_RESIDUAL_TOL = 1e-6


def kalman_gain(A, C, Q, R, *, dt=None) -> tuple[np.ndarray, np.ndarray]:
    """Steady-state Kalman gain L (n, p) and Riccati solution P (n, n).

    **Continuous time** (``dt=None``). P is the stabilizing solution of the
    algebraic Riccati equation, the equilibrium of (4.88):

        0 = A P + P A^T - P C^T R^{-1} C P + Q,

    solved by duality with the LQR equation (``solve_continuous_are(A^T, C^T, Q, R)``),
    and L = P C^T R^{-1} (4.87), for the observer (4.86) with error x̃' = (A - L C) x̃.
    python-control's ``lqe(A, I, C, Q, R)`` returns the same L (no sign flip: the
    observer convention is the same). Q (n, n) >= 0 and R (p, p) > 0 are the
    noise *intensities* (module docstring for units).

    **Discrete time** (``dt`` = the sampling period > 0 of x(k+1) = A x(k) + w(k),
    y(k) = C x(k) + v(k)). P is the stabilizing solution of the discrete
    algebraic Riccati equation (``solve_discrete_are(A^T, C^T, Q, R)``)

        P = A P A^T - A P C^T (C P C^T + R)^{-1} C P A^T + Q,

    the steady-state covariance of the *prediction* error x(k) - x̂(k|k-1). The
    returned gain is the **predictor gain**

        L = A P C^T (C P C^T + R)^{-1},

    the gain of the observer in the notes' form (4.86) written for sampled data,
    x̂(k+1) = A x̂(k) + B u(k) + L (y(k) - C x̂(k)), error x̃(k+1) = (A - L C) x̃(k);
    it is what python-control's ``dlqe(A, I, C, Q, R)`` returns (with the same P).
    The filter (measurement-update) gain M = P C^T (C P C^T + R)^{-1}, used by
    `discrete_kalman_filter` for x̂(k|k) = x̂(k|k-1) + M (y(k) - C x̂(k|k-1)), is
    L = A M, i.e. M = A^{-1} L when A is invertible. Here Q and R are the
    *covariances* of the sampled noises w(k) and v(k); for a continuous model
    with intensities Q_c, R_c sampled with period dt they are about Q_c dt (exactly
    the Van Loan integral ∫_0^dt e^{A s} Q_c e^{A^T s} ds) and R_c / dt (module
    docstring). As dt -> 0, L / dt tends to the continuous gain.

    Guarantees, checked on the result: P symmetric positive semidefinite, the
    Riccati residual at most 1e-6 of the size of its terms (entry by entry,
    so the test does not depend on the state units), and A - L C stable
    (eigenvalues in the open left half plane, or inside the unit circle).
    Raises ValueError when no stabilizing solution exists, naming the mode
    that prevents it: a mode of A that is unstable (or on the stability
    boundary) and not observable through C ((A, C) not detectable), or a mode
    on the imaginary axis (unit circle) that Q does not drive, e.g. an
    undamped oscillator or an integrator with Q = 0. Warns
    (`AccuracyWarning`) when the residual or the semidefiniteness of P is
    off by more than rounding explains.
    """
    A, C, Q, R = _gain_inputs(A, C, Q, R)
    dt = as_dt(dt)
    P = _solve_riccati(A, C, Q, R, dt)
    if dt is None:
        # (4.87): L = P C^T R^{-1}
        L = np.linalg.solve(R, C @ P).T
    else:
        # predictor gain L = A P C^T (C P C^T + R)^{-1} = A M
        L = A @ np.linalg.solve(C @ P @ C.T + R, C @ P).T
    _check_riccati(A, C, Q, R, P, L, dt)
    return L, P


def _solve_riccati(A, C, Q, R, dt):
    """The stabilizing P of the continuous (dt None) or discrete algebraic Riccati equation."""
    from scipy.linalg import solve_continuous_are, solve_discrete_are
    solve = solve_continuous_are if dt is None else solve_discrete_are
    try:
        # continuous, (4.88) with Ṗ = 0: A P + P A^T - P C^T R^{-1} C P + Q = 0
        # discrete: P = A P A^T - A P C^T (C P C^T + R)^{-1} C P A^T + Q
        P = solve(A.T, C.T, Q, R)
    except (np.linalg.LinAlgError, ValueError) as err:
        raise _no_stabilizing_solution(A, C, dt, *_modes_of(A, Q), solver=str(err)) from None
    if not np.all(np.isfinite(P)):
        raise _no_stabilizing_solution(A, C, dt, *_modes_of(A, Q), solver="the solution is not finite")
    asym = float(np.abs(P - P.T).max()) / max(float(np.abs(P).max()), 1e-300)
    if asym > 1e-8:
        warn_accuracy(f"kalman_gain: the Riccati solution P is not symmetric (asymmetry {asym:.1e} "
                      "of its largest entry); it was symmetrized. The equation is badly "
                      "conditioned: check the units of Q and R, or rescale the states.", stacklevel=4)
    return (P + P.T) / 2


def _riccati_residual(A, C, Q, R, P, dt) -> float:
    """Largest |residual| of the Riccati equation relative to the size of its terms.

    Entry (i, j) of the residual is divided by the same entry of the sum of
    the absolute values of the terms, products taken of absolute values
    (|A||P| + |P||A^T| + ...): the bound of the rounding errors made in
    evaluating it. The ratio does not change with diagonal state scaling or
    the time unit; for an exact P in floating point it is a few eps.
    """
    if dt is None:
        G = np.linalg.solve(R, C @ P)                                     # R^{-1} C P
        PCt = P @ C.T
        residual = A @ P + P @ A.T - PCt @ G + Q
        size = abs(A) @ abs(P) + abs(P) @ abs(A.T) + abs(PCt) @ abs(G) + abs(Q)
    else:
        APCt = A @ P @ C.T
        G = np.linalg.solve(C @ P @ C.T + R, APCt.T)                      # S^{-1} C P A^T
        residual = A @ P @ A.T - APCt @ G + Q - P
        size = abs(A) @ abs(P) @ abs(A.T) + abs(APCt) @ abs(G) + abs(Q) + abs(P)
    ratio = np.divide(abs(residual), size, out=np.zeros_like(size), where=size > 0)
    return float(ratio.max())


def _semidefinite_defect(P: np.ndarray) -> float:
    """Most negative eigenvalue of P scaled to unit diagonal (a correlation matrix), >= 0 if none.

    The scaling makes the test independent of the state units; a zero diagonal
    entry (a state the filter knows exactly) is left unscaled.
    """
    d = np.sqrt(np.abs(np.diag(P)))
    d[d == 0] = 1.0
    return max(0.0, -float(np.linalg.eigvalsh(P / np.outer(d, d)).min()))


def _unstable_modes(M: np.ndarray, dt):
    """Eigenvalues (and eigenvectors) of M not strictly stable, within rounding.

    Continuous: Re λ >= -tol; discrete: |λ| >= 1 - tol, tol = 1000 eps times
    the norm of M after balancing (`scipy.linalg.matrix_balance`, so that the
    tolerance does not depend on the state units).
    """
    from scipy.linalg import matrix_balance
    lam, V = np.linalg.eig(M)
    size = float(np.linalg.norm(matrix_balance(M, permute=False)[0], 1))
    tol = 1e3 * np.finfo(float).eps * (size if dt is None else max(size, 1.0))
    margin = -lam.real if dt is None else 1.0 - np.abs(lam)
    bad = margin <= tol
    return lam[bad], V[:, bad], tol


def _check_riccati(A, C, Q, R, P, L, dt) -> None:
    """Raise if A - L C is not stable; warn if the residual or P >= 0 is off (`kalman_gain`)."""
    lam, V, _ = _unstable_modes(A - L @ C, dt)
    if lam.size:
        raise _no_stabilizing_solution(A, C, dt, lam, V, closed_loop=True)
    residual = _riccati_residual(A, C, Q, R, P, dt)
    if residual > _RESIDUAL_TOL:
        warn_accuracy(
            f"kalman_gain: the Riccati equation is solved only to {residual:.1e} of the size of "
            f"its terms (rounding explains up to {_RESIDUAL_TOL:.0e}), so L and P are inaccurate. "
            "The equation is badly conditioned: check the units of Q and R (their ratio sets "
            "the gain), a nearly unobservable mode (obsv_singular_values), or rescale the states.",
            stacklevel=4)
    defect = _semidefinite_defect(P)
    if defect > 1e-8:
        warn_accuracy(
            f"kalman_gain: P is not positive semidefinite (eigenvalue {-defect:.1e} after scaling "
            "P to unit diagonal); the solution is inaccurate. Check the units of Q and R, or "
            "rescale the states.", stacklevel=4)


def _modes_of(A, Q):
    """Eigenvalues of A, right eigenvectors, and whether Q drives each mode (w^H Q w > 0 for
    the left eigenvector w, relative to |Q| |w|^2)."""
    from scipy.linalg import eig
    lam, W, V = eig(A, left=True, right=True)
    drive = np.einsum("ik,ij,jk->k", W.conj(), Q, W).real
    driven = drive > 1e-8 * max(float(np.linalg.norm(Q, 2)), 1e-300) * np.sum(abs(W) ** 2, axis=0)
    return lam, V, driven


def _fmt_mode(lam: complex, tol: float = 0.0) -> str:
    """λ for a message; parts within `tol` (rounding at A's scale) are printed as the 0 they are."""
    re = 0.0 if abs(lam.real) <= tol else lam.real
    im = 0.0 if abs(lam.imag) <= max(tol, 1e-12 * abs(lam)) else abs(lam.imag)
    return f"{re:.4g}" if im == 0.0 else f"{re:.4g} ± {im:.4g}j"


def _mode_reason(A, C, lam, v, dt, tol, closed_loop: bool, driven: bool) -> str | None:
    """Why the mode (lam, v) prevents a stabilizing solution, or None if it does not."""
    where = "on the imaginary axis" if dt is None else "on the unit circle"
    margin = -lam.real if dt is None else 1.0 - abs(lam)
    kind = where if abs(margin) <= tol else "unstable"
    v = v / v[np.argmax(np.abs(v))]
    shown = np.array2string((v.real if np.isrealobj(v) or not np.abs(v.imag).any() else v) + 0.0,
                            precision=3, suppress_small=True)   # + 0.0: no "-0."
    lam_text = _fmt_mode(lam, tol)
    if np.linalg.norm(C @ v) <= 1e-8 * np.linalg.norm(C, 2) * np.linalg.norm(v):
        return (f"the mode λ = {lam_text} of A (eigenvector {shown}) is {kind} and not "
                "observable through C (C v = 0): y carries no trace of it, so no gain L can "
                "move it ((A, C) is not detectable). Measure it (add a row to C that sees "
                "this mode) or remove it from the model.")
    if kind == where and not driven:
        return (f"the mode λ = {lam_text} of A (eigenvector {shown}) lies {where} and the "
                "process noise Q does not drive it: the model then claims this undamped mode "
                "is known exactly, the steady-state gain leaves it uncorrected and the "
                "estimation error never decays. Let Q act on it (e.g. Q = q * np.eye(n) with "
                "a small q > 0), or use the time-varying filter, whose gain decays.")
    if closed_loop:
        return (f"the solver returned a solution that is not stabilizing (A - L C has the "
                f"unstable eigenvalue {lam_text}): the equation is too badly conditioned; "
                "check the units of Q and R, or rescale the states.")
    return None


def _no_stabilizing_solution(A, C, dt, lam, V, driven=None, *, solver: str = "",
                             closed_loop: bool = False) -> ValueError:
    """The ValueError of `kalman_gain`, naming the modes of A that prevent a stabilizing P.

    `lam`, `V` are the suspect eigenpairs: those of A - L C that are not
    stable (closed_loop; a mode on the boundary that y sees is then one that
    Q does not drive), or all of A with `driven` (`_modes_of`) when the
    solver failed.
    """
    driven = np.zeros(lam.size, bool) if driven is None else driven
    _, _, tol = _unstable_modes(A, dt)
    reasons, seen = [], []
    for k in range(lam.size):
        # one of each conjugate pair, and one of a repeated eigenvalue (a Jordan block, whose
        # eigenvectors coincide: the same paragraph twice)
        if lam[k].imag < 0 or any(abs(lam[k] - other) <= max(tol, 1e-8 * abs(other)) for other in seen):
            continue
        seen.append(lam[k])
        margin = -lam[k].real if dt is None else 1.0 - abs(lam[k])
        if not closed_loop and margin > tol:                 # a stable mode of A is harmless
            continue
        reason = _mode_reason(A, C, lam[k], V[:, k], dt, tol, closed_loop, driven[k])
        if reason:
            reasons.append(reason)
    boundary = "the imaginary axis" if dt is None else "the unit circle"
    detail = " ".join(reasons) if reasons else (
        f"(the solver said: {solver}). Check that every unstable mode of A is observable "
        f"through C (is_observable) and that Q drives every mode on {boundary} (try Q = np.eye(n)).")
    return ValueError(
        f"kalman_gain: the algebraic Riccati equation has no stabilizing solution (A - L C "
        f"would not be stable): {detail} A stabilizing solution needs (A, C) detectable and "
        f"no mode on {boundary} that Q leaves undriven.")


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


def _records(t, u, y, m: int):
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


def _finite(a: np.ndarray, b: np.ndarray | None = None) -> bool:
    """True when no entry of a (and b) is inf or nan (a sum is finite only then)."""
    total = np.add.reduce(a, None)
    return math.isfinite(total if b is None else total + np.add.reduce(b, None))


_MAX_STEPS = 100_000


def _next_step(tau: float, dt: float, substeps: int, M: np.ndarray) -> float:
    """Length of the RK4 step from tau inside a sample interval of length dt.

    At most dt / substeps and at most 0.5 / rate (`_step_length`, the rate of
    (4.88) at the current P, M = A - L C); stretched to the end of the
    interval when within 1e-9 dt of it.
    """
    h = _step_length(M, min(dt - tau, dt / substeps))
    return dt - tau if dt - tau - h < 1e-9 * dt else h


def _advance(tau: float, h: float, dt: float, steps: int) -> tuple[float, int]:
    """(tau, steps) after a step of length h; RuntimeError past _MAX_STEPS steps."""
    steps += 1
    if steps > _MAX_STEPS:
        raise RuntimeError(
            f"the Riccati equation (4.88) needs more than {_MAX_STEPS} RK4 steps between two "
            "samples (its rate is huge): check the units of Q and R (module docstring), or "
            "start from a smaller P0.")
    return (dt if h == dt - tau else tau + h), steps


def _diverged(t_k: float) -> RuntimeError:
    return RuntimeError(
        f"the filter diverged at t={t_k:g} (non-finite estimate or P); check the "
        "model, the units of Q and R, and try substeps=10.")


def _rk4_interval(rhs, x, P, cur, w0, w1, t0: float, dt: float, substeps: int):
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
        h = _next_step(tau, dt, substeps, M)
        # w linear over the interval: w0 + s (w1 - w0) at s = (tau + h/2)/dt and (tau + h)/dt
        w_mid, w_end = w0 + (tau + h / 2) / dt * dw, w0 + (tau + h) / dt * dw
        t_mid, t_end = t0 + tau + h / 2, t0 + tau + h
        k2x, k2P, _, _ = rhs(x + h / 2 * k1x, P + h / 2 * k1P, w_mid, t_mid)
        k3x, k3P, _, _ = rhs(x + h / 2 * k2x, P + h / 2 * k2P, w_mid, t_mid)
        k4x, k4P, _, _ = rhs(x + h * k3x, P + h * k3P, w_end, t_end)
        x = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        P = P + h / 6 * (k1P + 2 * k2P + 2 * k3P + k4P)
        P = (P + P.T) / 2
        if not _finite(x, P):
            return x, P, None
        tau, steps = _advance(tau, h, dt, steps)
        cur = rhs(x, P, w_end, t_end)
    return x, P, cur


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


def _run_filter(rhs, t, w, P0, x0, substeps: int) -> KalmanResult:
    """Integrate (4.91) and (4.87)-(4.88) with RK4 on the grid t (w = [u, y] per sample)."""
    N = t.size
    x, P = x0.copy(), P0.copy()
    cur = rhs(x, P, w[0], t[0])
    xs, Ps, Ls = np.empty((N,) + x.shape), np.empty((N,) + P.shape), np.empty((N,) + cur[2].shape)
    for k, dt in enumerate(np.diff(t).tolist()):
        xs[k], Ps[k], Ls[k] = x, P, cur[2]
        x, P, cur = _rk4_interval(rhs, x, P, cur, w[k], w[k + 1], t[k], dt, substeps)
        if cur is None:
            raise _diverged(t[k + 1])
    xs[-1], Ps[-1], Ls[-1] = x, P, cur[2]
    return KalmanResult(t=t, x=xs, P=Ps, L=Ls)


def _riccati_interval(riccati, P, cur, dt: float, substeps: int):
    """RK4 on (4.88) alone over one sample interval, with the steps of `_rk4_interval`.

    `cur` = riccati(P) = (P', A - L C) at the start. Returns (P, cur, steps)
    at the end, cur None if P stopped being finite, and for each step
    (s_mid, s_end, h, P1, P2, P3, P4): the stage positions as fractions of
    the interval, the length and P at the four stages.
    """
    tau, count, steps = 0.0, 0, []
    while tau < dt:
        k1, M = cur
        h = _next_step(tau, dt, substeps, M)
        P2 = P + h / 2 * k1
        k2 = riccati(P2)[0]
        P3 = P + h / 2 * k2
        k3 = riccati(P3)[0]
        P4 = P + h * k3
        k4 = riccati(P4)[0]
        steps.append(((tau + h / 2) / dt, (tau + h) / dt, h, P, P2, P3, P4))
        P = P + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        P = (P + P.T) / 2
        if not _finite(P):
            return P, None, steps
        tau, count = _advance(tau, h, dt, count)
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
            raise _diverged(t[k + 1])
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


# RK4's error falls like h^4: 1000 steps per sample interval are 1e-12 of one step's error, and
# more only cost time in proportion (10^9 of them made the filters run for hours)
_MAX_SUBSTEPS = 1000


def _substeps(substeps) -> int:
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


def _initial_estimate(x0, n: int) -> np.ndarray:
    return as_vector(x0, "x0", size=n, why="the initial estimate x̂(0), one entry per state")


def _filter_setup(n: int, p: int, Q, R, P0, x0):
    """Validate the weights (sizes explained from n and p) and the initial P0, x̂(0)."""
    Q = _covariance(Q, "Q", n, definite=False, why=f"one row and column per state, n = {n}")
    R = _covariance(R, "R", p, definite=True, why=f"one row and column per output, p = {p}")
    P0 = _covariance(P0, "P0", n, definite=True, why=f"one row and column per state, n = {n}")
    return Q, R, P0, _initial_estimate(x0, n)


def kalman_bucy(sys, t, u, y, Q, R, P0, x0, *, substeps: int = 1) -> KalmanResult:
    """Time-varying Kalman(-Bucy) filter (4.86)-(4.88) on recorded data.

    Runs the observer x̂' = A x̂ + B u + L(t) (y - C x̂ - D u) (4.86) with
    L(t) = P(t) C^T R^{-1} (4.87) and the Riccati ODE (4.88) from
    P(0) = P0, x̂(0) = x0. `sys` is a continuous-time `StateSpace`; `u`
    (N, m) or None and `y` (N, p) are the recorded input and measurement on
    the grid `t`. Q (n, n) >= 0 and R (p, p) > 0 are intensities (module
    docstring). As t grows P(t) tends to the solution of `kalman_gain`.

    Returns a `KalmanResult` (estimate, P(t), L(t)). `substeps` RK4 steps
    (at least; 1 to 1000, ValueError beyond) are taken between samples.
    """
    sys = as_system(sys, kind="linear", time="continuous",
                    hint="for a NonlinearSystem use extended_kalman_filter.")
    t, u, y = _records(t, u, y, sys.m)
    if y.shape[1] != sys.p:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, "
                         f"expected {sys.p} (one per output, since C has {sys.p} rows).")
    Q, R, P0, x0 = _filter_setup(sys.n, sys.p, Q, R, P0, x0)
    G = sys.C.T @ np.linalg.inv(R)                      # L = P G (4.87)
    Ps, steps = _riccati_pass(sys.A, sys.C, Q, G, t, P0, _substeps(substeps))
    xs = _estimate_pass(sys, G, np.hstack([u, y]), x0, steps)
    finite = np.isfinite(xs).all(axis=1)
    if not finite.all():
        raise _diverged(t[np.argmin(finite)])
    return KalmanResult(t=t, x=xs, P=Ps, L=Ps @ G)


def _accepts_batches(fun, x0: np.ndarray, u0: np.ndarray) -> bool:
    """True when fun(X, U), states and inputs as columns, agrees column by column with
    fun(x, u) on single states (within 1e-12), checked on the states of `_perturbed(x0)`.

    The test of `simulation._check_batch`, but a function written for one state at a
    time (``float(x[0])``, ``if x[0] > 0``, ...) is an answer, not an error; so is a
    function that raises here (it is then called one state at a time, and an error it
    raises there is reported with its context).
    """
    X, _ = _perturbed(x0)
    U = u0[:, None].repeat(X.shape[1], axis=1)
    try:
        batch = np.asarray(fun(X, U), dtype=float)
        return _agrees_column_by_column(fun, X, U, batch)
    except Exception:                   # written for one state at a time
        return False


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
    batch of `_perturbed(x)`: x and its 2n central-difference neighbours as columns."""
    cols = 2 * n + 1
    f, h = _user(f, "f", batch=True), _user(h, "h", batch=True)

    def model(x, u, t):
        X, step = _perturbed(x)
        U = u[:, None].repeat(cols, axis=1)
        G = np.concatenate((f(X, U, t).reshape(-1, cols), h(X, U, t).reshape(-1, cols)))
        J = _quotients(G, step)
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
    f_raw, h_raw = _raw_field(sys), _raw_output(sys)   # wrapped once, by _user, with the time
    if dfdx is None and dhdx is None and _accepts_batches(f_raw, x0, u0) \
            and _accepts_batches(h_raw, x0, u0):
        return _batched_model(f_raw, h_raw, n)
    f, h = _user(f_raw, "f"), _user(h_raw, "h")
    jf = _user_jacobian(dfdx, "dfdx", (n, n), "∂f/∂x (4.92), n x n") if dfdx else \
        (lambda x, v, t: _jacobian(lambda z: f(z, v, t), x, refine=False))
    jh = _user_jacobian(dhdx, "dhdx", (p, n), "∂h/∂x (4.93), p x n") if dhdx else \
        (lambda x, v, t: _jacobian(lambda z: h(z, v, t), x, refine=False))
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
    t, u, y = _records(t, u, y, sys.m)
    x0 = _initial_estimate(x0, sys.n)
    _user(_raw_field(sys), "f")(x0, u[0], t[0])
    sys.check(x0, u[0])
    p_h = _user(_raw_output(sys), "h")(x0, u[0], t[0]).size
    if p_h != y.shape[1]:
        raise ValueError(f"y has the wrong number of columns: received {y.shape[1]}, expected "
                         f"{p_h} (the number of outputs of sys.h).")
    Q, R, P0, x0 = _filter_setup(sys.n, p_h, Q, R, P0, x0)
    model = _ekf_model(sys, p_h, dfdx, dhdx, x0, u[0])
    return _run_filter(_ekf_rhs(model, Q, R, sys.m), t, np.hstack([u, y]), P0, x0,
                       _substeps(substeps))


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
    W = _covariance(W, "intensity", W.shape[0], definite=False)
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
    sys = as_system(sys, time="continuous")
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
