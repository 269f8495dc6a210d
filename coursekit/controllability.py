"""Controllability (section 2.2) and the controllability canonical form (2.4).

* `ctrb(A, B)` builds Wc = [B, AB, ..., A^(n-1) B] (2.13);
* `is_controllable(A, B)` is Kalman's criterion, rank Wc = n, decided with
  singular values (a determinant only exists for one input and says nothing
  about *how close* to singular Wc is);
* `charpoly(A)` returns the coefficients a_0..a_{n-1} of det(sI - A), in the
  notes' ascending order;
* `ccf_transform(A, B)` returns T with z = T x in CCF (2.59)-(2.65);
* `similarity_transform(sys, T)` applies z = T x to a StateSpace (2.50).
"""

from __future__ import annotations

import numpy as np

from ._validation import as_matrix, as_square
from .systems import StateSpace

__all__ = [
    "NotControllableError",
    "ctrb",
    "ctrb_singular_values",
    "is_controllable",
    "charpoly",
    "ccf_transform",
    "similarity_transform",
]


class NotControllableError(ValueError):
    """Raised when an algorithm needs a controllable pair (A, B) and it is not."""


def _pair(A, B):
    A = as_square(A, "A")
    n = A.shape[0]
    B = as_matrix(B, "B", rows=n, rows_why=f"one per state, since A is {n}x{n}",
                  cols=1 if np.ndim(B) == 1 else None)
    if B.shape[1] == 0:
        raise ValueError("B has no columns: the system has no input to control it with.")
    return A, B


def _ctrb(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    blocks = [B]
    for _ in range(A.shape[0] - 1):
        blocks.append(A @ blocks[-1])
    return np.hstack(blocks)


def ctrb(A, B) -> np.ndarray:
    """Controllability matrix Wc = [B, AB, A^2 B, ..., A^(n-1) B] (2.13), shape (n, n m)."""
    A, B = _pair(A, B)
    return _ctrb(A, B)


def ctrb_singular_values(A, B) -> np.ndarray:
    """Singular values of Wc, largest first: the smallest says how close to uncontrollable."""
    return np.linalg.svd(ctrb(A, B), compute_uv=False)


def _rank(W: np.ndarray, tol: float | None) -> int:
    s = np.linalg.svd(W, compute_uv=False)
    if tol is None:
        tol = max(W.shape) * np.finfo(float).eps * (s[0] if s.size else 0.0)
    return int(np.sum(s > tol))


def is_controllable(A, B, *, tol: float | None = None) -> bool:
    """Kalman's criterion (section 2.2.3): rank Wc = n.

    The rank counts singular values of Wc above `tol` (default: NumPy's
    ``matrix_rank`` rule, ``max(shape) * eps * largest singular value``).
    """
    A, B = _pair(A, B)
    return _rank(_ctrb(A, B), tol) == A.shape[0]


def require_controllable(A: np.ndarray, B: np.ndarray, *, purpose: str) -> np.ndarray:
    """Return Wc, or raise NotControllableError explaining what failed and why it matters."""
    W = _ctrb(A, B)
    r = _rank(W, None)
    n = A.shape[0]
    if r < n:
        raise NotControllableError(
            f"(A, B) is not controllable, so {purpose} is impossible: the controllability "
            f"matrix Wc = [B, AB, ..., A^{n - 1} B] (2.13) has rank {r} < n = {n}. "
            f"{n - r} direction(s) of the state cannot be influenced by u; check B and A "
            "(e.g. with is_controllable and ctrb_singular_values)."
        )
    return W


def charpoly(A) -> np.ndarray:
    """Characteristic polynomial det(sI - A) = s^n + a_{n-1} s^(n-1) + ... + a_0.

    Returns the ascending coefficients ``[a_0, ..., a_{n-1}]`` (the leading 1
    is left out), the notes' order in (1.53) and (3.39).
    """
    A = as_square(A, "A")
    return np.real(np.poly(A))[::-1][:-1].copy()


def ccf_transform(A, B) -> np.ndarray:
    """Transform T such that z = T x puts (A, B) in controllability canonical form.

    Implements (2.59)-(2.65): the first row is ``T_1 = e_n^T Wc^{-1}`` and the
    others follow from ``T_{i+1} = T_i A``. Then ``T A T^{-1}`` has ones on
    the superdiagonal and last row ``-[a_0 ... a_{n-1}]``, and ``T B = e_n``.

    Single input only (B of shape (n, 1)). Raises `NotControllableError` when
    Wc is singular: an uncontrollable system has no CCF.
    """
    A, B = _pair(A, B)
    n, m = B.shape
    if m != 1:
        raise ValueError(
            f"B must have a single column for the CCF: received shape {B.shape}; "
            "the CCF (2.16) is defined for one input. Pick one column of B, or use place() "
            "which handles several inputs."
        )
    W = require_controllable(A, B, purpose="a transform to the controllability canonical form")
    e_n = np.zeros(n)
    e_n[-1] = 1.0
    # (2.64)-(2.65): T_1 Wc = e_n^T, solved without forming Wc^{-1}
    T = np.empty((n, n))
    T[0] = np.linalg.solve(W.T, e_n)
    # (2.61): T_{i+1} = T_i A
    for i in range(1, n):
        T[i] = T[i - 1] @ A
    return T


def similarity_transform(sys: StateSpace, T) -> StateSpace:
    """Change of coordinates z = T x (2.50): returns (T A T^-1, T B, C T^-1, D)."""
    if not isinstance(sys, StateSpace):
        raise ValueError(f"sys must be a StateSpace: received {type(sys).__name__}.")
    T = as_square(T, "T", size=sys.n)
    if np.linalg.cond(T) > 1 / np.finfo(float).eps:
        raise ValueError("T is singular: a change of coordinates z = T x needs an invertible T.")
    Tinv = np.linalg.inv(T)
    return StateSpace(T @ sys.A @ Tinv, T @ sys.B, sys.C @ Tinv, sys.D, dt=sys.dt, name=sys.name)
