"""What `simulate` shares with `noise`: the exact LTI step of (2.4) and the float-range check."""

from __future__ import annotations

import math

import numpy as np

from .diagnostics import SimulationError
from .systems import StateSpace

__all__ = ["step_matrices", "check_finite", "overflow_error"]


def overflow_error(sys, what: str, *, feedback: bool = False) -> SimulationError:
    """The error for a state beyond the float range: when, why, and what to try."""
    return SimulationError(
        f"the simulation left the float range (about 1.8e308): {what}. {_growth(sys, feedback)} "
        "To see the growth, simulate a shorter time (stop before this time) or plot |x| on a "
        "log scale; to keep the state bounded, stabilize the system (chapter 3)."
    )


def _growth(sys, feedback: bool = False) -> str:
    """Why the state grows: for a StateSpace, the eigenvalues of A (section 3.2.2)."""
    if not isinstance(sys, StateSpace):
        return ("The solution grows without bound: it runs away from an unstable equilibrium, "
                "or has a finite escape time (as x' = x^2 does).")
    lam = np.linalg.eigvals(sys.A)
    of_a = ("of A alone (your input u(t, x) changes the dynamics: for u = K x look at the "
            "eigenvalues of A + B K)" if feedback else "of A")
    if sys.is_discrete:
        rho = float(np.abs(lam).max())
        verdict = (f"> 1: the system is unstable and |x| grows like {rho:.4g}^k, passing 1e308 "
                   f"within about {709.8 / np.log(rho):.4g} steps") if rho > 1 else \
            "<= 1: the growth comes from the input"
        return f"The spectral radius (largest |eigenvalue|) {of_a} is {rho:.4g} {verdict}."
    a = float(lam.real.max())
    verdict = (f"> 0: the system is unstable (section 3.2.2) and |x| grows like e^({a:.4g} t), "
               f"passing 1e308 within about {709.8 / a:.4g} time units") if a > 0 else \
        "<= 0: the growth comes from the input"
    return f"The largest real part of the eigenvalues {of_a} is {a:.4g} {verdict}."


def check_finite(sys, t: np.ndarray, x: np.ndarray, *, feedback: bool = False) -> None:
    """Raise `overflow_error` at the first sample where x (N, ...) is not finite."""
    with np.errstate(over="ignore"):   # a sum of large finite entries may overflow: settled below
        if math.isfinite(x.sum()):     # a cheap screen: a sum is finite
            return
    bad = ~np.isfinite(x.reshape(t.size, -1)).all(axis=1)
    if bad.any():
        k = max(int(np.argmax(bad)), 1)
        raise overflow_error(sys, f"the state is finite up to t = {t[k - 1]:.6g} (largest |x| = "
                        f"{np.abs(x[k - 1]).max():.3g}) and overflows by t = {t[k]:.6g}",
                        feedback=feedback)


def step_matrices(A: np.ndarray, B: np.ndarray, h: float):
    """`lti_step_matrices` for checked arguments."""
    from scipy.linalg import expm
    n, m = B.shape
    # The input blocks are linear in B: a B far larger than A h (B scaled by 1e200) would make
    # expm square many more times and spoil Ad = e^(A h); B is brought to A h's size by a power
    # of two (exact), and the blocks scaled back.
    with np.errstate(over="ignore"):
        ratio = float(np.abs(B).max(initial=0.0)) * h / max(1.0, float(np.abs(A).max(initial=0.0)) * h)
    scale = 2.0 ** np.ceil(np.log2(ratio)) if ratio > 1.0 and np.isfinite(ratio) else 1.0
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A * h
    M[:n, n:n + m] = (B / scale) * h
    M[n:n + m, n + m:] = np.eye(m)
    with np.errstate(over="ignore", invalid="ignore"):   # an overflow is raised just below
        E = expm(M)
        Ad, G0, G1 = E[:n, :n], E[:n, n:n + m] * scale, E[:n, n + m:] * scale
    if not (np.isfinite(Ad).all() and np.isfinite(G0).all() and np.isfinite(G1).all()):
        raise overflow_error(StateSpace(A), f"e^(A h) over one step h = {h:g} is already beyond it")
    return Ad, G0 - G1, G1
