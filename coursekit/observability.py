"""Observability (section 4.2), the observability canonical form (4.4-4.5) and
observer gains by pole placement (4.46, 4.60, 4.84).

Observability is the dual of controllability: (A, C) is observable exactly
when (A^T, C^T) is controllable, since the observability matrix Wo of (4.15)
is the transpose of the controllability matrix of (A^T, C^T). This module
therefore reuses the helpers of `_pairs` and `_pole_placement` instead
of repeating them.

* `obsv(A, C)` builds Wo = [C; CA; ...; CA^(n-1)] (4.12), (4.15);
* `is_observable(A, C)` is Kalman's criterion, rank Wo = n, decided without
  units by duality with `is_controllable`;
* `ocf_transform(A, C)` returns T with z = T x in OCF (4.31)-(4.32);
* `place_observer(A, C, poles)` returns L with eig(A - L C) = poles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._pairs import (Staircase, as_obs_pair, canonical_transform, check_tol, ctrb_unchecked, marginal_note,
                     unit_free_staircase)
from ._pole_placement import PoleMatch, check_size, place_gain, require_finite, warn_if_missed
from ._validation import as_poles
from .controllability import charpoly
from .diagnostics import NotObservableError
from .placement import poly_from_roots

__all__ = ["obsv", "obsv_singular_values", "is_observable", "ocf_transform", "place_observer",
           "place_observer_details", "ObserverDetails"]


def _obsv(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    # duality: Wo = [C; CA; ...; CA^(n-1)] = Wc(A^T, C^T)^T
    return ctrb_unchecked(A.T, C.T).T


def obsv(A, C) -> np.ndarray:
    """Observability matrix Wo = [C; CA; CA^2; ...; CA^(n-1)] (4.15), shape (n p, n).

    With one output it is the n x n matrix of (4.12); with p outputs the
    blocks C A^i have p rows each.
    """
    A, C = as_obs_pair(A, C)
    return _obsv(A, C)


def obsv_singular_values(A, C) -> np.ndarray:
    """Singular values of Wo, largest first: the smallest says how close to unobservable."""
    return np.linalg.svd(obsv(A, C), compute_uv=False)


def is_observable(A, C, *, tol: float | None = None) -> bool:
    """Kalman's criterion (4.14)-(4.15), rank Wo = n, decided without units.

    By duality (Wo is the transpose of the controllability matrix of (A^T, C^T)) this is
    ``is_controllable(A.T, C.T, tol=tol)``: the same answer in any units and coordinates, for
    the reasons `coursekit._pairs` gives. It also works for several outputs, where Wo is not
    square and the notes' ``det(Wo) != 0`` test does not apply. `tol` as in `is_controllable`.
    """
    A, C = as_obs_pair(A, C)
    return unit_free_staircase(A.T, C.T, check_tol(tol)).rank == A.shape[0]


def require_observable(A: np.ndarray, C: np.ndarray, *, purpose: str,
                       tol: float | None = None) -> Staircase:
    """Return the staircase of the dual pair (A^T, C^T), or raise NotObservableError.

    The verdict is `is_observable`'s; the message says how many directions
    leave no trace in y, what to do, and whether the decision was marginal.
    """
    v = unit_free_staircase(A.T, C.T, check_tol(tol))
    n, r = A.shape[0], v.rank
    if r < n:
        raise NotObservableError(
            f"(A, C) is not observable, so {purpose} is impossible: the observability "
            f"matrix Wo = [C; CA; ...; CA^{n - 1}] (4.15) has rank {r} < n = {n} (decided "
            "without units by an orthogonal staircase of the balanced dual pair (A^T, C^T); "
            f"see is_observable). {n - r} direction(s) of the state leave no trace in y: "
            "measure another combination of the states (add a row to C), or check the "
            "entries of A and C." + marginal_note(v, "nearly observable")
        )
    return v


def _single_output(C: np.ndarray, what: str) -> None:
    if C.shape[0] != 1:
        raise ValueError(
            f"C must have a single row for {what}: received shape {C.shape}; the OCF (4.31) "
            "is defined for one output. Pick one row of C, or use place_observer() "
            "which handles several outputs."
        )


def ocf_transform(A, C) -> np.ndarray:
    """Transform T such that z = T x puts (A, C) in observability canonical form.

    Implements (4.48)-(4.56): with V = T^{-1} = [V_1, ..., V_n], the first
    column solves Wo V_1 = e_n (4.55)-(4.56) and the others follow from
    V_{i+1} = A V_i (4.52). Then ``T A T^{-1}`` has ones on the subdiagonal
    and last column ``-[a_0 ... a_{n-1}]``, and ``C T^{-1} = e_n^T`` (4.31)-(4.32).

    By duality V^T is the CCF transform of (A^T, C^T) (V_1^T Wo^T = e_n^T is
    (2.65) for that pair), so V is computed by `ccf_transform`'s method:
    without forming Wo, in unit-free coordinates, and checked, with an
    `AccuracyWarning` when C V misses e_n^T or T A V misses the OCF by more
    than rounding explains. Badly scaled but observable systems (a DC motor
    in SI units) get their transform.

    Single output only (C of shape (1, n)). Raises `NotObservableError` when
    (A, C) is not observable: an unobservable system has no OCF.
    """
    A, C = as_obs_pair(A, C)
    _single_output(C, "the OCF")
    # duality: V = T^{-1} has columns V_i = (T_dual,i)^T, T_dual the CCF transform of (A^T, C^T)
    T_dual = canonical_transform(A.T, C.T, form="observability canonical form (4.31)",
                                 purpose="a transform to the observability canonical form",
                                 equations="C T^-1 = e_n^T and the structure of T A T^-1",
                                 require=_require_observable_dual)
    # (4.49): T = V^{-1}
    return np.linalg.inv(T_dual.T)


def _require_observable_dual(At: np.ndarray, Ct: np.ndarray, *, purpose: str) -> Staircase:
    """`require_observable` called with the dual pair (A^T, C^T)."""
    return require_observable(At.T, Ct.T, purpose=purpose)


@dataclass(repr=False)
class ObserverDetails:
    """The intermediate quantities of the single-output method (4.46), (4.60).

    Attributes: ``T`` (z = T x in OCF), ``V`` (= T^{-1}), ``A_ocf`` (T A V),
    ``C_ocf`` (C V = e_n^T), ``a`` (open-loop coefficients a_0..a_{n-1}),
    ``p`` (desired coefficients p_0..p_{n-1}), ``L_ocf`` (gain in z
    coordinates, l_i = p_{i-1} - a_{i-1}) and ``L`` (= V L_ocf).
    """

    T: np.ndarray
    V: np.ndarray
    A_ocf: np.ndarray
    C_ocf: np.ndarray
    a: np.ndarray
    p: np.ndarray
    L_ocf: np.ndarray
    L: np.ndarray

    def __repr__(self) -> str:
        fmt = lambda v: np.array2string(np.asarray(v), precision=4, suppress_small=True,  # noqa: E731
                                        prefix=" " * 9)
        names = ("T", "V", "A_ocf", "C_ocf", "a", "p", "L_ocf", "L")
        return "\n".join(f"{k:>6} = {fmt(getattr(self, k))}" for k in names)


def place_observer_details(A, C, poles) -> ObserverDetails:
    """Single-output observer gain through the OCF, returning every step (4.46), (4.60).

    This is the notes' method, kept literally for teaching; `place_observer`
    returns the same gain (unique for one output) computed more accurately.
    Like `place_observer`, it checks eig(A - L C) against `poles` and issues an
    `AccuracyWarning` when they miss.
    """
    A, C = as_obs_pair(A, C)
    n = A.shape[0]
    poles = as_poles(poles, "poles", count=n)
    charpoly(A)                           # its coefficients, the OCF's last column, must be floats
    T = ocf_transform(A, C)
    V = np.linalg.inv(T)
    # (4.49): A~ = V^{-1} A V, C~ = C V
    A_ocf, C_ocf = T @ A @ V, C @ V
    a = -A_ocf[:, -1].copy()              # last column of the OCF is -[a_0 ... a_{n-1}]
    p = poly_from_roots(poles)            # desired p(s) of the error dynamics
    L_ocf = (p - a).reshape(n, 1)         # (4.46): l_i = p_{i-1} - a_{i-1}
    L = V @ L_ocf                         # (4.60): L = V L~
    warn_if_missed(PoleMatch(A - L @ C, poles, A), _OBSERVER)
    return ObserverDetails(T=T, V=V, A_ocf=A_ocf, C_ocf=C_ocf, a=a, p=p, L_ocf=L_ocf, L=L)


_OBSERVER = {
    "gain": "L",
    "weak": ("some states show in y (the pair is nearly unobservable, or the poles are huge; see "
             "obsv_singular_values)"),
    "what": "observer poles eig(A - L C) of the estimation error dynamics (4.27)",
    "advice": ("Try fewer or less clustered observer poles, poles closer to the open-loop ones, "
               "or rescale the states and time to similar magnitudes"),
}


def place_observer(A, C, poles) -> np.ndarray:
    """Observer gain L, shape (n, p), with eig(A - L C) = poles.

    The observer is x̂' = A x̂ + B u + L (y - C x̂) (4.25), with error
    dynamics x̃' = (A - L C) x̃ (4.27). The sign convention matches MATLAB's
    ``place(A', C', P)'`` of (4.84) (no minus sign, unlike the state-feedback
    gain of (4.78)).

    Duality (4.82)-(4.84): eig(A - L C) = eig(A^T - C^T L^T), so L^T is a
    state-feedback gain for (A^T, C^T); with the course's u = K x convention,
    ``L = -place(A^T, C^T, poles)^T``, computed by `place`'s methods:

    * One output: the gain is unique and equals the notes' OCF method (4.46),
      (4.60) (`place_observer_details` shows those steps); it is computed as
      the dual of `place`'s single-input method, accurate to about 1e-14
      relative where the OCF route loses digits in its Wo solve.
    * Several outputs: C is compressed to its row rank (two equal rows are
      fine) and the robust method is used, or Heymann's lemma when a pole is
      repeated more than rank(C) times; any observable pair gets any set of
      poles closed under conjugation.

    Self-check: eig(A - L C) is matched to `poles` with `place`'s tolerance
    (1e-6 of the pole scale; a k-fold pole within 1e-6^(1/k) with one output,
    within 1e-6 when it is requested at most twice per independent output), otherwise an
    `AccuracyWarning` gives the largest error and the eigenvector condition
    number of A - L C. As for `place`, some requests (many evenly spread
    poles, n = 20) cannot be met in double precision by any gain.

    Raises `NotObservableError` if (A, C) is not observable and `ValueError`
    for a wrong number of poles or a complex pole without its conjugate.
    """
    A, C = as_obs_pair(A, C)
    poles = as_poles(poles, "poles", count=A.shape[0])
    check_size(A.shape[0], C.shape[0], f"C has {C.shape[0]} rows")
    require_observable(A, C, purpose="placing every pole of the estimation error dynamics")
    # (4.84): L^T = place(A^T, C^T, P) in MATLAB's sign, i.e. L = -K^T in the course's
    K, dual = place_gain(A.T, C.T, poles)
    L = -K.T
    require_finite(L, _OBSERVER)
    # judged on A - L C itself, with the dual's number of independent outputs
    warn_if_missed(PoleMatch(A - L @ C, poles, A, inputs=dual.inputs), _OBSERVER)
    return L
