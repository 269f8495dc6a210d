"""Observers as systems that `simulate` can run (sections 4.3 and 4.6).

The observer (4.25) is a copy of the plant corrected by the measurement:

    x̂' = A x̂ + B u + L (y - ŷ),   ŷ = C x̂ + D u.

Three ways to put it to work, each returning a `StateSpace`:

* `observer_system(sys, L)` -- the observer alone, driven by the recorded
  input and measurement ``[u; y]``; use it on measured (e.g. noisy) data;
* `plant_with_observer(sys, L)` -- plant and observer side by side with the
  state ``[x; x̂]``, the same input u applied to both (figure 4.4, 4.5);
  ``L = 0`` gives the uncorrected copy of (4.20)-(4.24);
* `output_feedback(sys, K, L)` -- the loop closed with u = K x̂ + v (4.73),
  state ``[x; x̂]``; its eigenvalues are those of A + B K and A - L C
  (the separation principle). `observer_tracking_input` turns a desired
  trajectory (x_d, u_d) into the v that gives the tracking law (4.77).
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._validation import as_matrix, as_series
from .systems import StateSpace

__all__ = ["observer_system", "plant_with_observer", "output_feedback", "observer_tracking_input",
           "separation_eigenvalues"]


def _plant(sys) -> StateSpace:
    return as_system(sys, kind="linear", time="continuous", hint="the observers of chapter 4 copy "
                     "a linear plant (for a NonlinearSystem use extended_kalman_filter).")


def _gain_L(L, sys: StateSpace) -> np.ndarray:
    return as_matrix(L, "L", rows=sys.n, cols=sys.p, rows_why=f"one per state, n = {sys.n}",
                     cols_why=f"one per output, p = {sys.p}")


def _gain_K(K, sys: StateSpace) -> np.ndarray:
    return as_matrix(K, "K", rows=sys.m, cols=sys.n, rows_why=f"one per input, m = {sys.m}",
                     cols_why=f"one per state, n = {sys.n}")


def observer_system(sys, L) -> StateSpace:
    """The observer (4.25) as a system with inputs ``[u; y]`` and output x̂.

    Rewriting (4.25) with ŷ = C x̂ + D u:
    x̂' = (A - L C) x̂ + (B - L D) u + L y. Simulate it on a recorded input
    and measurement, ``simulate(obs, t, u=np.hstack([u, y]), x0=xhat0)``;
    the output (and the state) is the estimate x̂.
    """
    sys = _plant(sys)
    L = _gain_L(L, sys)
    # (4.25): x̂' = A x̂ + B u + L (y - C x̂ - D u)
    A_o = sys.A - L @ sys.C
    B_o = np.hstack([sys.B - L @ sys.D, L])
    return StateSpace(A_o, B_o, np.eye(sys.n), name=f"observer of {sys.name or 'the plant'}")


def plant_with_observer(sys, L) -> StateSpace:
    """Plant (4.19) and observer (4.25) in one system, state ``[x; x̂]`` (2n).

    Both receive the same input u (m inputs). The measurement correction
    L (y - ŷ) = L C (x - x̂) couples them (the D u terms cancel), so

        [x; x̂]' = [[A, 0], [L C, A - L C]] [x; x̂] + [B; B] u.

    The outputs are ``[y; x̂]`` (p + n). ``L = 0`` (e.g. ``np.zeros((n, p))``)
    is the mere copy of the plant (4.20), whose error x̂ - x obeys
    x̃' = A x̃ (4.24); with L it obeys x̃' = (A - L C) x̃ (4.27).
    """
    sys = _plant(sys)
    L = _gain_L(L, sys)
    n = sys.n
    A_aug = np.block([[sys.A, np.zeros((n, n))], [L @ sys.C, sys.A - L @ sys.C]])
    B_aug = np.vstack([sys.B, sys.B])
    C_aug = np.block([[sys.C, np.zeros((sys.p, n))], [np.zeros((n, n)), np.eye(n)]])
    D_aug = np.vstack([sys.D, np.zeros((n, sys.m))])
    return StateSpace(A_aug, B_aug, C_aug, D_aug, name=f"{sys.name or 'plant'} with observer")


def output_feedback(sys, K, L) -> StateSpace:
    """The output-feedback loop u = K x̂ + v (4.73), state ``[x; x̂]``, input v.

    Substituting u into the plant and the observer:

        x'  = A x + B K x̂ + B v
        x̂' = L C x + (A - L C + B K) x̂ + B v

    ``v = 0`` is the regulator (4.73); ``v = u_d - K x_d`` gives the
    tracking controller (4.77) (see `observer_tracking_input`). The outputs
    are ``[y; x̂; u]`` (p + n + m). Gains in the course's signs: u = K x
    with A + B K (3.17), observer error A - L C (4.27).
    """
    sys = _plant(sys)
    K, L = _gain_K(K, sys), _gain_L(L, sys)
    A, B, C, D = sys.A, sys.B, sys.C, sys.D
    n, m = sys.n, sys.m
    # y - ŷ = C (x - x̂): the D u terms cancel
    A_cl = np.block([[A, B @ K], [L @ C, A - L @ C + B @ K]])
    B_cl = np.vstack([B, B])
    C_cl = np.block([[C, D @ K], [np.zeros((n, n)), np.eye(n)], [np.zeros((m, n)), K]])
    D_cl = np.vstack([D, np.zeros((n, m)), np.eye(m)])
    return StateSpace(A_cl, B_cl, C_cl, D_cl, name=f"{sys.name or 'plant'} with output feedback")


def observer_tracking_input(K, x_d, u_d) -> np.ndarray:
    """The input v of `output_feedback` that realizes the tracking law (4.77).

    u = K (x̂ - x_d) + u_d = K x̂ + v with v = u_d - K x_d. `x_d` is the
    desired state trajectory sampled on the time grid, shape (N, n), and
    `u_d` its feedforward input, shape (N, m) (time-major). Returns v, (N, m).
    """
    K = as_matrix(K, "K")
    m, n = K.shape
    x_d = as_matrix(x_d, "x_d", cols=n, cols_why=f"one column per state, since K is {m}x{n}")
    u_d = as_series(u_d, "u_d", samples=x_d.shape[0], channels=m, samples_why="one row per time, as x_d",
                    channels_why=f"one column per input, since K is {m}x{n}")
    # (4.77): v = u_d - K x_d
    return u_d - x_d @ K.T


def separation_eigenvalues(sys, K, L) -> tuple[np.ndarray, np.ndarray]:
    """The two halves of the output-feedback spectrum: ``(eig(A + B K), eig(A - L C))``.

    By the separation principle the eigenvalues of `output_feedback` are
    exactly the union of these: in the coordinates (x, x̃ = x̂ - x) the
    closed-loop matrix is block triangular [[A + B K, B K], [0, A - L C]].
    """
    sys = _plant(sys)
    K, L = _gain_K(K, sys), _gain_L(L, sys)
    return np.linalg.eigvals(sys.A + sys.B @ K), np.linalg.eigvals(sys.A - L @ sys.C)
