"""The gain of a pole placement and its self-check, shared by `place` and `place_observer`.

`place_observer` places the poles of A - L C as those of the dual A^T + C^T K (L = -K^T)
with the same `place_gain` (one input: Ackermann's form of (3.46)-(3.47); several: SciPy's
robust method or Heymann's lemma), `PoleMatch` and `warn_if_missed`.
"""

from __future__ import annotations

import warnings

import numpy as np

from ._pairs import balancing
from ._validation import warn_accuracy
from .diagnostics import NotControllableError

__all__ = ["place_gain", "PoleMatch", "warn_if_missed", "require_finite", "check_size"]


# Relative tolerance of the self-check. A backward-stable gain and LAPACK's eigenvalue solver
# each move a closed-loop pole by about n eps ||A + B K|| kappa (kappa: its eigenvector
# condition number), i.e. 1e-13 of the pole scale for the course's systems; 1e-6 leaves seven
# orders of magnitude for ill-conditioning before warning, and a pole that is off by less than
# a millionth of the largest pole is indistinguishable in any plot or simulation of the course.
POLE_RTOL = 1e-6


# The relative perturbation that rounding leaves on a closed loop of the course's sizes (n up to
# 100, eigenvector conditions up to 1e2: 1e3 n eps ~ 1e-11, rounded down): a Jordan chain of
# length L splits a repeated eigenvalue by about its L-th root.
ROUNDING = 1e-12


# The work of the multi-input methods grows fast with n: SciPy's Tits-Yang iteration takes about
# 1.4 s at n = 20 and 8.5 s at n = 50 (it is tried up to _ROBUST_MAX_STATES states, Heymann's
# lemma alone beyond), and the pole placement of more than _MULTI_INPUT_MAX_STATES states with
# several inputs is refused before any work (it took minutes at n = 200, for poles that no
# double-precision gain places anyway).
_ROBUST_MAX_STATES = 40
_MULTI_INPUT_MAX_STATES = 100


def check_size(n: int, m: int, channels: str) -> None:
    """Refuse m > 1 channels with more than _MULTI_INPUT_MAX_STATES states (bounded work).

    `channels` says where m comes from ("B has 3 columns", "C has 3 rows").
    """
    if m > 1 and n > _MULTI_INPUT_MAX_STATES:
        raise ValueError(
            f"A has {n} states: pole placement with several channels ({channels}) is limited "
            f"to {_MULTI_INPUT_MAX_STATES} states, where its work stays "
            "bounded (seconds) and double precision can still place poles; reduce the model "
            "(e.g. balanced truncation) or design the gain by LQR (scipy.linalg.solve_continuous_are; "
            "for an observer, kalman_gain)."
        )


def require_finite(G: np.ndarray, words: dict) -> None:
    """Raise when a gain overflowed: no double-precision gain places these poles."""
    if not np.all(np.isfinite(G)):
        raise ValueError(
            f"the gain {words['gain']} overflows double precision: the requested poles are too far "
            f"from the open-loop ones for how weakly {words['weak']}; choose slower poles."
        )


def place_gain(A: np.ndarray, B: np.ndarray, poles: np.ndarray):
    """K with eig(A + B K) = poles for a controllable (A, B), and its `PoleMatch`."""
    if B.shape[1] == 1:
        K = _single_input(A, B[:, 0], poles)
        return K, PoleMatch(A + B @ K, poles, A)
    r = np.linalg.matrix_rank(B)
    _, _, Vt = np.linalg.svd(B)
    V_r = Vt[:r].T                                   # B V = [B_r, 0]: B_r = B V_r has full rank r
    B_r = B @ V_r if r < B.shape[1] else B
    if r == 1:
        K = V_r @ _single_input(A, B_r[:, 0], poles)
        return K, PoleMatch(A + B @ K, poles, A)
    lift = (lambda K_r: V_r @ K_r) if r < B.shape[1] else (lambda K_r: K_r)
    tried = []
    robust = _robust(A, B_r, poles)
    if robust is not None:
        tried.append((lift(robust), PoleMatch(A + B @ lift(robust), poles, A, inputs=r)))
        if tried[-1][1].ratio <= 1.0:
            return tried[-1]
    try:
        K = lift(_heymann(A, B_r, poles)[0])
        tried.append((K, PoleMatch(A + B @ K, poles, A, inputs=r)))
    except NotControllableError:
        if not tried:
            raise
    return min(tried, key=lambda pair: pair[1].ratio)


def _robust(A: np.ndarray, B_r: np.ndarray, poles: np.ndarray) -> np.ndarray | None:
    """SciPy's Tits-Yang gain in the course's sign, or None where it does not apply."""
    from scipy.signal import place_poles
    if _groups(poles)[1].max() > B_r.shape[1] or A.shape[0] > _ROBUST_MAX_STATES:
        return None                                   # YT places a pole at most rank(B) times
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # "convergence not reached": checked below
            return -np.real(place_poles(A, B_r, poles, method="YT").gain_matrix)
    except (ValueError, np.linalg.LinAlgError):
        return None


def _heymann(A: np.ndarray, B_r: np.ndarray, poles: np.ndarray, tries: int = 6):
    """Heymann's lemma: K = K0 + g k with k placing the poles of (A + B K0, B g).

    For a controllable (A, B) almost every (K0, g) makes (A + B K0, B g)
    controllable, so a few seeded draws suffice; the first whose result
    passes the self-check is returned, else the best one.
    """
    rng = np.random.default_rng(0)                    # seeded: the same K on every call
    n, r = B_r.shape
    d = balancing(A, B_r)
    A_b, B_b = A / d[:, None] * d, B_r / d[:, None]   # balanced pair D^-1 A D, D^-1 B
    size = np.linalg.norm(A_b, 1) / np.linalg.norm(B_b, 1)
    best = None
    for attempt in range(tries):
        g = rng.normal(size=r)
        g /= np.linalg.norm(g)
        K0 = np.zeros((r, n)) if attempt == 0 else size * rng.normal(size=(r, n)) / np.sqrt(n)
        try:
            k = _single_input(A_b + B_b @ K0, B_b @ g, poles)
        except NotControllableError:
            continue
        K = (K0 + np.outer(g, k)) / d                 # back to x: K = K_b D^-1
        match = PoleMatch(A + B_r @ K, poles, A)
        if best is None or match.ratio < best[1].ratio:
            best = (K, match)
        if match.ratio <= 1.0:
            break
    if best is None:
        raise NotControllableError(
            "no input direction g makes (A + B K0, B g) controllable to working precision: "
            "(A, B) is too close to uncontrollable for pole placement; check "
            "ctrb_singular_values(A, B)."
        )
    return best


def _single_input(A: np.ndarray, b: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """The unique k, shape (1, n), with eig(A + b k) = poles (3.46)-(3.47), accurately.

    Ackermann's form of (3.47): k = -e_n^T Wc^{-1} p(A). In balanced
    coordinates (x = D x_b) and controller-Hessenberg form (Q^T b = beta e_1,
    H = Q^T A_b Q upper Hessenberg), Wc(H, beta e_1) is upper triangular with
    last diagonal entry beta h_21 h_32 ... h_n,n-1, so
    k_H = -e_n^T p(H) / (beta prod h_{i+1,i}), and p(H) is applied to e_n^T
    one factor (H - lambda I), or (H^2 - 2 Re(lambda) H + |lambda|^2 I) for
    a conjugate pair, at a time, rescaling as it goes so nothing overflows.
    """
    n = A.shape[0]
    d = balancing(A, b.reshape(n, 1))
    A_b, b_b = A / d[:, None] * d, b / d
    Q1, beta = _householder(b_b)                              # Q1^T b = beta e_1
    from scipy.linalg import hessenberg
    H, Q2 = hessenberg(Q1.T @ A_b @ Q1, calc_q=True)           # Q2 e_1 = e_1
    sub = np.diag(H, -1)
    if beta == 0 or np.any(sub == 0):
        raise NotControllableError(
            "(A, B) is uncontrollable to working precision: its controller-Hessenberg form has a "
            "zero subdiagonal entry, so no gain moves every pole; check ctrb_singular_values(A, B)."
        )
    row, log_size = np.zeros(n), 0.0
    row[-1] = 1.0
    for kind, c1, c2 in _real_factors(poles):
        rH = row @ H
        row = rH - c1 * row if kind == 1 else rH @ H - c1 * rH + c2 * row
        size = np.abs(row).max()
        if not size > 0:         # e_n^T p(H) = 0: the poles are already A's (k = 0)
            return np.zeros((1, n))
        row, log_size = row / size, log_size + np.log(size)
    log_den = np.log(abs(beta)) + np.sum(np.log(np.abs(sub)))
    sign = np.sign(beta) * np.prod(np.sign(sub))
    with np.errstate(over="ignore", invalid="ignore"):    # an overflow is reported by the caller
        k_H = -sign * np.exp(log_size - log_den) * row
        return (k_H @ (Q1 @ Q2).T / d).reshape(1, n)


def _householder(b: np.ndarray):
    """Symmetric orthogonal Q (a reflection) and beta with Q b = Q^T b = beta e_1."""
    norm = np.linalg.norm(b)
    beta = -norm if b[0] >= 0 else norm               # the sign that avoids cancellation
    v = b.copy()
    v[0] -= beta
    vv = v @ v
    Q = np.eye(b.size) if vv == 0 else np.eye(b.size) - (2.0 / vv) * np.outer(v, v)
    return Q, beta


def _real_factors(poles: np.ndarray):
    """Real factors of p(s): (1, lambda, 0) for s - lambda, (2, 2 Re, |lambda|^2) for a pair."""
    scale = max(1.0, float(np.abs(poles).max()))
    real = np.abs(poles.imag) <= 1e-12 * scale       # as_poles' rule for "real"
    factors = [(1, float(p.real), 0.0) for p in poles[real]]
    factors += [(2, 2 * float(p.real), float(abs(p) ** 2)) for p in poles[~real] if p.imag > 0]
    return factors


def _groups(poles: np.ndarray, rtol: float = 1e-9):
    """Label each pole by its group of equal poles (to `rtol`); returns (labels, counts)."""
    close = np.abs(poles[:, None] - poles[None, :]) <= rtol * np.maximum(1.0, np.abs(poles))
    labels = np.argmax(close, axis=1)                 # index of the first pole equal to it
    return labels, np.bincount(labels, minlength=poles.size)


class PoleMatch:
    """eig(M) matched to the requested poles, with the largest error against the tolerance.

    The scale is the largest requested or achieved pole magnitude, or the
    spectral radius of the open loop `A` where that is larger (poles all at
    0, as in a discrete-time deadbeat design, are judged against A's own
    speed); all three are in the units of the poles, whatever the state units.
    A pole requested once must be hit to POLE_RTOL * scale. A pole requested
    k times is a k-fold eigenvalue, which any rounding splits into k
    eigenvalues spread by about (perturbation)^(1/L), L the length of its
    longest Jordan chain: their mean must hit it to POLE_RTOL * scale. With
    one input L = k, and each eigenvalue must lie within POLE_RTOL^(1/k) * scale.
    With `inputs` = r >= 2 independent inputs a gain exists whose chains are
    no longer than L = ceil(k / r); each eigenvalue must then lie within
    max(POLE_RTOL, ROUNDING^(1/L)) * scale, the spread rounding explains for
    such a gain (1e-6 for L <= 2): a gain that makes one long chain (a pole
    requested 3 times with 2 inputs, split by 1e-5) is reported.
    ``ratio`` is the largest error divided by its tolerance (> 1: missed).
    """

    def __init__(self, M: np.ndarray, poles: np.ndarray, A: np.ndarray | None = None, *, inputs: int = 1):
        self.M, self.poles, self.inputs = M, poles, inputs
        if not np.all(np.isfinite(M)):                # an overflowed gain: nothing is placed
            self.achieved = self.errors = np.full(poles.shape, np.inf)
            self.scale, self.ratio = float(np.abs(poles).max()), np.inf
            return
        eig = np.linalg.eigvals(M)
        from scipy.optimize import linear_sum_assignment
        rows, cols = linear_sum_assignment(np.abs(eig[:, None] - poles[None, :]))
        self.achieved = np.empty_like(poles)
        self.achieved[cols] = eig[rows]
        self.errors = np.abs(self.achieved - poles)
        self.scale = max(float(np.abs(poles).max()), float(np.abs(self.achieved).max()))
        self.ratio = self._ratio()
        if self.ratio > 1.0 and A is not None:        # only then is eig(A) worth computing
            own = (self.scale, self.ratio)
            self.scale = max(self.scale, float(np.abs(np.linalg.eigvals(A)).max()))
            self.ratio = self._ratio()
            if 0 < np.abs(poles).max() < self.errors.max():
                # A's speed excuses errors of its own rounding, not a closed loop that misses by more
                # than the poles' size: poles 1e-200 of A's scale, unreachable in double precision
                self.scale, self.ratio = own

    def _ratio(self) -> float:
        if self.scale == 0.0:
            return 0.0                                # every pole 0 and every eigenvalue exactly 0
        labels, counts = _groups(self.poles)
        ratio = self.errors[counts[labels] == 1].max(initial=0.0) / (POLE_RTOL * self.scale)
        for j in np.flatnonzero(counts > 1):
            group, k = labels == j, counts[j]
            mean_error = abs(self.achieved[group].mean() - self.poles[j])
            ratio = max(ratio, mean_error / (POLE_RTOL * self.scale),
                        self.errors[group].max() / (self.spread_tolerance(k) * self.scale))
        return float(ratio) if np.isfinite(ratio) else np.inf

    def spread_tolerance(self, k: int) -> float:
        """How far (relative to the scale) each eigenvalue of a k-fold pole may lie from it."""
        if self.inputs == 1:
            return POLE_RTOL ** (1.0 / k)
        return max(POLE_RTOL, ROUNDING ** (1.0 / -(-k // self.inputs)))

    def eigenvector_condition(self) -> float:
        """cond(V) of M = V diag(eig) V^-1 (unit columns): how sensitive its eigenvalues are."""
        if not np.all(np.isfinite(self.M)):
            return np.inf
        _, V = np.linalg.eig(self.M)
        return float(np.linalg.cond(V))


def warn_if_missed(match: PoleMatch, words: dict, stacklevel: int = 4) -> None:
    """Issue an AccuracyWarning when `match` exceeds its tolerance, saying by how much."""
    if match.ratio <= 1.0:
        return
    i = int(np.argmax(match.errors))
    err, want, got = match.errors[i], match.poles[i], match.achieved[i]
    warn_accuracy(
        f"the {words['what']} miss the requested poles: the largest error is {err:.3g} at the "
        f"requested pole {_fmt(want)} (achieved {_fmt(got)}), {err / match.scale:.2g} relative to "
        f"the pole scale {match.scale:.3g}, above the tolerance {POLE_RTOL:g}. The closed loop's "
        f"eigenvector condition number is {match.eigenvector_condition():.2g}: its eigenvalues "
        "move by about that times the rounding of its entries, so the problem is ill-conditioned "
        f"in double precision.{_chain_note(match)} {words['advice']}.",
        stacklevel=stacklevel,
    )


def _chain_note(match: PoleMatch) -> str:
    """For several inputs: the pole requested more often than there are inputs, and what to do."""
    labels, counts = _groups(match.poles)
    j = int(np.argmax(counts))
    if match.inputs == 1 or counts[j] <= match.inputs:
        return ""
    return (f" The pole {_fmt(match.poles[j])} is requested {counts[j]} times with {match.inputs} "
            f"independent inputs (outputs): this gain makes it one Jordan chain, whose eigenvalues "
            f"rounding splits by about eps^(1/{counts[j]}), more than the tolerance "
            f"{match.spread_tolerance(int(counts[j])):.2g} of a gain with chains of length "
            f"{-(-int(counts[j]) // match.inputs)}; if the exact repetition is not needed, spread "
            "the poles slightly (e.g. -1, -1.01, -0.99).")


def _fmt(z: complex) -> str:
    """Enough digits to tell an achieved pole from the requested one."""
    return f"{z.real:.10g}" if z.imag == 0 else f"{z.real:.10g}{z.imag:+.10g}j"
