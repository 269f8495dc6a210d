"""Flatness (section 2.4): state and input as functions of a flat output F.

A `FlatSystem` bundles, for one system, the flat output F = phi(x) and the
two maps of (2.88)-(2.89)::

    x = psi_x(F, F', ..., F^(n-1)),    u = psi_u(F, F', ..., F^(n)).

Both maps take ``derivs = [F, F', F'', ...]``: a list whose k-th entry is the
k-th derivative of F, an array with one entry per flat output (shape (p,))
at one time or shape (N, p) at N times; with one flat output a number or an
(N,) array (N > 1) is accepted too. They return x of shape (n,) or (N, n) and u of
shape (m,) or (N, m).

The systems of the notes:

* `linear_flatness(A, B)`: F = T_1 x (2.74)-(2.87);
* `pendulum_flatness(...)`: F = theta (2.90)-(2.92);
* `two_wheeled_flatness()`: F = (x1, x2) (2.94)-(2.102);
* `car_like_flatness(L)`: F = (x1, x2), the exercise at the end of 2.4.

`plan_flat_output` plans polynomial F_d (the nonlinear open-loop algorithm of
2.4.2) and `plan_robot` does it from poses for the two mobile robots.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._pairs import as_pair
from ._plans import PLAN_RTOL, input_time, plan_grid
from ._validation import as_flag, as_matrix, as_scalar, as_vector, float_array, warn_accuracy
from .controllability import ccf_transform, charpoly
from .trajectory import plot_plan, poly_trajectory

__all__ = ["FlatSystem", "FlatPlan", "linear_flatness", "pendulum_flatness", "two_wheeled_flatness",
           "car_like_flatness", "plan_flat_output", "plan_robot"]


class FlatSystem:
    """A system with a flat output F = phi(x) and the maps psi_x, psi_u (2.88)-(2.89).

    Attributes
    ----------
    name : str
    n, m : numbers of states and inputs; m flat outputs (2.93).
    order_x, order_u : highest derivative of F that psi_x and psi_u need.
    params : the parameters the maps were built with.
    """

    def __init__(self, *, name: str, n: int, m: int, order_x: int, order_u: int,
                 phi: Callable, psi_x: Callable, psi_u: Callable, params: dict | None = None):
        self.name = name
        self.n, self.m = n, m
        self.order_x, self.order_u = order_x, order_u
        self._phi, self._psi_x, self._psi_u = phi, psi_x, psi_u
        self.params = dict(params or {})

    def phi(self, x) -> np.ndarray:
        """Flat output F = phi(x); x of shape (n,) or (N, n)."""
        single = np.ndim(x) == 1
        X = as_matrix(x, "x", rows=1 if single else None, cols=self.n,
                      cols_why=f"one per state of the {self.name}")
        F = self._phi(X)
        return F[0] if single else F

    def psi_x(self, derivs) -> np.ndarray:
        """State x = psi_x(F, ..., F^(order_x)) (2.88)."""
        D, single = self._derivs(derivs, self.order_x)
        x = self._psi_x(D)
        return x[0] if single else x

    def psi_u(self, derivs) -> np.ndarray:
        """Input u = psi_u(F, ..., F^(order_u)) (2.89)."""
        D, single = self._derivs(derivs, self.order_u)
        u = self._psi_u(D)
        return u[0] if single else u

    def _derivs(self, derivs, order: int):
        """Check `derivs` and return it as a list of (N, m) arrays and a single-time flag."""
        if not isinstance(derivs, (list, tuple, np.ndarray)) or len(derivs) < order + 1:
            got = len(derivs) if isinstance(derivs, (list, tuple, np.ndarray)) else type(derivs).__name__
            raise ValueError(
                f"derivs must list F and its derivatives [F, F', ..., F^({order})] for the "
                f"{self.name}: received {got}; expected at least {order + 1} entries."
            )
        arrays = [float_array(d, f"derivs[{k}]") for k, d in enumerate(derivs[:order + 1])]
        # one time: a number, or shape (m,); with one flat output an (N,) array lists N times
        single = arrays[0].ndim == 0 or (arrays[0].ndim == 1 and (self.m > 1 or arrays[0].size == 1))
        out = []
        for k, d in enumerate(arrays):
            d = d.reshape(1, -1) if single else (d.reshape(-1, 1) if d.ndim == 1 else d)
            out.append(as_matrix(d, f"derivs[{k}]", cols=self.m,
                                 cols_why=f"one per flat output of the {self.name}",
                                 rows=out[0].shape[0] if out else None,
                                 rows_why="one per time, like derivs[0]"))
        return out, single

    def __repr__(self) -> str:
        return (f"FlatSystem {self.name!r}: n={self.n}, m={self.m}; x needs F..F^({self.order_x}), "
                f"u needs F..F^({self.order_u})")


def linear_flatness(A, B) -> FlatSystem:
    """Flat output F = T_1 x of a controllable single-input LTI system (2.74)-(2.87).

    T_1 is the first row of the CCF transform (2.65). Then
    ``x = Lambda [F, F', ..., F^(n-1)]`` with ``Lambda = T^-1`` (2.77)-(2.78)
    and ``u = a_0 F + ... + a_{n-1} F^(n-1) + F^(n)`` (2.79). Raises
    `NotControllableError` for an uncontrollable pair: no flat output exists.
    The maps are checked against their defining equations (`_check_linear_maps`);
    an `AccuracyWarning` says when an ill-conditioned CCF transform breaks them.
    """
    A, B = as_pair(A, B)
    n = A.shape[0]
    a = charpoly(A)                # first: raises when its coefficients leave the float range
    T = ccf_transform(A, B)
    Lam = np.linalg.inv(T)

    def phi(X):
        # (2.76): F = T_1 x
        return X @ T[:1].T

    def psi_x(D):
        # (2.78): x = Lambda [F, F', ..., F^(n-1)]
        Z = np.hstack(D[:n])
        return Z @ Lam.T

    def psi_u(D):
        # (2.79): u = a_0 F + ... + a_{n-1} F^(n-1) + F^(n)
        return np.hstack(D[:n]) @ a.reshape(-1, 1) + D[n]

    flat = FlatSystem(name="linear system", n=n, m=1, order_x=n - 1, order_u=n,
                      phi=phi, psi_x=psi_x, psi_u=psi_u, params=dict(A=A, B=B))
    flat.T1, flat.Lambda, flat.a = T[0].copy(), Lam, a
    _check_linear_maps(A, B, T, Lam, a)
    return flat


# Rounding leaves residuals of about n eps cond(T) in (2.77)-(2.79) (random 16-state systems:
# cond(T) ~ 1e8, residuals <= 5e-12); above 1e-8 the maps no longer describe the system.
_MAPS_RTOL = 1e-8


def _check_linear_maps(A, B, T, Lam, a) -> None:
    """Warn unless x = Lambda z, u = a.z + F^(n) satisfy x' = A x + B u and F = T_1 x.

    Along any F(t), z = [F, ..., F^(n-1)] obeys z' = A_c z + e_n u with the CCF
    matrix A_c (2.16), so x = Lambda z solves x' = A x + B u exactly when
    A Lambda = Lambda A_c and Lambda e_n = B; F = T_1 x needs T_1 Lambda = e_1^T.
    """
    n = A.shape[0]
    A_c = np.eye(n, k=1)
    A_c[-1] = -a
    norm = np.linalg.norm
    residuals = {
        "A Lambda = Lambda A_c": norm(A @ Lam - Lam @ A_c) / (norm(Lam) * (norm(A) + norm(A_c))),
        "Lambda e_n = B": norm(Lam[:, -1] - B[:, 0]) / norm(B),
        "T_1 Lambda = e_1^T": norm(T[0] @ Lam - np.eye(n)[0]) / (norm(T[0]) * norm(Lam)),
    }
    name, worst = max(residuals.items(), key=lambda item: item[1] if np.isfinite(item[1]) else np.inf)
    if not worst <= _MAPS_RTOL:
        warn_accuracy(
            f"linear_flatness: the flat maps miss their defining equations (2.77)-(2.79): "
            f"{name} holds only to {worst:.2g} (relative; allowed {_MAPS_RTOL:g}). The CCF "
            f"transform T has condition number {np.linalg.cond(T):.2g}, so x = Lambda [F, ..., "
            f"F^(n-1)] loses about {np.log10(np.linalg.cond(T)):.0f} of the 16 digits. "
            "Use a model in units that make the entries of A and B of similar size, or fewer states.",
            stacklevel=4,
        )


def pendulum_flatness(m: float = 1.0, l: float = 1.0, g: float = 9.81,
                      d_theta: float = 0.0) -> FlatSystem:
    """Flat output F = theta of the pendulum (2.90)-(2.92), same parameters as `models.pendulum`.

    ``x = [F, F']`` (2.91) and ``u = m l^2 F'' + d_theta l^2 F' + m g l sin F``:
    (2.92) plus the damping term of (1.8) (zero by default, as in (2.90)).
    """
    m, l = as_scalar(m, "m", positive=True), as_scalar(l, "l", positive=True)
    g, d_theta = as_scalar(g, "g"), as_scalar(d_theta, "d_theta")

    def phi(X):
        return X[:, :1]

    def psi_x(D):
        # (2.91): x1 = F, x2 = F'
        return np.hstack([D[0], D[1]])

    def psi_u(D):
        # (2.92) with damping: tau = m l^2 F'' + d_theta l^2 F' + m g l sin F
        return m * l**2 * D[2] + d_theta * l**2 * D[1] + m * g * l * np.sin(D[0])

    return FlatSystem(name="pendulum", n=2, m=1, order_x=1, order_u=2, phi=phi,
                      psi_x=psi_x, psi_u=psi_u, params=dict(m=m, l=l, g=g, d_theta=d_theta))


def _speed_squared(D, name: str) -> np.ndarray:
    """|F'|^2 of a planar robot, after checking it is away from the zero-speed singularity
    and inside the float range (the turn rate (2.101) divides by it)."""
    dF = D[1]
    speed = np.hypot.reduce(dF, axis=1)   # without overflow in the squares of a fast plan
    scale = max(1.0, float(speed.max()))
    if np.any(speed <= 1e-9 * scale):
        k = int(np.argmin(speed))
        raise ValueError(
            f"the flat parametrization of the {name} is singular at zero speed: at sample {k} "
            f"F' = {dF[k].tolist()}, so |F'| = {float(speed[k]):.3g}, nothing beside the largest "
            f"speed {scale:.3g} on the plan. The heading theta = atan2(F2', F1') (2.97) is "
            "the direction of motion and does not exist when the robot stands still, and the "
            "turn rate (2.101) divides by |F'|^2. Plan with a nonzero speed at both ends "
            "(e.g. plan_robot(..., speed=1.0)) so that F' never vanishes on [0, T]."
        )
    with np.errstate(over="ignore"):
        speed_sq = (speed ** 2)[:, None]
    if not np.isfinite(speed_sq).all():
        raise ValueError(
            f"the planned speed |F'| of the {name} reaches {scale:.3g}, and its square, by which the "
            "turn rate (2.101) divides, leaves the float range: the end pose or the speed is far "
            "too large for the horizon; plan distances and speeds of a physical size (metres, "
            "metres per second)."
        )
    return speed_sq


def _heading(D, sign: float) -> np.ndarray:
    # (2.97) with the quadrant fixed: theta = atan2(s F2', s F1'), s = sign of the speed
    return np.arctan2(sign * D[1][:, 1:2], sign * D[1][:, 0:1])


def _turn_rate(D, speed_sq) -> np.ndarray:
    # (2.101): theta' = (F2'' F1' - F1'' F2') / (F1'^2 + F2'^2)
    return (D[2][:, 1:2] * D[1][:, 0:1] - D[2][:, 0:1] * D[1][:, 1:2]) / speed_sq


def _planar_phi(X):
    # F = (x1, x2), the position (2.95)
    return X[:, :2]


def two_wheeled_flatness(reverse: bool = False) -> FlatSystem:
    """Flat output F = (x1, x2) of the two-wheeled robot (2.94)-(2.102).

    ``theta = atan2(F2', F1')`` ((2.97) with the quadrant fixed; the notes'
    arctan(F2'/F1') is wrong whenever the robot drives in -x1 direction),
    ``u1 = |F'|`` (2.99) and ``u2 = (F2'' F1' - F1'' F2') / |F'|^2`` (2.101).
    With ``reverse=True`` the robot drives backwards: u1 = -|F'| and theta
    is turned by pi (`reverse` must be True or False: ValueError otherwise).
    Singular at zero speed (F' = 0), where a ValueError explains why.
    """
    def turn_rate(D, speed_sq, v):
        # (2.100)-(2.101): u2 = theta'
        return _turn_rate(D, speed_sq)

    return _robot_flatness("two-wheeled robot", reverse, turn_rate, {})


def car_like_flatness(L: float = 2.5, reverse: bool = False) -> FlatSystem:
    """Flat output F = (x1, x2) of the car-like robot (1.11): the exercise of 2.4 solved.

    The first two equations of (1.11) are those of the two-wheeled robot, so
    ``theta = atan2(F2', F1')`` and ``v = |F'|`` as in (2.97)-(2.99), and
    ``theta' = (F2'' F1' - F1'' F2') / |F'|^2`` (2.101). The third equation
    ``theta' = v tan(delta) / L`` then gives the steering angle::

        delta = arctan(L theta' / v) = arctan(L (F2'' F1' - F1'' F2') / (v |F'|^2)),

    i.e. arctan(L kappa) with kappa the curvature of the path. Same
    parameter L [m] as `models.car_like_robot`; singular at zero speed.
    """
    L = as_scalar(L, "L", positive=True)

    def steering(D, speed_sq, v):
        # (1.11): theta' = v tan(delta) / L, so delta = arctan(L theta' / v)
        return np.arctan(L * _turn_rate(D, speed_sq) / v)

    return _robot_flatness("car-like robot", reverse, steering, dict(L=L))


def _robot_flatness(name: str, reverse: bool, second_input: Callable, params: dict) -> FlatSystem:
    """The flat maps shared by both robots; `second_input(D, |F'|^2, v)` gives u2."""
    reverse = as_flag(reverse, "reverse")
    sign = -1.0 if reverse else 1.0

    def psi_x(D):
        _speed_squared(D, name)
        return np.hstack([D[0], _heading(D, sign)])

    def psi_u(D):
        speed_sq = _speed_squared(D, name)
        # (2.99): u1 = +-sqrt(F1'^2 + F2'^2), the sign chosen by the driving direction
        v = sign * np.sqrt(speed_sq)
        return np.hstack([v, second_input(D, speed_sq, v)])

    return FlatSystem(name=name, n=3, m=2, order_x=1, order_u=2, phi=_planar_phi,
                      psi_x=psi_x, psi_u=psi_u, params=dict(params, reverse=reverse))


class FlatPlan:
    """A planned flat output F_d on [0, T] and the state and input it implies.

    Attributes: ``flat`` (the `FlatSystem`), ``horizon`` (T), ``trajectories``
    (one `PolyTrajectory` per flat output). Methods: ``F(t, k=0)`` (shape
    (N, m)), ``x(t)`` and ``u(t)`` from psi_x and psi_u, and ``input(t, x)``
    for `simulate`. Times are clipped to [0, T]: the end values are held.
    """

    def __init__(self, flat: FlatSystem, horizon: float, trajectories: list):
        self.flat = flat
        self.horizon = horizon
        self.trajectories = trajectories
        # smallest planned speed |F'| on [0, T], set by plan_robot
        self.min_speed = None

    def _clip(self, t):
        tt = as_vector(t, "t")
        return np.clip(tt, 0.0, self.horizon), np.ndim(t) == 0

    def F(self, t, k: int = 0) -> np.ndarray:
        """k-th derivative of the planned flat output, shape (N, m) (or (m,) for one time)."""
        tt, single = self._clip(t)
        values = np.column_stack([traj(tt, k) for traj in self.trajectories])
        return values[0] if single else values

    def derivs(self, t, order: int) -> list:
        """[F_d, F_d', ..., F_d^(order)] at the times t, each of shape (N, m)."""
        tt, _ = self._clip(t)
        return [np.column_stack([traj(tt, k) for traj in self.trajectories]) for k in range(order + 1)]

    def x(self, t) -> np.ndarray:
        """Planned state psi_x(F_d, ...) (2.88), shape (N, n)."""
        out = self.flat.psi_x(self.derivs(t, self.flat.order_x))
        return out[0] if np.ndim(t) == 0 else out

    def u(self, t) -> np.ndarray:
        """Feedforward input u_d = psi_u(F_d, ...) (2.89), shape (N, m)."""
        out = self.flat.psi_u(self.derivs(t, self.flat.order_u))
        return out[0] if np.ndim(t) == 0 else out

    def input(self, t, x=None) -> np.ndarray:
        """``u(t, x)`` for `simulate`: open loop, x is ignored (t is clipped to [0, T])."""
        tt = input_time(t, self.horizon)
        # the same maps as u(t), without re-checking the inputs at every solver step
        columns = [traj.derivatives(tt, self.flat.order_u) for traj in self.trajectories]
        D = [np.array([[col[k] for col in columns]]) for k in range(self.flat.order_u + 1)]
        return self.flat._psi_u(D)[0]

    def plot(self, samples: int = 301):
        """Figure of the planned state psi_x and input psi_u on [0, T]; returns the figure."""
        t = plan_grid(self.horizon, samples)
        return plot_plan(t, self.x(t), self.u(t), title=f"flat plan for the {self.flat.name} (2.88)-(2.89)")

    @property
    def x0(self) -> np.ndarray:
        """Planned state at t = 0."""
        return self.x(0.0)

    @property
    def xT(self) -> np.ndarray:
        """Planned state at t = T."""
        return self.x(self.horizon)

    def __repr__(self) -> str:
        return (f"FlatPlan for the {self.flat.name} over [0, {self.horizon:g}]: "
                f"x0 = {np.round(self.x0, 6).tolist()}, xT = {np.round(self.xT, 6).tolist()}")


def _boundary(value, name: str, m: int) -> np.ndarray:
    """Boundary conditions as an (r, m) array: row k is the k-th derivative of F."""
    # the shape only: as_vector / as_matrix reject text, complex, NaN, naming `name`
    if m == 1 and np.ndim(value) <= 1:
        return as_vector(value, name).reshape(-1, 1)
    return as_matrix(value, name, cols=m, cols_why=f"one per flat output (m = {m})")


def plan_flat_output(flat: FlatSystem, T, start, end) -> FlatPlan:
    """Open-loop plan for a flat system (the algorithm of 2.4.2).

    `start` and `end` give F and its first r - 1 derivatives at t = 0 and
    t = T, as an (r, m) array (row k = k-th derivative; a 1-D list when
    m = 1). Each flat output gets the polynomial of degree 2r - 1 of
    `poly_trajectory`; the input is ``u_d = psi_u(F_d, ..., F_d^(n))``.
    Choose r so that the state's boundary values are matched (r > order_x)
    and, for an input without jumps at the ends, one more.

    Check: with r > order_x the plan's x(0), x(T) = psi_x(F_d, F_d', ...)
    (2.88) are compared with psi_x of the requested data; a miss of more than
    1e-6 of the states' size gives an `AccuracyWarning` (as does a trajectory
    missing its own boundary conditions, see `poly_trajectory`).
    """
    if not isinstance(flat, FlatSystem):
        raise ValueError(f"flat must be a FlatSystem (e.g. pendulum_flatness()): received "
                         f"{type(flat).__name__}.")
    T = as_scalar(T, "T", positive=True)
    S = _boundary(start, "start", flat.m)
    E = _boundary(end, "end", flat.m)
    if S.shape != E.shape:
        raise ValueError(f"end must have the shape of start: received {E.shape}, expected {S.shape} "
                         "(the same derivatives at both ends).")
    trajs = [poly_trajectory(T, S[:, j], E[:, j]) for j in range(flat.m)]
    plan = FlatPlan(flat, T, trajs)
    if S.shape[0] > flat.order_x:
        # the states the boundary data ask for: psi_x of the requested F, F', ... (2.88)
        try:
            wanted = [flat.psi_x(list(S)), flat.psi_x(list(E))]
        except ValueError:
            # a singular start or end (a robot at rest): psi_x explains it when x(t) is asked for
            return plan
        _check_flat_plan(plan, "plan_flat_output", *wanted)
    return plan


def _planned_state(plan: FlatPlan, t: float) -> np.ndarray:
    """plan.x(t), or NaN where the planned F_d, F_d', ... are not finite (psi_x refuses them)."""
    try:
        return plan.x(t)
    except ValueError:
        return np.full(plan.flat.n, np.nan)


def _check_flat_plan(plan: FlatPlan, caller: str, x0, xT, *, angle: int | None = None) -> None:
    """Warn unless the plan's x(0), x(T) from psi_x meet the requested x0, xT.

    `angle` is the index of a state compared modulo 2 pi (a heading); the
    others are compared to PLAN_RTOL of the largest requested state.
    """
    got = [_planned_state(plan, t) for t in (0.0, plan.horizon)]
    diffs = [g - w for g, w in zip(got, (x0, xT))]
    if angle is not None:
        for d in diffs:
            d[angle] = np.arctan2(np.sin(d[angle]), np.cos(d[angle]))
    task = max(1.0 if angle is not None else 0.0, np.abs(x0).max(), np.abs(xT).max())
    allowed = PLAN_RTOL * (task if task > 0 else 1.0)
    misses = [float(np.abs(d).max()) for d in diffs]
    if all(miss <= allowed for miss in misses):
        return
    k = int(np.argmax([m if np.isfinite(m) else np.inf for m in misses]))
    when, wanted = ("x(0)", x0) if k == 0 else ("x(T)", xT)
    warn_accuracy(
        f"{caller}: the plan's {when} = psi_x(F_d, F_d', ...) (2.88) is "
        f"{np.array2string(got[k], precision=6)} instead of {np.array2string(wanted, precision=6)}, "
        f"off by {misses[k]:.3g}, more than {PLAN_RTOL:g} of the requested states' size {task:.3g}. "
        "The flat output misses its boundary conditions (see the poly_trajectory warning) or "
        "psi_x amplifies their rounding; try a horizon T nearer 1 in the time unit used or fewer "
        "boundary conditions.",
        stacklevel=4,
    )


def _zero_speed(v0: float, vT: float, pace: float | None = None) -> ValueError:
    """The error for end speeds that are zero (to rounding beside the manoeuvre's `pace`) or of two signs."""
    rounding = ("" if pace is None else f" (a speed within 1e-9 of the manoeuvre's pace, {pace:.3g} m/s "
                "here, is zero to rounding)")
    return ValueError(
        f"speed must be nonzero and of the same sign at both ends: received v0 = {v0:g}, "
        f"vT = {vT:g}{rounding}. A flat plan through zero speed is singular: the heading theta = "
        "atan2(F2', F1') (2.97) is undefined when the robot stands still, so it cannot be set "
        "by the boundary conditions. Start and end moving (e.g. speed=0.5), or turn on the "
        "spot first with u1 = 0, u2 != 0 and plan from there.")


def plan_robot(start, end, T, *, speed=1.0, L: float | None = None) -> FlatPlan:
    """Plan a manoeuvre of the two-wheeled robot (L=None) or of the car-like robot (wheelbase L).

    `start` and `end` are poses (x1, x2, theta) [m, m, rad]; `speed` [m/s]
    is the speed at both ends, or a pair (v0, vT). The flat output
    F = (x1, x2) gets cubic polynomials (2.31)-(2.38) with
    ``F'(0) = v0 (cos theta0, sin theta0)`` and ``F'(T) = vT (cos thetaT, sin thetaT)``,
    so the pose is met at both ends. Both speeds must be nonzero (above 1e-9
    of the manoeuvre's pace max(|end - start| / T, |v0|, |vT|)) and of one
    sign (negative: reversing): at zero speed the heading is undefined (the
    singularity of (2.97)-(2.101)). The smallest planned speed on [0, T] is
    found exactly (roots of d|F'|^2/dt) and stored as ``plan.min_speed``; a
    ValueError explains a plan whose speed vanishes on the way. The planned
    poses at 0 and T are checked against `start` and `end` (heading modulo
    2 pi) and an `AccuracyWarning` says when they miss.
    """
    start = as_vector(start, "start", size=3, why="a pose (x1, x2, theta)")
    end = as_vector(end, "end", size=3, why="a pose (x1, x2, theta)")
    T = as_scalar(T, "T", positive=True)
    v = as_vector(speed, "speed")
    v0, vT = (v[0], v[0]) if v.size == 1 else tuple(as_vector(speed, "speed", size=2, why="(v0, vT)"))
    if v0 == 0 or vT == 0 or np.sign(v0) != np.sign(vT):
        raise _zero_speed(v0, vT)
    reverse = v0 < 0
    flat = two_wheeled_flatness(reverse) if L is None else car_like_flatness(L, reverse)
    S = [start[:2], v0 * np.array([np.cos(start[2]), np.sin(start[2])])]
    E = [end[:2], vT * np.array([np.cos(end[2]), np.sin(end[2])])]
    plan = plan_flat_output(flat, T, S, E)
    # a speed that is rounding beside the manoeuvre's (0 m/s reached in steps of 0.1 from -2: 1.8e-15) is zero:
    # psi_x and psi_u divide by |F'|^2 and would give NaN, not this message
    pace = max(float(np.hypot(*(end[:2] - start[:2]))) / T, abs(v0), abs(vT))
    if min(abs(v0), abs(vT)) <= 1e-9 * pace:
        raise _zero_speed(v0, vT, pace)
    _check_flat_plan(plan, "plan_robot", start, end, angle=2)
    t_min, plan.min_speed = _slowest_point(plan)
    if plan.min_speed <= 1e-6 * max(abs(v0), abs(vT)):
        raise ValueError(
            f"the planned path stops on the way: its speed |F'| is {plan.min_speed:.2g} m/s at "
            f"t = {t_min:.4g} s. There the flat parametrization is singular (the heading (2.97) "
            "is undefined and flips by pi, the turn rate (2.101) divides by zero), so the robot "
            "cannot follow the plan; typical cause: the target lies behind the start and the "
            "path reverses. Add an intermediate pose, change the target heading, or plan "
            "the reversing part separately with a negative speed."
        )
    return plan


def _slowest_point(plan: FlatPlan):
    """(t, |F'(t)|) where the planned speed is smallest on [0, T], from the roots of d|F'|^2/dt."""
    P = np.polynomial.Polynomial
    # F_j as polynomials in the centred time s = 2 t / T - 1; F_j' in s is proportional to F_j' in t
    vel = [P(traj.coeffs).deriv() for traj in plan.trajectories]
    # one common scale (the roots do not change): F' ~ |F(T) - F(0)| or v T, whose square
    # overflows for a horizon such as T = 1e300
    scale = max(float(np.abs(v.coef).max()) for v in vel) or 1.0
    speed_sq = sum((v / scale) * (v / scale) for v in vel)
    roots = speed_sq.deriv().roots()
    s = np.concatenate([[-1.0, 1.0], roots.real[(np.abs(roots.imag) < 1e-9) & (np.abs(roots.real) <= 1)]])
    k = int(np.argmin(speed_sq(s)))
    t = (s[k] + 1.0) * plan.horizon / 2.0
    return float(t), float(np.linalg.norm(plan.F(t, 1)))
