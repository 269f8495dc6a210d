"""Steady-state Kalman gain design (section 4.7): `kalman_gain` and its checks.

* `kalman_gain(A, C, Q, R)` -- the steady-state gain: L = P C^T R^{-1} (4.87)
  with P the constant solution of the Riccati equation (4.88) (Ṗ = 0, the
  *algebraic* Riccati equation). It is the dual of the LQR equation: SciPy's
  ``solve_continuous_are(a, b, q, r)`` solves a^T X + X a - X b r^{-1} b^T X + q = 0,
  and with a = A^T, b = C^T this is exactly 0 = A P + P A^T - P C^T R^{-1} C P + Q.
  With ``dt=Ts`` the same for a sampled model x(k+1) = A x(k) + w(k): the
  discrete algebraic Riccati equation and the predictor gain of python-control's
  ``dlqe``. Either way the result is checked (residual, P >= 0, A - L C stable).

The Kalman filters live beside it: `coursekit.kalman_bucy` (the time-varying
filter (4.86)-(4.88)), `coursekit.ekf` (the extended filter (4.91)-(4.93)),
`coursekit.kalman_discrete` (sampled data), and `coursekit.noise` (white noise,
noisy simulations and Van Loan's sampled covariance).

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
for process noise of intensity Q (`van_loan` computes it exactly).
"""

from __future__ import annotations

import numpy as np

from ._pairs import as_obs_pair
from ._validation import as_covariance, as_dt, warn_accuracy

__all__ = ["kalman_gain"]


def _state_why(n: int) -> str:
    return f"one row and column per state, since A is {n}x{n}"


def _output_why(p: int) -> str:
    return (f"one row and column per output, since C has {p} row{'s' if p > 1 else ''}; "
            "if the system has another number of outputs, check C")


def _gain_inputs(A, C, Q, R):
    """Validate in the order the sizes come from: A (n), C (p rows), then Q (n x n), R (p x p)."""
    A, C = as_obs_pair(A, C)
    n, p = A.shape[0], C.shape[0]
    Q = as_covariance(Q, "Q", n, definite=False, why=_state_why(n))
    R = as_covariance(R, "R", p, definite=True, why=_output_why(p))
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


def _same_mode(lam: complex, v: np.ndarray, mu: complex, w: np.ndarray, tol: float) -> bool:
    """The same eigenvalue (to `tol`) with a parallel unit eigenvector: one mode, listed once."""
    return abs(lam - mu) <= max(tol, 1e-8 * abs(mu)) and abs(np.vdot(w, v)) > 1 - 1e-6


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
        # one of each conjugate pair, and one eigenpair of a Jordan block (a repeated eigenvalue
        # whose eigenvectors coincide: the same paragraph twice)
        v = V[:, k] / np.linalg.norm(V[:, k])
        if lam[k].imag < 0 or any(_same_mode(lam[k], v, mu, w, tol) for mu, w in seen):
            continue
        seen.append((lam[k], v))
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
