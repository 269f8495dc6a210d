"""Pole placement by state feedback u = K x (section 3.3).

The course's sign convention: u = K x and the closed loop is A + B K (3.17).
MATLAB, SciPy and python-control use u = -K x, so coursekit's K is minus theirs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import as_poles
from .controllability import _pair, _rank, ccf_transform, require_controllable

__all__ = ["place", "place_details", "PlacementDetails", "poly_from_roots"]


def poly_from_roots(poles) -> np.ndarray:
    """Monic polynomial with the given roots, ascending ``[p_0, ..., p_{n-1}]`` (3.43)."""
    return np.real(np.poly(np.asarray(poles, dtype=complex)))[::-1][:-1].copy()


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
    """Single-input pole placement through the CCF, returning every step (3.46)-(3.47)."""
    A, B = _pair(A, B)
    n = A.shape[0]
    poles = as_poles(poles, "poles", count=n)
    T = ccf_transform(A, B)
    A_ccf = T @ A @ np.linalg.inv(T)
    a = -A_ccf[-1].copy()          # last row of the CCF is -[a_0 ... a_{n-1}]
    p = poly_from_roots(poles)     # desired p(s) (3.43)
    K_ccf = (a - p).reshape(1, n)  # (3.46): k~_i = -p_{i-1} + a~_{i-1}
    K = K_ccf @ T                  # (3.47): u = K~ T x
    return PlacementDetails(T=T, A_ccf=A_ccf, a=a, p=p, K_ccf=K_ccf, K=K)


def place(A, B, poles) -> np.ndarray:
    """State-feedback gain K, shape (m, n), with eig(A + B K) = poles.

    Convention: u = K x, closed loop A + B K (3.17); this K is *minus* the gain
    of MATLAB's ``place``, SciPy's ``place_poles`` and python-control.

    * One input: the notes' method (3.46)-(3.47): transform to the CCF with
      `ccf_transform`, compare the coefficients of the open-loop and desired
      characteristic polynomials, map back with T. Repeated poles are fine.
      `place_details` shows the intermediate quantities.
    * Several inputs: K is not unique; SciPy's ``place_poles`` (Tits-Yang
      robust method, which maximizes the distance of the closed-loop
      eigenvectors from being dependent) picks one, and its sign is flipped.
      A pole may then be repeated at most rank(B) times.

    Accuracy (single input): against a 40-digit evaluation of the same
    gain, K is correct to about 1e-13 relative for random systems with
    n = 10 and cond(Wc) up to 1e7, because T is found by one linear solve
    with Wc^T (never by inverting Wc) and T_{i+1} = T_i A is exact up to
    rounding. SciPy's iterative ``place_poles`` is the *less* accurate of the
    two there (errors up to 1e-5), so tests compare with an Ackermann or
    high-precision oracle instead.

    Raises `NotControllableError` if (A, B) is not controllable and
    `ValueError` for a wrong number of poles or a complex pole without its
    conjugate.
    """
    A, B = _pair(A, B)
    n, m = B.shape
    poles = as_poles(poles, "poles", count=n)
    if m == 1:
        return place_details(A, B, poles).K
    require_controllable(A, B, purpose="placing every closed-loop pole")
    rank_B = _rank(B, None)
    values, counts = _multiplicities(poles)
    too_many = [(v, c) for v, c in zip(values, counts) if c > rank_B]
    if too_many:
        v, c = too_many[0]
        raise ValueError(
            f"poles repeats {v:g} {c} times, but with several inputs a pole can be repeated "
            f"at most rank(B) = {rank_B} times by the robust method; spread the poles slightly "
            "(e.g. -2, -2.1, -2.2) or use a single input."
        )
    from scipy.signal import place_poles
    return -np.real(place_poles(A, B, poles).gain_matrix)


def _multiplicities(poles: np.ndarray, rtol: float = 1e-9):
    values, counts = [], []
    for p in poles:
        for i, v in enumerate(values):
            if abs(p - v) <= rtol * max(1.0, abs(v)):
                counts[i] += 1
                break
        else:
            values.append(p)
            counts.append(1)
    return values, counts
