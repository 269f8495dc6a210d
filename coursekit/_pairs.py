"""The pair helpers of controllability and observability: checks, staircase, canonical transform.

Observability works on the dual pair (A^T, C^T) with the same tools, and `place`, the
trajectories and the flatness helpers check their pairs here too.

Why the verdict is not ``matrix_rank(ctrb(A, B))``
--------------------------------------------------
In exact arithmetic rank Wc = n is the whole story (2.13). In floating point
the columns A^k B of Wc grow or shrink like |lambda|^k: a DC motor in SI
units has eigenvalues 0, -1.3 and -1.45e6 rad/s, so the last column of Wc is
1e12 times the first, and any rank rule (NumPy's counts singular values
above ``max(shape) * eps * s_max``) drowns the small columns in the rounding
of the large ones. Changing the time unit (A -> a A, B -> a B) multiplies
column k by a^(k+1), and changing state units (x -> D x) rescales the rows,
so the numerical rank of Wc, unlike the true one, depends on the units.

coursekit decides instead with quantities that units do not change
(`unit_free_staircase`):

1. *units*: A is divided by its norm (this removes the time unit exactly:
   a A / |a A| = A / |A|) and each column of B by its norm (input units);
2. *state units*: the states are scaled by powers of two (exact), first to
   balance the matrix [[A, B], [0, 0]] (LAPACK's balancing, as in
   `scipy.linalg.matrix_balance`), giving states that no other state
   depends on (a motor's position), which balancing cannot reach, rows of
   size 1, then so that every row of Wc = [B, AB, ...] has norm 1, with Wc
   formed for A over its spectral radius (the time unit in which the
   system's own rates are 1). Scaling state i scales row i of Wc and nothing
   else, so this last step gives the same states whatever units they came
   in (Wc serves for its row norms only, never for a rank); the first steps
   only bring A to a size where Wc can be formed. Then step 1 is repeated;
3. *staircase*: orthogonal transformations (SVDs) bring the pair to the
   controllability staircase form: the first block is the range of B, and
   each further block is the part of A times the previous block that is
   new. The singular values of these coupling blocks (each at most 1 after
   step 1) are the "strength" with which the input reaches each further
   block; (A, B) is controllable exactly when n directions are reached.
   Orthogonal steps do not amplify rounding errors, and no power of A is
   ever formed, so no column grows like |lambda|^k.

A coupling counts as nonzero when it exceeds ``tol * min(1/c_min, 1e3)``,
``tol = 100 n^2 eps`` by default and ``c_min`` the smallest coupling kept so
far: rounding errors of size eps in A move the reached subspace by about
eps / c_min, which shows up as a spurious coupling of that size. (The cap
1e3 keeps genuinely weak but structural couplings, such as those of a
balanced companion matrix with roots -1..-30, above the tolerance.) With
these settings (measured on thousands of random cases): exactly
uncontrollable systems (Kalman decomposition [[A11, A12], [0, A22]],
[B1; 0]) transformed by random orthogonal matrices and diagonal scalings
1e-4..1e4 are refused, their largest spurious coupling staying below 0.1
times its tolerance; random N(0, 1) systems up to n = 30 in any units
1e-4..1e4 are accepted with margins above 1e4; the SI systems of the tests
(a DC motor, a cart-pendulum, a building, ...) keep their verdicts in any
units (margin = smallest coupling / its tolerance; below 100 a verdict is
called marginal in the error messages).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import as_matrix, as_square, require_columns, warn_accuracy
from .diagnostics import NotControllableError

__all__ = ["as_pair", "as_obs_pair", "ctrb_unchecked", "Staircase", "unit_free_staircase",
           "check_tol", "marginal_note", "balancing", "require_controllable", "canonical_transform"]


_EPS = np.finfo(float).eps
# a decision whose margin (coupling / tolerance, or its inverse) is below this is called marginal
_MARGINAL = 100.0
# the tolerance grows with 1 / (smallest coupling so far), up to this factor (module docstring)
_AMPLIFICATION_CAP = 1e3


def as_pair(A, B):
    """(A, B) checked: A square (n, n), B with n rows (a 1-D B is one column) and at least one column."""
    A = as_square(A, "A")
    n = A.shape[0]
    B = as_matrix(B, "B", rows=n, rows_why=f"one per state, since A is {n}x{n}",
                  cols=1 if np.ndim(B) == 1 else None)
    require_columns(B.shape, "B")
    return A, B


def ctrb_unchecked(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Wc = [B, AB, ..., A^(n-1) B] (2.13) for arrays already checked by `as_pair`."""
    blocks = [B]
    for _ in range(A.shape[0] - 1):
        blocks.append(A @ blocks[-1])
    return np.hstack(blocks)


@dataclass(frozen=True)
class Staircase:
    """The outcome of `unit_free_staircase`, in the unit-free coordinates it works in.

    The scaled pair is ``A_s = D^-1 A D / alpha``, ``B_s = D^-1 B / beta``
    (``d`` the diagonal of D, ``beta`` one factor per input). ``Q`` is
    orthogonal; its first ``rank`` columns span the controllable subspace of
    (A_s, B_s). ``margin`` is the smallest kept coupling over its tolerance
    (inf when none was kept), ``excess`` the largest coupling set to zero
    over its tolerance (0 when none was).
    """

    rank: int
    A_s: np.ndarray
    B_s: np.ndarray
    d: np.ndarray
    alpha: float
    beta: np.ndarray
    Q: np.ndarray
    margin: float
    excess: float

    @property
    def marginal(self) -> bool:
        return self.margin < _MARGINAL or self.excess > 1 / _MARGINAL


def _norms(M: np.ndarray, axis: int | None = None):
    """2-norm of M (Frobenius, axis=None) or of its columns (axis=0), safe from overflow."""
    m = np.abs(M).max(axis=axis, keepdims=True, initial=0.0)
    safe = np.where(m > 0, m, 1.0)
    norms = np.linalg.norm(M / safe, axis=axis, keepdims=True) * m
    return norms.item() if axis is None else norms.reshape(-1)


def _normalize(A: np.ndarray, B: np.ndarray):
    """A / |A|_F and each column of B over its norm (a zero column stays zero)."""
    a = _norms(A)
    a = a if a > 0 else 1.0
    b = _norms(B, axis=0)
    b[b == 0] = 1.0
    return A / a, B / b, a, b


def _scale_states(A: np.ndarray, B: np.ndarray, s: np.ndarray):
    """The pair in the states x / s: (S^-1 A S, S^-1 B)."""
    return A / s[:, None] * s[None, :], B / s[:, None]


def balancing(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """State scaling (powers of two) that balances [[A, B], [0, 0]] (LAPACK gebal, job 'S')."""
    from scipy.linalg import get_lapack_funcs

    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    gebal = get_lapack_funcs("gebal", (M,))
    # M_bal = S^-1 M S; without permutations, ps holds the diagonal of S
    _, _, _, s, _ = gebal(M, scale=1, permute=0)
    return s[:n]


def _sink_scaling(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """State scaling (powers of two) for the states no other state depends on.

    Balancing leaves such a state (its column of A is zero off the diagonal,
    e.g. the position of a motor) in whatever unit it came in, since
    nothing balances its row. Its unit is free, so it is chosen to make its
    row (A off the diagonal, and B) of norm about 1, like the rest.
    """
    off = A - np.diag(np.diag(A))
    rows = np.hypot(np.linalg.norm(off, axis=1), np.linalg.norm(B, axis=1))
    sink = ~off.any(axis=0) & (rows > 0)
    s = np.ones(A.shape[0])
    s[sink] = 2.0 ** np.round(np.log2(rows[sink]))
    return s


def _krylov_scaling(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """State scaling (powers of two) that equilibrates the rows of Wc = [B, AB, ...].

    Row i of Wc says how strongly the input reaches state i; scaling x_i
    scales that row and nothing else, so dividing each row by its norm gives
    the same result whatever unit x_i came in. A zero row (a state never
    reached) keeps its unit. Wc is formed for A over its spectral radius
    rho (the time unit in which the system's own rates are 1; rho does not
    depend on state units), floored at 1e-4 of |A| = 1 for (nearly)
    nilpotent A, so that Wc neither overflows nor underflows.
    """
    rho = np.abs(np.linalg.eigvals(A)).max(initial=0.0)
    W = ctrb_unchecked(A / max(rho, 1e-4), B)
    rows = np.linalg.norm(W, axis=1)
    s = np.ones(A.shape[0])
    reached = (rows > 0) & np.isfinite(rows)
    s[reached] = 2.0 ** np.round(np.log2(rows[reached]))
    return s


def _unit_free(A: np.ndarray, B: np.ndarray):
    """Steps 1-2 of the module docstring: remove time, input and state units.

    Returns (A_s, B_s, d, alpha, beta) with A_s = D^-1 A D / alpha and
    B_s = D^-1 B / beta, where |A_s|_F = 1 and the columns of B_s have norm 1.
    """
    A, B, alpha, beta = _normalize(A, B)
    d = np.ones(A.shape[0])
    for scaling in (balancing, _sink_scaling, balancing, _krylov_scaling):
        s = scaling(A, B)
        A, B = _scale_states(A, B, s)
        A, B, a, b = _normalize(A, B)
        d, alpha, beta = d * s, alpha * a, beta * b
    return A, B, d, alpha, beta


def unit_free_staircase(A: np.ndarray, B: np.ndarray, tol: float | None = None) -> Staircase:
    """Step 3 of the module docstring: the orthogonal staircase of the unit-free pair."""
    A_s, B_s, d, alpha, beta = _unit_free(A, B)
    n = A.shape[0]
    tol = 100 * n * n * _EPS if tol is None else tol
    Q = np.eye(n)
    k, Ak, Bk = 0, A_s, B_s           # Bk couples what is reached to the n - k states left
    c_min, margin, excess = 1.0, np.inf, 0.0
    while k < n:
        U, s, _ = np.linalg.svd(Bk)
        tol_k = tol * min(1.0 / c_min, _AMPLIFICATION_CAP)
        r = int(np.sum(s > tol_k))
        if r < s.size:
            excess = max(excess, s[r] / tol_k)
        if r == 0:
            break
        margin, c_min = min(margin, s[r - 1] / tol_k), min(c_min, s[r - 1])
        # new coordinates: the first r directions of U are reached at this step
        Ak = U.T @ Ak @ U
        Q[:, k:] = Q[:, k:] @ U
        k += r
        Bk, Ak = Ak[r:, :r], Ak[r:, r:]
    return Staircase(rank=k, A_s=A_s, B_s=B_s, d=d, alpha=alpha, beta=beta, Q=Q,
                     margin=margin, excess=excess)


def check_tol(tol):
    """`tol` of `is_controllable` / `is_observable` checked: None (the default) or a number in (0, 1)."""
    if tol is None:
        return None
    if not isinstance(tol, (int, float, np.integer, np.floating)) or not 0 < float(tol) < 1:
        raise ValueError(
            f"tol must be a number between 0 and 1: received {tol!r}. It is relative to the "
            "unit-free system (A and the columns of B scaled to norm 1); leave it out for the "
            "default 100 n^2 eps."
        )
    return float(tol)


def marginal_note(v: Staircase, verdict: str) -> str:
    """The sentence an error message adds when the staircase verdict `v` is marginal, else ""."""
    if not v.marginal:
        return ""
    return (
        f" This verdict is marginal (smallest coupling kept: {v.margin:.3g} x its tolerance; "
        f"largest set to zero: {v.excess:.3g} x its tolerance), so the system is {verdict}: "
        "small changes of the parameters can change the verdict. Check the model's parameter "
        "values, and try is_controllable(A, B, tol=...) with a smaller or larger tol."
    )


def require_controllable(A: np.ndarray, B: np.ndarray, *, purpose: str,
                         tol: float | None = None) -> Staircase:
    """Return the staircase of (A, B), or raise NotControllableError saying what failed.

    The verdict is `is_controllable`'s; the message says how many
    directions cannot be reached, what to do, and whether the decision was
    marginal (the system close to the boundary between the two verdicts).
    """
    v = unit_free_staircase(A, B, check_tol(tol))
    n, r = A.shape[0], v.rank
    if r < n:
        raise NotControllableError(
            f"(A, B) is not controllable, so {purpose} is impossible: the controllability "
            f"matrix Wc = [B, AB, ..., A^{n - 1} B] (2.13) has rank {r} < n = {n} (decided "
            "without units by an orthogonal staircase of the balanced pair; see "
            f"is_controllable). {n - r} direction(s) of the state cannot be influenced by u: "
            "add an actuator (a column of B) that acts on them, or check the entries of A "
            "and B." + marginal_note(v, "nearly controllable")
        )
    return v


def _ccf_rows(v: Staircase) -> np.ndarray:
    """The CCF transform of the unit-free single-input pair (A_s, b_s) of `v`.

    Its first row is orthogonal to b_s, A_s b_s, ..., A_s^(n-2) b_s, i.e. it
    is the last staircase direction Q[:, -1], scaled so that
    T_1 A_s^(n-1) b_s = 1: the row e_n^T Wc^{-1} of (2.65) without forming Wc.
    """
    n = v.Q.shape[0]
    Ts = np.empty((n, n))
    Ts[0] = v.Q[:, -1]
    for i in range(1, n):
        # (2.61): T_{i+1} = T_i A
        Ts[i] = Ts[i - 1] @ v.A_s
    # (2.64)-(2.65): T_n B = T_1 A^(n-1) B = 1
    return Ts / (Ts[-1] @ v.B_s[:, 0])


def _ccf_deviation(Ts: np.ndarray, v: Staircase) -> tuple[float, float]:
    """How far Ts misses the CCF, as a multiple of what rounding explains, and absolutely.

    Checks ``T B = e_n`` (each row against ``|T_i| |B|``, 2-norms) and that rows
    1..n-1 of ``T A T^-1`` are e_{i+1}^T (relative to the size of its last
    row), in the unit-free coordinates, where neither check depends on
    units. Rounding explains a miss of up to ``100 n eps cond(T)``: the
    orthogonality of T_1 to B, AB, ... holds to about eps over the smallest
    staircase coupling, and T^-1 amplifies that by cond(T). (On random
    systems, n = 2..30, also in units scaled by 1e-4..1e4, and on the SI
    systems of the tests in random units, the misses stay below 1/100 of
    this.)
    """
    n = Ts.shape[0]
    b = v.B_s[:, 0]
    # row by row against |T_i| |B| (2-norms: T_i B = 0 may be a cancellation of rounding-level
    # entries of T_i); |B| = 1 here, and no row of T is zero
    miss_B = np.max(np.abs(Ts @ b - np.eye(n)[-1]) / np.linalg.norm(Ts, axis=1))
    Ac = np.linalg.solve(Ts.T, (Ts @ v.A_s).T).T          # T A T^-1
    miss_A = np.abs(Ac[:-1] - np.eye(n, k=1)[:-1]).max(initial=0.0) / (1.0 + np.abs(Ac[-1]).max())
    miss = max(miss_B, miss_A)
    return miss / (100 * n * _EPS * np.linalg.cond(Ts)), miss


def canonical_transform(A: np.ndarray, B: np.ndarray, *, form: str, purpose: str,
                        equations: str = "T B = e_n and the structure of T A T^-1",
                        require=None) -> np.ndarray:
    """T with z = T x in the CCF of (A, B), checked; `form` and `equations` name it in the warning."""
    require = require or require_controllable
    v = require(A, B, purpose=purpose)
    n = A.shape[0]
    with np.errstate(all="ignore"):   # rows that leave the float range are refused below
        Ts = _ccf_rows(v)
        # back to the user's units: T_i = T_s,i D^-1 alpha^(i-n) / beta (z_i is z_1's (i-1)-th derivative)
        powers = v.alpha ** (np.arange(1, n + 1) - n)
        T = Ts / v.d[None, :] * powers[:, None] / v.beta[0]
    if not (np.isfinite(Ts).all() and np.isfinite(T).all()):
        raise ValueError(
            f"A has no {form} in double precision: the rows T_(i+1) = T_i A (2.61) of the transform "
            f"grow like the powers of A and leave the float range over its n = {n} states. Work "
            "without the canonical form (place and place_observer need none), or with fewer states."
        )
    with np.errstate(all="ignore"):   # norms of rows that are huge but finite: inf, a miss
        ratio, miss = _ccf_deviation(Ts, v)
        condition = np.linalg.cond(Ts)
    if ratio > 1 or not miss <= _CCF_MISS:
        warn_accuracy(
            f"the transform to the {form} misses its defining equations ({equations}) "
            f"by {miss:.2g} (relative), " + (
                f"{ratio:.2g} times more than the rounding of an ill-conditioned T explains: T is "
                "inaccurate, and so may be gains or trajectories computed from it. Check them (e.g. "
                "the eigenvalues of A + B K), and check whether the system is nearly uncontrollable: "
                "is_controllable(A, B, tol=1e-8) False means its input barely reaches some states."
                if ratio > 1 else
                f"more than {_CCF_MISS:g}: T has condition number {condition:.2g} (in balanced "
                f"units), so the canonical form of this {n}-state system cannot be computed in double "
                "precision by any method (its coefficients span too many orders of magnitude). Work "
                "without it (place and place_observer need none), or with fewer states."),
            stacklevel=4,
        )
    return T


# a canonical transform that misses its equations by more than a hundredth (relative) is reported
# even where its condition number explains the miss: it is no canonical form any more. (Random
# systems: below 1e-4 up to n = 12, median 1e-1 at n = 18 and 1e13 at n = 30; the checks of the
# gains and plans built on T judge their own accuracy below that.)
_CCF_MISS = 1e-2


def as_obs_pair(A, C):
    """Validate (A, C): A square (n, n), C of shape (p, n); a 1-D C is one row."""
    A = as_square(A, "A")
    n = A.shape[0]
    C = as_matrix(C, "C", cols=n, cols_why=f"one per state, since A is {n}x{n}",
                  rows=1 if np.ndim(C) == 1 else None)
    if C.shape[0] == 0:
        raise ValueError("C has no rows: the system has no measurement to estimate the state from.")
    return A, C
