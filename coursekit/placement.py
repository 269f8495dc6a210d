"""Pole placement by state feedback u = K x (section 3.3), checked against its result.

The course's sign convention: u = K x and the closed loop is A + B K (3.17).
MATLAB, SciPy and python-control use u = -K x, so coursekit's K is minus theirs.

Every gain is checked after it is computed: the eigenvalues of the closed
loop are matched to the requested poles, and an `AccuracyWarning` says by how
much they miss when they miss by more than the tolerance of `PoleMatch`.

The gain and its check are `_pole_placement`, shared with `place_observer`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._pairs import as_pair, require_controllable
from ._pole_placement import PoleMatch, check_size, place_gain, require_finite, warn_if_missed
from ._validation import as_poles
from .controllability import ccf_transform, charpoly

__all__ = ["place", "place_details", "PlacementDetails", "poly_from_roots"]


def poly_from_roots(poles) -> np.ndarray:
    """Monic polynomial with the given roots, ascending ``[p_0, ..., p_{n-1}]`` (3.43).

    ``poles`` must be finite numbers, complex ones in conjugate pairs (a real
    polynomial has no other roots), and at least one (degree n >= 1: an empty
    list is almost always a mistake, and the degree-0 polynomial 1 has no
    coefficients to return); otherwise `ValueError` names the problem. Any
    number n of roots is accepted: the degree is the number of roots.
    """
    try:
        count = int(np.size(poles))
    except (TypeError, ValueError):
        count = 1              # as_poles explains why poles is not a list of numbers
    if count == 0:
        raise ValueError("poles is empty: received no roots; pass at least one, e.g. "
                         "poly_from_roots([-1, -2]) for s^2 + 3 s + 2.")
    poles = as_poles(poles, "poles", count=count)
    return np.real(np.poly(poles))[::-1][:-1].copy()


@dataclass(repr=False)
class PlacementDetails:
    """The intermediate quantities of the single-input method (3.46)-(3.47).

    Attributes: ``T`` (z = T x in CCF), ``A_ccf`` (T A T^-1), ``a`` (open-loop
    coefficients a_0..a_{n-1}), ``p`` (desired coefficients p_0..p_{n-1}),
    ``K_ccf`` (gain in z coordinates, k~_i = a~_{i-1} - p_{i-1}) and ``K`` (= K_ccf T).
    """

    T: np.ndarray
    A_ccf: np.ndarray
    a: np.ndarray
    p: np.ndarray
    K_ccf: np.ndarray
    K: np.ndarray

    def __repr__(self) -> str:
        fmt = lambda v: np.array2string(np.asarray(v), precision=4, suppress_small=True)  # noqa: E731
        return "\n".join(f"{k:>5} = {fmt(getattr(self, k))}" for k in ("T", "A_ccf", "a", "p", "K_ccf", "K"))


def place_details(A, B, poles) -> PlacementDetails:
    """Single-input pole placement through the CCF, returning every step (3.46)-(3.47).

    This is the notes' method, kept literally for teaching. `place` returns
    the same gain (it is unique for one input) computed in a way that stays
    accurate for larger or badly scaled systems. Like `place`, it checks
    eig(A + B K) against `poles` and issues an `AccuracyWarning` when they miss.
    """
    A, B = as_pair(A, B)
    n = A.shape[0]
    poles = as_poles(poles, "poles", count=n)
    charpoly(A)                    # its coefficients, the CCF's last row, must be floats
    T = ccf_transform(A, B)
    A_ccf = T @ A @ np.linalg.inv(T)
    a = -A_ccf[-1].copy()          # last row of the CCF is -[a_0 ... a_{n-1}]
    p = poly_from_roots(poles)     # desired p(s) (3.43)
    K_ccf = (a - p).reshape(1, n)  # (3.46): k~_i = -p_{i-1} + a~_{i-1}
    K = K_ccf @ T                  # (3.47): u = K~ T x
    warn_if_missed(PoleMatch(A + B @ K, poles, A), _FEEDBACK)
    return PlacementDetails(T=T, A_ccf=A_ccf, a=a, p=p, K_ccf=K_ccf, K=K)


def place(A, B, poles) -> np.ndarray:
    """State-feedback gain K, shape (m, n), with eig(A + B K) = poles.

    Convention: u = K x, closed loop A + B K (3.17); this K is *minus* the gain
    of MATLAB's ``place``, SciPy's ``place_poles`` and python-control.

    * One input: the gain is unique and equals the notes' (3.46)-(3.47)
      (`place_details` shows those steps). It is computed as Ackermann's
      form of (3.46)-(3.47), K = -e_n^T Wc^{-1} p(A), evaluated without Wc
      and without the coefficients of p: (A, B) is balanced by a diagonal
      scaling, brought to controller-Hessenberg form by orthogonal
      transformations (Q^T B = beta e_1, H = Q^T A Q upper Hessenberg, where
      Wc is triangular), and p(H) is applied as the product of its factors
      (H - lambda_i I). Measured against a 120-digit evaluation of the exact
      gain, the relative error of K is at most 2e-14 for random systems up to
      n = 20, with states scaled by 1e-4..1e4 and for the DC motor in SI
      units, where the CCF route loses up to 4e-11 (its Wc solve) and SciPy's
      ``place_poles`` up to 1e-5 at n = 10 and all digits at n = 20.
    * Several inputs: K is not unique. B is first compressed to its column
      rank r (SVD, B V = [B_r, 0]), so a rank-deficient B is fine. SciPy's
      robust method (Tits-Yang, which keeps the closed-loop eigenvectors
      well conditioned) picks K when no pole is repeated more than r times
      and n <= 40 (its work grows like n^4: 8 s at n = 50);
      otherwise, or when that method fails or misses, Heymann's lemma is
      used: a feedback K0 and an input direction g with (A + B K0, B g)
      controllable reduce the problem to one input, K = K0 + g k. Any
      controllable pair thus gets any set of poles closed under conjugation.

    Self-check: the closed-loop eigenvalues are matched to `poles` (optimal
    assignment) and must agree to 1e-6 of the pole scale (the largest
    requested or achieved pole magnitude, or A's spectral radius if larger,
    so that deadbeat poles at 0 are judged fairly); a pole requested k times must have
    its k eigenvalues average to it to 1e-6 and, with one input, each lie
    within (1e-6)^(1/k) of it, which is how far a relative perturbation of
    1e-6 moves a k-fold eigenvalue. With r >= 2 independent inputs a gain
    whose Jordan chains are at most ceil(k/r) long exists, and each eigenvalue
    must lie within max(1e-6, 1e-12^(1/ceil(k/r))) (1e-6 for a pole
    requested up to 2r times): Heymann's one-chain gain for a pole requested
    more than r times scatters it by eps^(1/k) (1e-5 for k = 3) and is
    reported. Otherwise an `AccuracyWarning` gives the largest error and the
    eigenvector condition number of A + B K. Some requests cannot be met in
    double precision by any method: for n = 20 and poles -1, ..., -20 even
    the exact gain, rounded to double, puts the poles off by orders of
    magnitude (the closed loop's eigenvalues are that sensitive), so the
    warning is then the right answer, not a defect of the method.

    Raises `NotControllableError` if (A, B) is not controllable and
    `ValueError` for a wrong number of poles or a complex pole without its
    conjugate, and for more than 100 states with several inputs (before any
    work: minutes at n = 200, for poles no double-precision gain places).
    A request far below A's own scale (poles of size 1 for an A of 1e200)
    misses by more than the poles' size and gets the `AccuracyWarning`.
    """
    A, B = as_pair(A, B)
    poles = as_poles(poles, "poles", count=A.shape[0])
    check_size(A.shape[0], B.shape[1], f"B has {B.shape[1]} columns")
    require_controllable(A, B, purpose="placing every closed-loop pole")
    K, match = place_gain(A, B, poles)
    require_finite(K, _FEEDBACK)
    warn_if_missed(match, _FEEDBACK)
    return K


_FEEDBACK = {
    "gain": "K",
    "weak": ("the input reaches some states (the pair is nearly uncontrollable, or the poles are "
             "huge; see ctrb_singular_values)"),
    "what": "closed-loop poles eig(A + B K)",
    "advice": ("Try fewer or less clustered poles (e.g. not many poles spread evenly far from "
               "the open-loop ones), poles closer to the open-loop ones, or rescale the states "
               "and time to similar magnitudes"),
}


