"""Controllability (section 2.2) and the controllability canonical form (2.4).

* `ctrb(A, B)` builds Wc = [B, AB, ..., A^(n-1) B] (2.13), as the notes teach;
* `is_controllable(A, B)` decides Kalman's criterion, rank Wc = n, in a way
  that does not depend on the units of time, states or inputs (see below);
* `charpoly(A)` returns the coefficients a_0..a_{n-1} of det(sI - A), in the
  notes' ascending order;
* `ccf_transform(A, B)` returns T with z = T x in CCF (2.59)-(2.65);
* `similarity_transform(sys, T)` applies z = T x to a StateSpace (2.50).

Why the verdict is not ``matrix_rank(ctrb(A, B))`` is said in `_pairs`, which decides it.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._pairs import as_pair, canonical_transform, check_tol, ctrb_unchecked, unit_free_staircase
from ._validation import as_square, warn_accuracy
from .systems import StateSpace

__all__ = ["ctrb", "ctrb_singular_values", "is_controllable", "charpoly", "ccf_transform", "similarity_transform"]


def ctrb(A, B) -> np.ndarray:
    """Controllability matrix Wc = [B, AB, A^2 B, ..., A^(n-1) B] (2.13), shape (n, n m).

    This is the matrix of Kalman's criterion as the notes teach it. Its numerical rank depends
    on units (`coursekit._pairs` says why): decide with `is_controllable`, not with its rank.
    """
    A, B = as_pair(A, B)
    return ctrb_unchecked(A, B)


def ctrb_singular_values(A, B) -> np.ndarray:
    """Singular values of Wc, largest first.

    In well-scaled units the smallest says how close to uncontrollable the pair is; they
    change with the units (`coursekit._pairs` says why).
    """
    return np.linalg.svd(ctrb(A, B), compute_uv=False)


def is_controllable(A, B, *, tol: float | None = None) -> bool:
    """Kalman's criterion (section 2.2.3), rank Wc = n (2.13), decided without units.

    Returns the same answer for (A, B) in any time unit (A -> a A, B -> a B), any state units
    (x -> D x, D diagonal), any input units and any orthogonal change of coordinates, up to
    scalings far beyond 1e-4..1e4; `coursekit._pairs` explains the method (balancing +
    orthogonal staircase) and why ``matrix_rank(ctrb(A, B))`` cannot promise this.

    `tol` (between 0 and 1, default ``100 n^2 eps``) is the smallest coupling counted as nonzero
    in the unit-free system, where A and the columns of B have norm 1: a larger `tol` calls
    more nearly uncontrollable systems uncontrollable. A few milliseconds for n = 30.
    """
    A, B = as_pair(A, B)
    return unit_free_staircase(A, B, check_tol(tol)).rank == A.shape[0]


def charpoly(A) -> np.ndarray:
    """Characteristic polynomial det(sI - A) = s^n + a_{n-1} s^(n-1) + ... + a_0.

    Returns the ascending coefficients ``[a_0, ..., a_{n-1}]`` (the leading 1
    is left out), the notes' order in (1.53) and (3.39). Coefficients beyond
    the float range (a_0 = (-1)^n det A of an A scaled by 1e200) raise a
    ValueError naming A; the CCF methods (`place_details`,
    `place_observer_details`, `linear_flatness`) check this first.
    """
    A = as_square(A, "A")
    with np.errstate(over="ignore", invalid="ignore"):
        a = np.real(np.poly(A))[::-1][:-1].copy()
    if not np.isfinite(a).all():
        rho = float(np.abs(np.linalg.eigvals(A)).max())
        raise ValueError(
            f"A is too large for its characteristic polynomial det(sI - A) (1.53): its eigenvalues "
            f"reach {rho:.3g}, and the coefficients a_k, sums of products of n - k of them "
            f"(a_0 = (-1)^n det A), leave the float range (about 1.8e308). Express time in slower "
            "units (the entries of A are rates, 1/time) so that they are nearer 1."
        )
    return a


def ccf_transform(A, B) -> np.ndarray:
    """Transform T such that z = T x puts (A, B) in controllability canonical form.

    Implements (2.59)-(2.65): the first row is ``T_1 = e_n^T Wc^{-1}`` and the
    others follow from ``T_{i+1} = T_i A``. Then ``T A T^{-1}`` has ones on
    the superdiagonal and last row ``-[a_0 ... a_{n-1}]``, and ``T B = e_n``.

    T_1 is computed without Wc: it is the row orthogonal to B, AB, ...,
    A^(n-2) B, which the staircase of `is_controllable` already provides (the
    last direction it reaches), normalized so that T_1 A^(n-1) B = 1. This is
    done in the unit-free coordinates of `is_controllable` and mapped back,
    so badly scaled but controllable systems (a DC motor in SI units) get
    their transform. The result is checked: an `AccuracyWarning` says by how
    much T B misses e_n or T A T^-1 misses the CCF when that is more than
    rounding explains.

    Single input only (B of shape (n, 1)). Raises `NotControllableError` when
    (A, B) is not controllable: an uncontrollable system has no CCF.
    """
    A, B = as_pair(A, B)
    n, m = B.shape
    if m != 1:
        raise ValueError(
            f"B must have a single column for the CCF: received shape {B.shape}; "
            "the CCF (2.16) is defined for one input. Pick one column of B, or use place() "
            "which handles several inputs."
        )
    return canonical_transform(A, B, form="controllability canonical form (2.16)",
                               purpose="a transform to the controllability canonical form")


# cond(T) eps above 2e-6 (a millionth, as the checks of the pole placement): the transform warns
_T_COND_WARN = 1e10


def similarity_transform(sys: StateSpace, T) -> StateSpace:
    """Change of coordinates z = T x (2.50): returns (T A T^-1, T B, C T^-1, D).

    A singular T raises ValueError; a nearly singular one (condition number above 1e10,
    errors above about 2e-6 of the matrices' size) gives an `AccuracyWarning`.
    """
    sys = as_system(sys, kind="linear", hint="build one with StateSpace(A, B, C, D).")
    T = as_square(T, "T", size=sys.n)
    condition = np.linalg.cond(T)
    if condition > 1 / np.finfo(float).eps:
        raise ValueError("T is singular: a change of coordinates z = T x needs an invertible T.")
    if condition > _T_COND_WARN:
        warn_accuracy(
            f"similarity_transform: T is nearly singular (condition number {condition:.2g}): T A T^-1 and "
            f"C T^-1 carry errors of about {condition * np.finfo(float).eps:.1g} relative to their "
            "size, so the new matrices are only approximately similar to the old ones. Choose "
            "a better conditioned T (e.g. columns of similar length, not nearly parallel)."
        )
    Tinv = np.linalg.inv(T)
    return StateSpace(T @ sys.A @ Tinv, T @ sys.B, sys.C @ Tinv, sys.D, dt=sys.dt, name=sys.name)
