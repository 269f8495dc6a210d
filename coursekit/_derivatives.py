"""The derivative engine of `linearize`, `simulate`'s implicit solvers and the EKF (notes 3.65, 3.80).

`numerical_jacobian(g, z)`: central differences over a ladder of steps refined by Richardson
extrapolation, the most accurate one chosen by its error estimate (Ridders' method), exact to
rounding along directions in which g is affine; `checked_jacobian` adds `linearize`'s explanations.
`perturbed_states` and `difference_quotients` give the unrefined quotients from one batch call.
"""

from __future__ import annotations

from functools import cache
from typing import Callable

import numpy as np

from ._validation import warn_accuracy

__all__ = ["numerical_jacobian", "checked_jacobian", "perturbed_states", "difference_quotients"]


def _central(g: Callable, z: np.ndarray, h: np.ndarray, k: int) -> np.ndarray:
    """(g(z + h_k e_k) - g(z - h_k e_k)) / (2 h_k): one column of the Jacobian."""
    step = np.zeros_like(z)
    step[k] = h[k]
    return (g(z + step) - g(z - step)) / (2 * h[k])


_EPS = float(np.finfo(float).eps)
_CBRT_EPS = float(np.cbrt(_EPS))


def _filter_steps(z: np.ndarray) -> np.ndarray:
    """The steps h_k ~ eps^(1/3) max(1, |z_k|) of the unrefined central difference."""
    return _CBRT_EPS * np.maximum(1.0, np.abs(z))


@cache
def _signs(n: int) -> np.ndarray:
    """[I, -I, 0], shape (n, 2n + 1), read-only: the pattern of `perturbed_states`."""
    E = np.hstack([np.eye(n), -np.eye(n), np.zeros((n, 1))])
    E.flags.writeable = False
    return E


def perturbed_states(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(Z, h): the states of the unrefined central difference as the columns of Z (n, 2n + 1).

    Column k is z + h_k e_k, column n + k is z - h_k e_k (the numbers
    `numerical_jacobian(g, z, refine=False)` evaluates g at, one call each) and the
    last column is z itself; h = `_filter_steps(z)`.
    """
    h = _filter_steps(z)
    return z[:, None] + _signs(z.size) * h[:, None], h


def difference_quotients(G: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The Jacobian (q, n) from G (q, 2n + 1), g evaluated on the columns of `perturbed_states`.

    Column k is (g(z + h_k e_k) - g(z - h_k e_k)) / (2 h_k), as in `numerical_jacobian(g,
    z, refine=False)`, from one call of g on a batch instead of 2n calls.
    """
    n = h.size
    return (G[:, :n] - G[:, n:2 * n]) / (2 * h)


# Ridders' ladder: steps h_j = h_0 / 2^j, j < _LADDER, down to ~1e-9 h_0, at most _TABLEAU
# Richardson columns (error terms h^2 ... h^12 removed). The absolute ladder starts at
# h_0 = 1/4 whatever |z_k| is (sin(x) at x = 2 pi 1000 needs steps below ~1); for |z_k| >
# _RELATIVE a second ladder from |z_k| / 4 is tried too (polynomials and exponentials of
# large arguments, where a step relative to |z_k| is right) and kept only when it agrees
# with the first: large steps can fake convergence on oscillating functions (for sin, the
# quotients at h = 1024, 2048, 4096 differ by factors cos(h) that happen to be near 1).
_LADDER = 30
_TABLEAU = 6
_ABSOLUTE_TOP = 0.25
_RELATIVE = 16.0


# the second absolute ladder's top step, in units of the first's: the golden ratio's inverse,
# the number farthest from every fraction, so that no period of an oscillating f divides the
# steps of both ladders (with 0.6 = 3/5 a sine of period 0.25/2400 fooled both alike)
_OTHER = (np.sqrt(5.0) - 1.0) / 2.0


def _probe(g: Callable, z: np.ndarray):
    """g(z) as a flat float array, or None where g raises.

    The large steps of the ladder may leave the function's domain (a square
    root, a logarithm): such steps are skipped (as are NaN/inf values, in
    `_quotient_ladder`); `_checked_jacobian` reports the error when no step
    is usable.
    """
    try:
        return np.ravel(np.asarray(g(z), dtype=float))
    except Exception:  # the user's function outside its domain: this step is not usable
        return None


def _quotient_ladder(g: Callable, z: np.ndarray, k: int, q: int,
                     h0: float) -> tuple[np.ndarray, np.ndarray]:
    """(D, noise): central differences along e_k for the steps h0 / 2^j and their rounding errors.

    D has shape (_LADDER, q), NaN where a step is unusable. noise[j] bounds the
    rounding in row j: eps (|g(z + h e_k)| + |g(z - h e_k)| + |z_k| |D_j|) / 2h,
    the values' own rounding and that of an argument of size |z_k| inside g
    (a model computing x / 1000 or x - 2 pi sees x only to eps |x|).
    """
    G = np.full((2, _LADDER, q), np.nan)
    width = np.ones(_LADDER)
    with np.errstate(all="ignore"):
        for j in range(_LADDER):
            plus, minus = z.copy(), z.copy()
            plus[k] += h0 / 2**j
            minus[k] -= h0 / 2**j
            # the step actually taken: z_k + h is rounded, so use the difference of the arguments
            width[j] = plus[k] - minus[k]
            for side, point in enumerate((plus, minus)):
                value = _probe(g, point)
                if value is not None and value.size == q:
                    G[side, j] = value
        D = (G[0] - G[1]) / width[:, None]
        noise = _EPS * (np.abs(G[0]) + np.abs(G[1]) + abs(z[k]) * np.abs(D)).max(axis=1) / width
    unusable = ~np.isfinite(D).all(axis=1)
    D[unusable], noise[unusable] = np.nan, np.nan
    return D, noise


def _ridders_column(D: np.ndarray, noise: np.ndarray) -> tuple[np.ndarray, float]:
    """(column, error estimate) from the ladder D by Richardson extrapolation (Ridders).

    Row j, column c of the tableau removes the h^2, ..., h^(2c) error terms:
    R[j, c] = R[j, c-1] + (R[j, c-1] - R[j-1, c-1]) / (4^c - 1). Its error is
    estimated by its distance to the two entries it came from, and at least
    twice the rounding of its newest row (the extrapolation weights add up
    to less than 2); the entry with the smallest estimate is returned.
    """
    best, best_err = D[0], np.inf
    previous = D
    for c in range(1, _TABLEAU + 1):
        current = previous[1:] + (previous[1:] - previous[:-1]) / (4.0**c - 1)
        err = np.maximum(np.abs(current - previous[1:]).max(axis=1),
                         np.abs(current - previous[:-1]).max(axis=1))
        err = np.maximum(err, 2 * noise[c:])
        if np.any(np.isfinite(err)):
            j = int(np.nanargmin(err))
            if err[j] < best_err:
                best, best_err = current[j], float(err[j])
        previous = current
    return best, best_err


# A column along which g is affine (a straight line to rounding) is the same quotient at every
# step, and the largest step rounds least: it is taken from four steps (powers of two of the
# point's scale, its golden-ratio fraction, and 2^-10 of both) when their quotients agree and the
# second differences vanish to _AFFINE_RTOL of the column's size, plus their rounding.
_AFFINE_RTOL = 1e-12
_AFFINE_STEPS = (1.0, _OTHER, 2.0 ** -10, _OTHER * 2.0 ** -10)
# the steps at most this fraction of the largest: a curvature would bend them 2^-20 as much, so
# their second differences measure the rounding inside g (intermediate values larger than g's),
# where they are at most _NOISE_MAX of the change over the largest step (not a fast oscillation)
_NOISE_STEPS = 2.0 ** -10
_NOISE_MAX = 1e-8


# the rounding of a difference: a few eps of the values involved, with room for the rounding
# of the arguments and of intermediate results inside g
_ROUNDING = 64 * _EPS


def _affine_column(g: Callable, z: np.ndarray, k: int, q: int,
                   scale: float) -> tuple[np.ndarray, float] | None:
    """(dg/dz_k, error estimate) when g is affine along e_k at the scale of the point, else None.

    The steps are h = s * (1, 0.618..., 2^-10, 0.618... 2^-10), s =
    2^round(log2 max(scale, |z|)) / 4 (`scale`: the size of the whole point,
    x and u, whose rounding inside g a step much smaller than it would
    magnify); for each, the central difference D(h) must equal D(s) to
    _AFFINE_RTOL |D(s)| s / h, and g(z + h e_k) + g(z - h e_k) - 2 g(z) must
    vanish to 8 _AFFINE_RTOL |D(s)| s, plus the rounding of the values
    (rounding inside g is the same absolute error at every step, hence the
    factors s / h and s) and 8 times the second differences of the two small
    steps where they are below _NOISE_MAX |D(s)| s (the rounding inside g: a
    term A x of 10^4 beside a column of 10^-2, which the values of g do not
    show; a curvature would bend the largest step 2^20 times as much, and a
    fast oscillation is not that small). Then D(s) is exact to rounding (no
    truncation error on a straight line), whatever the scale of the
    coefficients; for a smooth f that passes, its error is below ~1e-11.
    """
    top = 2.0 ** np.round(np.log2(max(scale, float(np.abs(z).max())))) / 4
    with np.errstate(all="ignore"):
        center = _probe(g, z)
        rows = [_sides(g, z, k, top * factor) for factor in _AFFINE_STEPS]
    if center is None or center.size != q or any(row is None or row[0].size != q for row in rows):
        return None
    with np.errstate(all="ignore"):
        quotients = [(plus - minus) / width for plus, minus, width in rows]
        size = float(np.abs(quotients[0]).max())
        noise = np.max([np.abs(plus + minus - 2 * center)
                        for (plus, minus, _), factor in zip(rows, _AFFINE_STEPS) if factor <= _NOISE_STEPS], axis=0)
        noise = np.where(noise <= _NOISE_MAX * size * top, 8 * noise, 0.0)
        worst = 0.0
        for (plus, minus, width), D in zip(rows, quotients):
            # rounding inside g (intermediate values larger than g's) is the same at every step, so
            # its share of D grows like 1 / width: the tolerances grow alike, from the top step's
            rounding = noise + _ROUNDING * (np.abs(plus) + np.abs(minus) + 2 * np.abs(center)
                                            + abs(z[k]) * np.abs(D))
            curvature = np.abs(plus + minus - 2 * center)
            spread = np.abs(D - quotients[0])
            if not (np.all(curvature <= _AFFINE_RTOL * size * 8 * top + rounding)
                    and np.all(spread <= _AFFINE_RTOL * size * 2 * top / width + rounding / width)):
                return None
            worst = max(worst, float(spread.max()))
    plus, minus, width = rows[0]
    own = 2 * _EPS * float((np.abs(plus) + np.abs(minus) + abs(z[k]) * np.abs(quotients[0])).max()) / width
    return quotients[0], max(own, worst)


def _sides(g: Callable, z: np.ndarray, k: int, h: float):
    """(g(z + h e_k), g(z - h e_k), the step actually taken), or None where g fails or is not finite."""
    plus, minus = z.copy(), z.copy()
    plus[k] += h
    minus[k] -= h
    values = [_probe(g, point) for point in (plus, minus)]
    if any(v is None or not np.all(np.isfinite(v)) or v.size != values[0].size for v in values):
        return None
    return values[0], values[1], plus[k] - minus[k]


def _column(g: Callable, z: np.ndarray, k: int, q: int, scale: float) -> tuple[np.ndarray, float]:
    """(dg/dz_k, error estimate): exact where g is affine along e_k (`_affine_column`), else
    from the absolute ladders, or the relative one where it agrees.

    The tableau's own estimate can be fooled by noise or a kink (a lucky
    agreement of two entries), so a second absolute ladder on other points
    (its top step is not a rational multiple of the first's) is computed as
    well, and the two results' disagreement is a lower bound of the error
    (`_agreed`).
    """
    affine = _affine_column(g, z, k, q, scale)
    if affine is not None:
        return affine
    J, err = _agreed([_quotient_ladder(g, z, k, q, _ABSOLUTE_TOP * scale) for scale in (1.0, _OTHER)])
    if abs(z[k]) > _RELATIVE:
        h0 = 2.0 ** np.round(np.log2(abs(z[k]))) / 4
        J_rel, err_rel = _ridders_column(*_quotient_ladder(g, z, k, q, h0))
        if err_rel < err and np.abs(J_rel - J).max() <= err + err_rel:
            return J_rel, err_rel
    return J, err


def _agreed(ladders: list) -> tuple[np.ndarray, float]:
    """(column, error estimate) from two ladders (D, noise): the first's Ridders result, with
    the largest of both tableaus' estimates and of the two results' difference as its error.

    Where the two results differ by more than their own estimates, the largest steps may have
    fooled one tableau: a function that oscillates faster than the largest steps resolve (a
    sine of period 1e-4) looks like a straight line to steps that are near multiples of its
    period, and several such steps agree to the last digit. Their rows are then left out,
    the largest first, and the result whose error is smallest is kept. A tableau's own
    estimate only grows as rows are left out, so the search ends once it exceeds the best.
    """
    best, best_err = None, np.inf
    for top in range(_LADDER - _TABLEAU):
        (J, err), (J_other, err_other) = (_ridders_column(D[top:], noise[top:]) for D, noise in ladders)
        own = max(err, err_other)
        total = max(own, float(np.abs(J - J_other).max()))
        if best is None or total < best_err:
            best, best_err = J, total
        if total <= own or own >= best_err:
            break
    return best, best_err


def _ridders(g: Callable, z: np.ndarray, q: int, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(J, err): the Jacobian (q, n) of g at z by Ridders' method and each column's error estimate.

    Columns along which g is affine are exact (`_affine_column`, at least `scale` wide)."""
    J = np.full((q, z.size), np.nan)
    err = np.full(z.size, np.inf)
    for k in range(z.size):
        J[:, k], err[k] = _column(g, z, k, q, scale)
    return J, err


def numerical_jacobian(g: Callable, z: np.ndarray, *, refine: bool = True) -> np.ndarray:
    """Numerical Jacobian of g at z by central differences.

    ``refine=True`` is Ridders' method (`_ridders`, for `linearize`: about
    1e-10 relative wherever z lies); ``refine=False`` is one central
    difference with step ~ eps^(1/3) max(1, |z_k|) (about 1e-8 relative near
    the origin, 2n evaluations: for filters that need a Jacobian at every step).
    """
    if not refine:
        h = _filter_steps(z)
        return np.column_stack([np.ravel(_central(g, z, h, k)) for k in range(z.size)])
    return _ridders(g, z, np.ravel(g(z)).size)[0]


# A column whose error estimate exceeds 1e-7 of its size is reported: Ridders' method
# reaches ~1e-10 on smooth functions, so a larger estimate means f is not smooth at the
# point (a kink, a discontinuity, noise) or its scale is outside the ladder.
_JACOBIAN_RTOL = 1e-7


def checked_jacobian(g: Callable, z: np.ndarray, q: int, *, symbol: str, variable: str,
                      name: str, checked: Callable, scale: float = 1.0) -> np.ndarray:
    """Ridders' Jacobian of g at z; raises on NaN, warns when a column is not accurate.

    `checked(z, where)` evaluates the same function through `call_user`: for a
    column without any usable step it re-raises what f did there, with context.
    """
    J, err = _ridders(g, z, q, scale)
    for k in range(z.size):
        if not np.all(np.isfinite(J[:, k])):
            step = z.copy()
            step[k] += _ABSOLUTE_TOP / 2 ** (_LADDER - 1)
            checked(step, f"at {variable}_eq + {step[k] - z[k]:.2g} e_{k + 1} (a difference-quotient step)")
            raise ValueError(
                f"{name} has no derivative with respect to {variable}{k + 1} at the equilibrium: "
                f"every difference quotient for column {k + 1} of {symbol} is NaN or inf. Check "
                "that f is defined and smooth in a neighbourhood of x_eq, u_eq (no square root "
                "or logarithm at the edge of its domain, no division by zero)."
            )
    # a (nearly) zero column is measured against the largest entry of the whole matrix
    floor = np.sqrt(_EPS) * np.abs(J).max(initial=0.0)
    size = np.maximum(np.abs(J).max(axis=0, initial=0.0), floor)
    bad = [k for k in range(z.size) if not err[k] <= _JACOBIAN_RTOL * size[k]]
    if bad:
        k = max(bad, key=lambda i: err[i] / max(size[i], 1e-300))
        warn_accuracy(
            f"linearize: column {k + 1} of {symbol} (d f / d {variable}{k + 1}) is uncertain: its "
            f"error estimate {err[k]:.2g} exceeds {_JACOBIAN_RTOL:g} of the column's size "
            f"{size[k]:.3g} ({len(bad)} column(s) affected). Either {name} is not smooth at this "
            "point (a jump, a switch, noise in its values), or |" + f"{variable}{k + 1}| = "
            f"{abs(z[k]):.3g} is so large that f sees it only to about {_EPS * abs(z[k]):.1g} "
            "(rounding). Check f there, shift the coordinates so that the equilibrium is near "
            "0, or compute the Jacobian exactly with linearize_symbolic.",
            stacklevel=4,
        )
    return J
