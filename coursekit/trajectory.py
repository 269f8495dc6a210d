"""Open-loop control (section 2.3): polynomial trajectories and feedforward.

* `poly_trajectory(T, start, end)` is the polynomial of degree 2r - 1 that
  meets r boundary values (value and r - 1 derivatives) at t = 0 and t = T,
  the construction (2.31)-(2.38) for any r, in closed form (a two-point
  Hermite basis in tau = t / T): accurate to rounding for r up to 20, and it
  re-checks its boundary conditions;
* `feedforward(a, b, traj)` is the input (2.25) that makes the output of a
  plant in controllability canonical form follow `traj`;
* `open_loop_control(A, B, x0, xT, T)` is the algorithm (2.73) for any
  controllable single-input system: transform to the CCF, plan z1 from
  z0 = T x0 to zT = T xT, and apply the feedforward input; the plan is
  checked by solving the plant exactly with it (`AccuracyWarning` if it
  does not land).

Shared within coursekit (not in ``ck.*``): `input_time`, `plan_grid` and `PLAN_RTOL`,
which `flatness` uses for its plans too.
"""

from __future__ import annotations

from fractions import Fraction
from functools import cache
from math import comb, factorial, isfinite
from typing import Callable

import numpy as np

from ._pairs import as_pair
from ._plans import PLAN_RTOL, input_time, plan_grid
from ._validation import (as_integer, as_scalar, as_series, as_time_grid, as_vector, call_user, require_columns,
                          warn_accuracy)
from .controllability import ccf_transform, charpoly

__all__ = ["PolyTrajectory", "poly_trajectory", "feedforward", "OpenLoopPlan", "open_loop_control",
           "plot_plan"]


def _times(t, name: str = "t"):
    """Return (times as a 1-D array, whether the input was a single number)."""
    return as_vector(t, name), np.ndim(t) == 0


def _derivative_order(k) -> int:
    k_float = as_scalar(k, "k", integer=True)
    if k_float < 0:
        raise ValueError(f"k must be a derivative order >= 0: received {k!r}; use k=0 for the value.")
    return int(k_float)


# Taylor expansions of the normalized polynomial p(tau) are kept at the centres tau = q / 16
# (q = 0..16); each time is evaluated with the nearest one, |tau - q/16| <= 1/32. Against an
# exact rational evaluation this keeps every derivative of degree-39 polynomials (r = 20)
# within ~50 eps of its largest value on [0, T]; with 8 centres r = 20 loses ~1e3 eps, with
# one expansion at each end ~1e8 eps (the sums then cancel as in a monomial basis).
_CENTRES = 16
# A boundary condition comes out of ~6 roundings (the data times T^k, one basis coefficient,
# a factorial, the division by T^k): a miss above 32 eps of its value is not rounding.
_BOUNDARY_ULPS = 32.0
_EPS = float(np.finfo(float).eps)


def _taylor_shift(coeffs: list, q: int) -> list:
    """Integer coefficients of P(q + g) from those of P(g) (ascending), exactly."""
    a = list(coeffs)
    for i in range(len(a) - 1):
        for j in range(len(a) - 2, i - 1, -1):
            a[j] += q * a[j + 1]
    return a


@cache
def _hermite_basis(r: int) -> np.ndarray:
    """Taylor coefficients of the two-point Hermite basis of degree N = 2r - 1 at the centres.

    ``H_k(tau) = tau^k / k! (1 - tau)^r sum_{j < r - k} C(r - 1 + j, j) tau^j``
    (k = 0..r-1) has ``H_k^(i)(0) = delta_ik`` and ``H_k^(i)(1) = 0`` for i < r:
    the polynomial with k-th derivative 1 at tau = 0 and every other boundary
    condition of (2.34)-(2.37) zero. Entry ``[q, k, j]`` is the coefficient of
    h^j in ``H_k(q / M + h)``, M = `_CENTRES`, computed in exact integer
    arithmetic and rounded once, so the coefficients that must vanish (those
    of h^j, j < r, other than j = k at q = 0, and all of them at q = M) are
    exactly zero.
    """
    N, M = 2 * r - 1, _CENTRES
    out = np.zeros((M + 1, r, N + 1))
    for k in range(r):
        # numerator of H_k in powers of tau: tau^k (1 - tau)^r Q_k(tau), integer coefficients
        numer = [0] * (N + 1)
        for i in range(r + 1):
            for j in range(r - k):
                numer[k + i + j] += (-1) ** i * comb(r, i) * comb(r - 1 + j, j)
        for q in range(M + 1):
            # H_k(q/M + h) = sum_j numer_j (q + g)^j / (k! M^j) with g = M h
            shifted = _taylor_shift([c * M ** (N - j) for j, c in enumerate(numer)], q)
            den = factorial(k) * M ** N
            out[q, k] = [float(Fraction(c * M ** j, den)) for j, c in enumerate(shifted)]
    out.flags.writeable = False
    return out


@cache
def _falling(N: int) -> np.ndarray:
    """F[i, l] = (i + l)! / l!: the factor of h^l in the i-th derivative of h^(i + l)."""
    F = np.zeros((N + 1, N + 1))
    for i in range(N + 1):
        for l in range(N + 1 - i):
            F[i, l] = float(factorial(i + l) // factorial(l))
    F.flags.writeable = False
    return F


class PolyTrajectory:
    """A polynomial y_d(t) of degree 2r - 1 with given values and derivatives at 0 and T.

    Call it as ``traj(t, k=0)`` for the k-th time derivative at time(s) `t`
    (a number gives a number, an array an array of the same length); outside
    [0, T] the polynomial is simply continued. Attributes: ``T``, ``start``,
    ``end``, ``r``, ``degree`` and ``coeffs``, the ascending coefficients of
    the same polynomial in the centred time s = 2 t / T - 1.

    Representation: in the normalized time tau = t / T the polynomial is
    ``p(tau) = sum_k T^k [y^(k)(0) H_k(tau) + y^(k)(T) G_k(tau)]`` with the
    two-point Hermite basis H_k of `_hermite_basis` and ``G_k(tau) =
    (-1)^k H_k(1 - tau)``, and ``y^(k)(t) = p^(k)(t / T) / T^k``. The basis is
    computed exactly and kept as Taylor expansions at 17 centres in [0, 1];
    a time is evaluated with the nearest one by Horner's rule. So every
    derivative is accurate to about 50 eps of its largest value on [0, T]
    for r up to 20, and at t = 0 and t = T the expansions reproduce the
    boundary values to a few units in the last place.
    """

    def __init__(self, T: float, start: np.ndarray, end: np.ndarray):
        self.T = T
        self.start = start
        self.end = end
        self.r = start.size
        N = self.degree
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            Tk = T ** np.arange(self.r, dtype=float)
            # the boundary conditions in normalized time: d^k p / d tau^k = T^k d^k y / dt^k
            self._alpha, self._beta = start * Tk, end * Tk
            H = _hermite_basis(self.r)
            sign_k = (-1.0) ** np.arange(self.r)
            sign_j = (-1.0) ** np.arange(N + 1)
            # G_k(q/M + h) = (-1)^k H_k((M - q)/M - h): the expansion at the mirrored centre
            C = (np.einsum("k,qkj->qj", self._alpha, H)
                 + np.einsum("k,qkj->qj", self._beta * sign_k, H[::-1]) * sign_j)
            # table[q, i, l]: coefficient of h^l in p^(i)(q/M + h)
            rows = np.arange(N + 1)[:, None] + np.arange(N + 1)[None, :]
            self._table = np.where(rows <= N, C[:, np.minimum(rows, N)], 0.0) * _falling(N)
            self._inv_powers = T ** -np.arange(N + 1, dtype=float)
        # plain-float copies of the table, one centre at a time, for `derivatives`
        self._rows = [None] * (_CENTRES + 1)
        self._inv = self._inv_powers.tolist()

    @property
    def degree(self) -> int:
        """Degree 2r - 1 of the polynomial."""
        return 2 * self.r - 1

    @property
    def coeffs(self) -> np.ndarray:
        """Ascending coefficients of the polynomial in the centred time s = 2 t / T - 1."""
        # tau = 1/2 + s/2: the coefficient of s^j is that of h^j at the middle centre over 2^j
        return self._table[_CENTRES // 2, 0] / 2.0 ** np.arange(self.degree + 1)

    def __call__(self, t, k=0):
        if isinstance(t, float) and isfinite(t) and type(k) is int and k >= 0:
            # one finite time, as an ODE solver asks at every step: skip the array checks
            return self.derivatives(t, k)[k]
        tt, scalar = _times(t)
        values = self._eval(tt, _derivative_order(k))
        return float(values[0]) if scalar else values

    def derivatives(self, t: float, order: int) -> list:
        """[y, y', ..., y^(order)] at one finite time t (a float), in plain floats, unchecked:
        the fast path for ODE solvers and for the flat outputs' derivatives (2.88)."""
        tau = t / self.T
        q = min(max(round(tau * _CENTRES), 0), _CENTRES)
        h = tau - q / _CENTRES
        if self._rows[q] is None:
            self._rows[q] = self._table[q].tolist()
        table, N = self._rows[q], self.degree
        out = []
        for k in range(order + 1):
            if k > N:
                out.append(0.0)
                continue
            value = 0.0
            # Horner's rule for p^(k)(q/M + h), then d^k y/dt^k = p^(k) / T^k
            for c in reversed(table[k][:N + 1 - k]):
                value = value * h + c
            out.append(value * self._inv[k])
        return out

    def _eval(self, tt, k: int):
        """k-th derivative at the checked times `tt` (no input validation: for inner loops)."""
        N = self.degree
        if k > N:
            return np.zeros_like(tt)
        tau = tt / self.T
        q = np.clip(np.rint(tau * _CENTRES), 0, _CENTRES).astype(int)
        h = tau - q / _CENTRES
        coef = self._table[q, k]
        value = np.zeros_like(tau)
        # Horner's rule, each time with the expansion at its own centre
        for l in range(N - k, -1, -1):
            value = value * h + coef[:, l]
        return value * self._inv_powers[k]

    def __repr__(self) -> str:
        return (f"PolyTrajectory of degree {self.degree} on [0, {self.T:g}]: "
                f"start {self.start.tolist()}, end {self.end.tolist()}")


def _boundary_misses(traj: PolyTrajectory) -> list:
    """[(k, end name, wanted, got, miss, allowed)] for every boundary condition missed."""
    misses = []
    for name, t_end, wanted in (("t = 0", 0.0, traj.start), ("t = T", traj.T, traj.end)):
        for k, want in enumerate(wanted):
            got = traj(t_end, k)
            miss = abs(got - want)
            allowed = _BOUNDARY_ULPS * _EPS * abs(want)
            if not miss <= allowed:
                misses.append((k, name, float(want), got, miss, allowed))
    return misses


def _out_of_range(traj: PolyTrajectory) -> bool:
    """True when a power T^(+-k), k <= 2r - 1, or a nonzero y^(k) T^k is outside the normal range."""
    tiny = np.finfo(float).tiny
    scaled = np.concatenate([traj._alpha, traj._beta])
    data = np.concatenate([traj.start, traj.end])
    unrepresentable = (data != 0) & ~(np.isfinite(scaled) & (np.abs(scaled) >= tiny))
    with np.errstate(over="ignore", divide="ignore"):
        powers = np.concatenate([traj._inv_powers, 1.0 / traj._inv_powers[1:]])
    return bool(np.any(unrepresentable)) or not np.all(np.isfinite(powers) & (powers >= tiny))


def _check_boundaries(traj: PolyTrajectory) -> None:
    """Warn when traj misses one of its boundary conditions (2.34)-(2.37) by more than rounding."""
    misses = _boundary_misses(traj)
    if not misses:
        return
    k, name, want, got, miss, allowed = max(
        misses, key=lambda m: m[4] / max(abs(m[2]), 1e-300) if np.isfinite(m[4]) else np.inf)
    reason = (
        f"Double precision cannot hold the conditions in normalized time tau = t / T: "
        f"y^(k) T^k over- or underflows for T = {traj.T:g} and k up to {traj.degree}. "
        "Express time in other units so that T is nearer 1 (ms, minutes, hours), or use "
        "fewer boundary conditions."
        if _out_of_range(traj) else
        "Try fewer boundary conditions (a lower r) or a horizon T nearer 1 in the time unit used."
    )
    warn_accuracy(
        f"poly_trajectory misses {len(misses)} of its {2 * traj.r} boundary conditions "
        f"(2.34)-(2.37); worst: y^({k}) at {name} is {got:.6g} instead of {want:.6g}, off by "
        f"{miss:.3g}, while rounding explains at most {allowed:.3g} ({_BOUNDARY_ULPS:g} eps "
        f"of the value). {reason}",
        stacklevel=4,
    )


def _check_finite(traj: PolyTrajectory) -> None:
    """Raise naming T when a derivative of traj is inf or NaN somewhere on [0, T].

    The k-th derivative scales like 1/T^k and the conditions in normalized time like
    y^(k) T^k: for a T far from 1 (1e-300, 1e300) they leave the float range, and a plan
    built on such a trajectory would hand out inf or NaN without a word.
    """
    t = traj.T * np.linspace(0.0, 1.0, _CENTRES + 1)
    with np.errstate(all="ignore"):
        for k in range(traj.degree + 1):
            values = traj._eval(t, k)
            if not np.isfinite(values).all():
                bad = values[~np.isfinite(values)][0]
                raise ValueError(
                    f"T = {traj.T:g} is out of reach of double precision for this trajectory: its "
                    f"derivative y^({k}) on [0, T] is {bad} (the k-th derivative scales like 1/T^k, "
                    f"the boundary conditions in normalized time like y^(k) T^k, k up to "
                    f"{traj.degree}). Express time in other units so that T is nearer 1 (ms, "
                    "minutes, hours), or use fewer boundary conditions."
                )


def poly_trajectory(T, start, end) -> PolyTrajectory:
    """Polynomial trajectory from `start` at t = 0 to `end` at t = T.

    Implements (2.31)-(2.38) for any number r of boundary conditions:
    ``start = [y(0), y'(0), ..., y^(r-1)(0)]`` and likewise `end` at T give
    the unique polynomial of degree 2r - 1 (r = 2 is the cubic (2.33)).

    Returns a `PolyTrajectory` ``traj`` with ``traj(t, k=0)`` the k-th derivative, written in
    closed form in tau = t / T rather than by solving (2.37) in powers of t (a matrix of T, ...,
    T^(2r-1): hopeless for long horizons or many conditions); its accuracy is `PolyTrajectory`'s
    for any T whose powers T^k (k < 2r) stay in double range. A T for which a derivative on
    [0, T] leaves the float range raises a ValueError naming T; a boundary condition missed by
    more than 32 eps of its value (possible only when y^(k) T^k over- or underflows) gives an
    `AccuracyWarning` saying which derivative, at which end, by how much.
    """
    T = as_scalar(T, "T", positive=True)
    start = as_vector(start, "start")
    end = as_vector(end, "end", size=start.size,
                    why="the same number of boundary conditions at t = 0 and t = T")
    if start.size == 0:
        raise ValueError("start is empty: expected at least the value y(0) (and its derivatives).")
    traj = PolyTrajectory(T, start, end)
    _check_finite(traj)
    _check_boundaries(traj)
    return traj


def _check_trajectory(traj, order: int) -> None:
    """Call traj once at t = 0 for every derivative k = 0..order that (2.25) uses."""
    if not callable(traj):
        raise ValueError(
            f"traj must be a function traj(t, k) returning the k-th derivative of y_d at t: "
            f"received {type(traj).__name__}; build one with poly_trajectory(T, start, end)."
        )
    for k in range(order + 1):
        value = call_user(traj, (0.0, k), "traj", where=f"at t = 0 (k = {k}), called once as a check")
        if value.size != 1:
            raise ValueError(f"traj(0.0, {k}) returned shape {value.shape}; expected one number (the "
                             f"derivative y_d^({k})(0)).")


def feedforward(a, b, traj: Callable) -> Callable:
    """Feedforward input u_d(t) for a plant in controllability canonical form.

    Implements (2.25): ``u_d = (a_0 y_d + a_1 y_d' + ... + a_{n-1} y_d^(n-1) + y_d^(n)) / b``
    for the CCF (2.16) with last row ``-[a_0 ... a_{n-1}]`` (ascending, as
    returned by `charpoly`) and input gain b. `traj(t, k)` is the desired
    output and its derivatives, e.g. a `poly_trajectory`.

    Returns ``ud(t)``: a number for a number, an array for an array of times.
    A `traj` that raises, or returns NaN/inf, text or None (checked once at
    t = 0 for every derivative k = 0..n, and at every call of ``ud``) gives a `UserFunctionError` (a
    ValueError) naming traj and the derivative asked for.
    """
    a = as_vector(a, "a")
    b = as_scalar(b, "b")
    if b == 0:
        raise ValueError("b must be nonzero: received 0; with b = 0 the input does not enter "
                         "the plant (2.16) and no feedforward exists.")
    n = a.size
    _check_trajectory(traj, n)

    def y(t, k):
        value = call_user(traj, (t, k), "traj", where=f"for the derivative k = {k} in feedforward's ud(t)")
        return value[()] if value.ndim == 0 else value

    def ud(t):
        # (2.25): u_d = (1/b) [a_0 y_d + ... + a_{n-1} y_d^(n-1) + y_d^(n)]
        total = y(t, n)
        for i in range(n):
            total = total + a[i] * y(t, i)
        return total / b

    return ud


class OpenLoopPlan:
    """Result of `open_loop_control`: the plan from x0 to xT in time T.

    Attributes
    ----------
    A, B : the plant; x0, xT : start and target state; horizon : the time T.
    transform : the matrix T with z = T x in CCF (2.59)-(2.65).
    a : ascending characteristic polynomial of A (last row of the CCF is -a).
    z0, zT : T x0 and T xT, the boundary conditions of y_d = z1.
    yd : the `PolyTrajectory` planned for z1.

    Methods ``ud(t)``, ``z(t)``, ``x(t)`` evaluate the planned input and
    states; ``input(t, x)`` is ``ud`` in the form `simulate` accepts. Times
    outside [0, T] are clipped: before 0 and after T the end values are held.
    `open_loop_control` has checked that x(0), x(T) and the plant driven by
    ``ud`` meet x0 and xT (or warned).
    """

    def __init__(self, A, B, x0, xT, horizon, transform, a, yd):
        self.A, self.B, self.x0, self.xT = A, B, x0, xT
        self.horizon = horizon
        self.transform = transform
        self.a = a
        self.yd = yd
        self.z0 = transform @ x0
        self.zT = transform @ xT
        self._ud = feedforward(a, 1.0, yd)

    @property
    def n(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    def _clip(self, t):
        tt, scalar = _times(t)
        return np.clip(tt, 0.0, self.horizon), scalar

    def ud(self, t):
        """Planned input u_d(t) (2.73), the CCF feedforward (2.25) with b = 1."""
        tt, scalar = self._clip(t)
        values = self._ud(tt)
        return float(values[0]) if scalar else values

    def z(self, t) -> np.ndarray:
        """Planned CCF state z = [y_d, y_d', ..., y_d^(n-1)] (2.20)-(2.23), shape (N, n)."""
        tt, scalar = self._clip(t)
        z = np.column_stack([self.yd(tt, k) for k in range(self.n)])
        return z[0] if scalar else z

    def x(self, t) -> np.ndarray:
        """Planned original state x = T^-1 z (2.46), shape (N, n)."""
        # x = T^-1 z, solved rather than inverted
        z = self.z(t)
        return np.linalg.solve(self.transform, z.T).T

    def input(self, t, x=None) -> np.ndarray:
        """``u(t, x)`` for `simulate`: the open-loop input ignores x (t is clipped to [0, T])."""
        return np.array(self._input_derivatives(input_time(t, self.horizon), 1))

    def _input_derivatives(self, t: float, count: int) -> list:
        """[u_d, u_d', ..., u_d^(count-1)] at one time t, in plain floats.

        The same u_d as `ud`, (2.25) with b = 1, differentiated term by term:
        u_d^(k) = y_d^(n+k) + a_0 y_d^(k) + ... + a_{n-1} y_d^(n-1+k).
        """
        n = self.n
        y = self.yd.derivatives(t, n + count - 1)
        out = []
        for k in range(count):
            total = y[n + k]
            for i in range(n):
                total = total + self.a[i] * y[i + k]
            out.append(float(total))
        return out

    def plot(self, samples: int = 301):
        """Figure of the planned states x(t) and the input u_d(t) on [0, T]; returns the figure."""
        t = plan_grid(self.horizon, samples)
        return plot_plan(t, self.x(t), self.ud(t).reshape(-1, 1),
                         title=f"open-loop plan (2.73) from x0 = {self.x0.tolist()} to xT = {self.xT.tolist()}")

    def __repr__(self) -> str:
        return (f"OpenLoopPlan over [0, {self.horizon:g}] from x0 = {self.x0.tolist()} "
                f"to xT = {self.xT.tolist()}; CCF a = {np.round(self.a, 6).tolist()}")


def plot_plan(t, x, u, *, title: str):
    """Two panels: planned states and planned inputs against time (used by the plan objects).

    `t` is the (N,) time grid, `x` the (N, n) states and `u` the (N, m) inputs
    (time-major; a 1-D `u` is one input). Raises ValueError naming the
    argument whose shape does not fit.
    """
    t = as_time_grid(t, "t")
    x = as_series(x, "x", samples=t.size)
    u = as_series(u, "u", samples=t.size)
    require_columns(x.shape, "x", each="state")
    require_columns(u.shape, "u", each="input")
    title = str(title)
    from .style import new_figure
    fig, (ax_x, ax_u) = new_figure(1, 2, figsize=(10, 3.6))
    for i in range(x.shape[1]):
        ax_x.plot(t, x[:, i], label=f"x{i + 1}")
    for j in range(u.shape[1]):
        ax_u.plot(t, u[:, j], label=f"u{j + 1}" if u.shape[1] > 1 else "u_d")
    ax_x.set(title="planned state", xlabel="time t [s]", ylabel="state x [units of x]")
    ax_u.set(title="planned input", xlabel="time t [s]", ylabel="input u [units of u]")
    for ax in (ax_x, ax_u):
        ax.grid(True, alpha=0.4)
        ax.legend()
    fig.suptitle(title, wrap=True)
    return fig


def _landing(plan: OpenLoopPlan) -> np.ndarray:
    """x(T) of x' = A x + B u_d from x0, exactly: (2.4) over 16 steps of the polynomial u_d.

    On each step [t_k, t_k + h] the input is the polynomial u_d with Taylor data
    w = [u_d, T u_d', ..., T^N u_d^(N)] at t_k, and w' = S w / T (S the shift):
    one matrix exponential of [[A h, B e_1^T h], [0, S h / T]] gives the exact step.
    """
    from scipy.linalg import expm
    A, B, T, n, N = plan.A, plan.B, plan.horizon, plan.n, plan.yd.degree
    h = T / _CENTRES
    M = np.zeros((n + N + 1, n + N + 1))
    M[:n, :n] = A * h
    M[:n, n] = B[:, 0] * h
    M[n:, n:] = np.eye(N + 1, k=1) * (h / T)
    E = expm(M)
    scale = T ** np.arange(N + 1, dtype=float)
    x = plan.x0
    for k in range(_CENTRES):
        w = np.array(plan._input_derivatives(k * h, N + 1)) * scale
        x = E[:n, :n] @ x + E[:n, n:] @ w
    return x


def _check_plan(plan: OpenLoopPlan) -> None:
    """Warn unless the plan's own x(0), x(T) and the plant driven by u_d meet x0 and xT."""
    t = np.linspace(0.0, plan.horizon, _CENTRES + 1)
    with np.errstate(all="ignore"):
        x_plan = plan.x(t)
        landed = _landing(plan)
    task = max(np.abs(plan.x0).max(), np.abs(plan.xT).max())
    peak = float(np.abs(x_plan).max()) if np.all(np.isfinite(x_plan)) else np.inf
    misses = {"the planned x(0)": np.abs(x_plan[0] - plan.x0).max(),
              "the planned x(T)": np.abs(x_plan[-1] - plan.xT).max(),
              "the simulated x(T)": np.abs(landed - plan.xT).max()}
    allowed = PLAN_RTOL * (task if task > 0 else 1.0)
    worst = max(misses, key=lambda key: misses[key] if np.isfinite(misses[key]) else np.inf)
    if all(miss <= allowed for miss in misses.values()):
        return
    other = "; ".join(f"{key} misses by {miss:.3g}" for key, miss in misses.items() if key != worst)
    warn_accuracy(
        f"open_loop_control: the plan does not land. {worst} misses its target by "
        f"{misses[worst]:.3g}, more than {PLAN_RTOL:g} of the task's size {task:.3g} ({other}; "
        f"simulated: x' = A x + B u_d solved exactly). On the way the planned state reaches "
        f"{peak:.3g} and the CCF transform z = T x (2.65) has condition number "
        f"{np.linalg.cond(plan.transform):.2g}, so rounding alone moves x(T) this much. "
        "Try a different horizon T (a longer one if the plan swings far, a shorter one if A "
        "has fast unstable modes), fewer states (a reduced model), or a model in units that "
        "make the entries of A and B of similar size.",
        stacklevel=4,
    )


def open_loop_control(A, B, x0, xT, T, *, smooth: int = 0) -> OpenLoopPlan:
    """Open-loop steering of x' = A x + B u from x0 to xT in time T (algorithm (2.73)).

    1. check controllability and compute the CCF transform z = T x (2.59)-(2.65)
       (raises `NotControllableError` otherwise);
    2. translate the task: z0 = T x0, zT = T xT;
    3. plan y_d = z1 as the polynomial of degree 2n - 1 with
       y_d^(k)(0) = z0[k], y_d^(k)(T) = zT[k] (2.31)-(2.38);
    4. apply the feedforward u_d (2.25) with the CCF's a and b = 1;
    5. check the plan (`_check_plan`): its own x(0) and x(T), and the end state of the plant
       driven by u_d (solved exactly, `_landing`), must meet x0 and xT to 1e-6 of
       max(|x0|, |xT|), else an `AccuracyWarning` says which misses, by how much and what to
       try. The trajectory meets its boundary conditions to rounding, so a miss comes from
       the plant: states passing through ~1e9 times the task's size cannot land in doubles.

    ``smooth = s > 0`` adds s more boundary conditions, y_d^(n)..y_d^(n+s-1)
    = 0 at both ends (degree 2(n + s) - 1): then u_d starts and ends at the
    value a . z that holds an equilibrium, without a jump.

    Single input only. Returns an `OpenLoopPlan`.
    """
    A, B = as_pair(A, B)
    n = A.shape[0]
    why = f"one per state of the {n}-state system"
    x0 = as_vector(x0, "x0", size=n, why=why)
    xT = as_vector(xT, "xT", size=n, why=why)
    horizon = as_scalar(T, "T", positive=True)
    extra = as_integer(smooth, "smooth", minimum=0, why="the number of extra zero derivatives")
    Tz = ccf_transform(A, B)
    a = charpoly(A)
    zeros = np.zeros(extra)
    # z0 = T x0, zT = T xT; in the CCF z = [z1, z1', ..., z1^(n-1)]
    yd = poly_trajectory(horizon, np.concatenate([Tz @ x0, zeros]), np.concatenate([Tz @ xT, zeros]))
    plan = OpenLoopPlan(A, B, x0, xT, horizon, Tz, a, yd)
    _check_plan(plan)
    return plan
