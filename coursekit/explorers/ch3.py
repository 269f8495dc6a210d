"""Explorers of chapter 3: pole placement, the upright pendulum, integral action.

Each explorer is a pure ``*_compute`` function (numbers only, unit-tested)
and a ``*_explorer()`` factory that wires it to sliders.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from .. import models
from .._validation import as_scalar, time_grid
from ..controllers import PendulumLinearizingController, StateFeedback, integral_augment, integral_closed_loop
from ..linearization import linearize
from ..placement import place
from ..simulation import simulate, simulate_batch
from ..systems import StateSpace
from ..stability import format_poles
from ..style import PALETTE, course_subplots, curve_style
from ._base import Explorer, slider
from .limits import Y_EDGE, is_moving, rescale

__all__ = ["pair_poles", "pole_placement_compute", "pole_placement_explorer", "upright_pendulum_compute",
           "upright_pendulum_explorer", "integral_action_compute", "integral_action_explorer"]

#: plant of the pole-placement explorer: (3.22) driven through its first input only
PLACEMENT_A = np.array([[2.0, 0.0, 0.0], [1.0, -1.0, 2.0], [0.0, 2.0, -1.0]])
PLACEMENT_B = np.array([[1.0], [0.0], [0.0]])

#: the largest disturbance the integral-action explorer's slider offers (either sign)
INTEGRAL_D_MAX = 3.0

#: plant of the integral-action explorer: the CCF (3.27) with a0 = 6, a1 = -5
INTEGRAL_A = np.array([[0.0, 1.0], [-6.0, 5.0]])
INTEGRAL_B = np.array([[0.0], [1.0]])


def pair_poles(wn: float, zeta: float) -> np.ndarray:
    """The two roots of s^2 + 2 zeta wn s + wn^2 (complex pair when zeta < 1)."""
    wn, zeta = as_scalar(wn, "wn", positive=True), as_scalar(zeta, "zeta", positive=True)
    if zeta < 1:
        wd = wn * np.sqrt(1 - zeta**2)
        return np.array([-zeta * wn + 1j * wd, -zeta * wn - 1j * wd])
    # sqrt(zeta^2 - 1) without squaring zeta (1e300**2 overflows); the slow root from the
    # product of the roots, wn^2, so it keeps its digits when zeta is large
    fast = -wn * (zeta + np.sqrt(zeta - 1) * np.sqrt(zeta + 1))
    poles = np.array([wn * (wn / fast), fast], dtype=complex)
    if not np.isfinite(poles).all():
        raise ValueError(f"wn and zeta are out of range: wn = {wn:g}, zeta = {zeta:g} give a pole beyond the "
                         "float range (about 2 zeta wn); pick values within the sliders' range.")
    return poles


def _gain_text(K) -> str:
    return "K = [" + ", ".join(f"{k:.3g}" for k in np.ravel(K)) + "]"


def pole_placement_compute(wn: float = 2.0, zeta: float = 0.7, p3: float = -3.0,
                           t_end: float = 6.0, samples: int = 1000) -> dict:
    """Place a pole pair (wn, zeta) and a real pole p3 for the plant (3.22) with input u1.

    K = place(A, B, poles) (3.46)-(3.47); the closed loop A + B K (3.21) is
    simulated exactly from x0 = [1, 0, 0]. Returns ``t``, ``x`` (N, 3),
    ``u`` (N,) = K x, ``K``, ``poles`` (requested), ``achieved``
    (eig(A + B K)), ``open_loop`` (eig A) and ``max_u`` = max |u|.
    """
    p3 = as_scalar(p3, "p3")
    t = time_grid(t_end, samples)
    poles = np.concatenate([pair_poles(wn, zeta), [p3]])
    if np.abs(poles).max() * t[-1] > 1e6:
        raise ValueError(f"wn, zeta and p3 ask for poles up to {np.abs(poles).max():.3g} 1/s: over t_end = "
                         f"{t[-1]:g} s the response would change by e^{np.abs(poles).max() * t[-1]:.3g}; "
                         "pick poles a few times faster than the plant's, within the sliders' range.")
    K = place(PLACEMENT_A, PLACEMENT_B, poles)
    A_cl = PLACEMENT_A + PLACEMENT_B @ K
    x = simulate(StateSpace(A_cl), t, x0=[1.0, 0.0, 0.0]).x
    u = x @ K[0]
    return dict(t=t, x=x, u=u, K=K, poles=poles, achieved=np.linalg.eigvals(A_cl),
                open_loop=np.linalg.eigvals(PLACEMENT_A), max_u=float(np.abs(u).max()))


def pole_placement_explorer() -> Explorer:
    """Sliders for a pole pair (wn, zeta) and a real pole: K, pole plot, x(t) and u(t)."""
    def draw(fig):
        ax_p, ax_x, ax_u = course_subplots(fig, 1, 3, width_ratios=[1, 1.3, 1.3])
        stable = ax_p.axvspan(-1e3, 0, color=PALETTE["bluish green"], alpha=0.12, label="stable (Re < 0)")
        ol, = ax_p.plot([], [], "x", color=PALETTE["vermillion"], ms=10, mew=2, label="open loop eig(A)")
        cl, = ax_p.plot([], [], "o", color=PALETTE["blue"], ms=10, mew=2, fillstyle="none",
                        label="closed loop eig(A + B K)")
        ax_p.axhline(0, color="0.5", lw=0.8)
        ax_p.axvline(0, color="0.5", lw=0.8)
        ax_p.set(xlim=(-12, 4), ylim=(-8, 8), xlabel="real part [1/s]", ylabel="imaginary part [rad/s]",
                 title="poles")
        xs = [ax_x.plot([], [], label=f"x{i + 1}", **curve_style(i))[0] for i in range(3)]
        ax_x.set(xlabel="time t [s]", ylabel="state x (dimensionless)", title="response from x0 = [1, 0, 0]")
        u, = ax_u.plot([], [], color=PALETTE["black"], label="u = K x")
        ax_u.set(xlabel="time t [s]", ylabel="control effort u", title="control effort u(t)")
        # one legend below the figure, where it hides no pole or curve whatever the sliders say and
        # is drawn with the background (a "best" place in the axes was searched at every frame)
        # (filled column by column: the poles and u in the first row, the states in the second)
        fig.legend(handles=[stable, xs[0], ol, xs[1], cl, xs[2], u], loc="outside lower center", ncols=4,
                   fontsize="small")
        for ax in (ax_p, ax_x, ax_u):
            ax.grid(True, alpha=0.4)
        return dict(ax_p=ax_p, ax_x=ax_x, ax_u=ax_u, ol=ol, cl=cl, xs=xs, u=u)

    def update(h, r):
        h["ol"].set_data(r["open_loop"].real, r["open_loop"].imag)
        h["cl"].set_data(r["achieved"].real, r["achieved"].imag)
        h["ax_p"].set_xlim(min(-12.0, 1.15 * r["achieved"].real.min()), 4.0)
        for i, line in enumerate(h["xs"]):
            line.set_data(r["t"], r["x"][:, i])
        h["u"].set_data(r["t"], r["u"])
        for ax in (h["ax_x"], h["ax_u"]):
            ax.set_xlim(0, r["t"][-1])
        rescale(h["ax_x"], h["ax_u"])

    def readout(r):
        return (f"{_gain_text(r['K'])}, max |u| = {r['max_u']:.3g}\n"
                f"closed-loop poles eig(A + B K) = {format_poles(r['achieved'])}; "
                f"open loop eig(A) = {format_poles(r['open_loop'])}")

    return Explorer(
        title="Pole placement (3.46)-(3.47) for the plant (3.22) driven by u1 only",
        controls=dict(wn=slider(2.0, 0.5, 6.0, 0.25, "pair: natural frequency wn [rad/s]"),
                      zeta=slider(0.7, 0.1, 2.0, 0.05, "pair: damping ratio zeta"),
                      p3=slider(-3.0, -10.0, -0.5, 0.25, "real pole p3 [1/s]")),
        compute=pole_placement_compute, draw=draw, update=update, readout=readout, figsize=(13, 4.5))


def _saturated(ctrl, u_max: float):
    """The controller with its torque clipped to [-u_max, u_max] (an actuator limit)."""
    return lambda t, x: np.clip(ctrl(t, x), -u_max, u_max)


@cache
def _upright_linearization() -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of the pendulum (m = l = 1, g = 9.81) at theta* = pi, u* = 0 (3.74).

    The same for every slider setting, so computed once: `linearize` spends a
    few milliseconds on its checked derivatives, a quarter of a redraw budget.
    The arrays are read-only, so no caller can change the cached values.
    """
    A, B = linearize(models.pendulum(), np.array([np.pi, 0.0]), np.array([0.0]))
    A.flags.writeable = B.flags.writeable = False
    return A, B


def upright_pendulum_compute(theta0_deg: float = 30.0, pole: float = -2.0, u_max: float = 50.0,
                             t_end: float = 5.0, samples: int = 500) -> dict:
    """Hold the pendulum (m = l = 1, g = 9.81, no damping) upright, theta* = pi.

    Both controllers place the poles at ``[pole, pole - 1]``: the linear
    law u = K (x - x*) + u* (3.92) with K from the linearization (3.74),
    and the feedback-linearizing law (3.154) measured from theta = pi. Both
    torques are clipped to |u| <= `u_max` [N m] (a motor limit; the notes
    have none). Start: theta = pi + `theta0_deg` (in degrees), at rest, so the
    deviations from upright ``dev_linear`` and ``dev_fl`` = theta - pi [deg] start at
    `theta0_deg`, in its sign. Returns ``t``, the deviations,
    the torques ``u_linear`` and ``u_fl`` [N m], ``K`` and booleans
    ``linear_ok`` / ``fl_ok`` (ends within 1 degree of upright, any turn).
    """
    theta0 = np.deg2rad(as_scalar(theta0_deg, "theta0_deg"))
    pole = as_scalar(pole, "pole")
    u_max = as_scalar(u_max, "u_max", positive=True)
    if pole >= 0:
        raise ValueError(f"pole must be negative (a stable closed loop): received {pole!r}.")
    t = time_grid(t_end, samples)
    P = models.pendulum()
    x_eq, u_eq = np.array([np.pi, 0.0]), np.array([0.0])
    poles = [pole, pole - 1.0]
    A, B = _upright_linearization()
    K = place(A, B, poles)
    controllers = dict(linear=StateFeedback(K, x_eq, u_eq),
                       fl=PendulumLinearizingController(poles, theta_ref=np.pi))
    out = dict(t=t, K=K, theta0_deg=float(np.rad2deg(theta0)), u_max=u_max)
    laws = [_saturated(ctrl, u_max) for ctrl in controllers.values()]

    def u_batch(tk, X):
        # both loops in one stacked ODE: column j of X is driven by controller j
        return np.column_stack([law(tk, X[:, j]) for j, law in enumerate(laws)])

    x0 = [np.pi + theta0, 0.0]             # theta - pi = theta0: the slider's angle, its sign
    X = simulate_batch(P, t, [x0, x0], u=u_batch, rtol=1e-6, atol=1e-8)
    for j, (name, law) in enumerate(zip(controllers, laws)):
        x = X[:, j]
        dev = np.rad2deg(x[:, 0] - np.pi)
        # the torque along the trajectory (the controllers take all samples at once)
        out[f"dev_{name}"], out[f"u_{name}"] = dev, law(t, x.T)[0]
        wrapped = (dev[-1] + 180.0) % 360.0 - 180.0
        out[f"{name}_ok"] = bool(abs(wrapped) < 1.0 and abs(x[-1, 1]) < 0.1)
    return out


def _eighth_turns(degrees) -> tuple[float, float]:
    """Limits of an angle axis for the angles `degrees` (with 0, upright): out to whole eighth
    turns (45 deg; rounding noise of 1e-9 deg is not a turn), then by `Y_EDGE` of their span."""
    low = 45.0 * np.floor(min(0.0, degrees.min()) / 45.0 + 1e-6)
    high = 45.0 * np.ceil(max(0.0, degrees.max()) / 45.0 - 1e-6)
    if high - low < 45.0:                    # upright all along: an eighth turn either way
        low, high = -45.0, 45.0
    return low - Y_EDGE * (high - low), high + Y_EDGE * (high - low)


def upright_pendulum_explorer() -> Explorer:
    """Sliders for the initial angle and the pole speed: linear vs feedback-linearizing control."""
    def draw(fig):
        ax_th, ax_u = course_subplots(fig, 1, 2)
        lin, = ax_th.plot([], [], label="linear u = K(x - x*) (3.92)", **curve_style(0))
        fl, = ax_th.plot([], [], label="feedback linearizing (3.154)", **curve_style(1))
        ax_th.axhline(0, color="0.5", lw=0.8)
        ax_th.set(xlabel="time t [s]", ylabel="theta - pi [deg]", title="angle from upright")
        ulin, = ax_u.plot([], [], **curve_style(0))
        ufl, = ax_u.plot([], [], **curve_style(1))
        ax_u.set(xlabel="time t [s]", ylabel="torque u [N m]", title="control torque")
        # one legend for both axes, below them, where it hides no curve
        fig.legend(handles=[lin, fl], loc="outside lower center", ncols=2, fontsize="small")
        for ax in (ax_th, ax_u):
            ax.grid(True, alpha=0.4)
        return dict(ax_th=ax_th, ax_u=ax_u, lin=lin, fl=fl, ulin=ulin, ufl=ufl)

    def update(h, r):
        h["lin"].set_data(r["t"], r["dev_linear"])
        h["fl"].set_data(r["t"], r["dev_fl"])
        h["ulin"].set_data(r["t"], r["u_linear"])
        h["ufl"].set_data(r["t"], r["u_fl"])
        for ax in (h["ax_th"], h["ax_u"]):
            ax.set_xlim(0, r["t"][-1])
        # limits a step of the initial angle keeps (a blitted frame, not a full draw): the angles
        # out to whole eighth turns, and the torque limit (the torques are clipped to it)
        low, high = _eighth_turns(np.r_[r["dev_linear"], r["dev_fl"]])
        if is_moving():     # a hand drags: the angle axis only grows (each eighth turn was a full draw)
            shown = h["ax_th"].get_ylim()
            low, high = min(low, shown[0]), max(high, shown[1])
        h["ax_th"].set_ylim(low, high)
        h["ax_u"].relim()
        h["ax_u"].update_datalim([[0.0, -r["u_max"]], [0.0, r["u_max"]]])
        rescale(h["ax_u"], relim=False, fill=0.9)

    def readout(r):
        def told(name):
            ok = "upright" if r[f"{name}_ok"] else "NOT upright"
            return f"{ok}, peak |u| {np.max(np.abs(r[f'u_{name}'])):.3g} N m"
        return (f"start {r['theta0_deg']:g} deg from upright, |u| <= {r['u_max']:g} N m, K = {_gain_text(r['K'])[4:]}\n"
                f"linear: {told('linear')}; feedback linearizing: {told('fl')}")

    return Explorer(
        title="Upright pendulum (m = l = 1, g = 9.81): linear feedback vs feedback linearization",
        controls=dict(theta0_deg=slider(30.0, -180.0, 180.0, 5.0, "initial angle from upright [deg]"),
                      pole=slider(-2.0, -6.0, -0.5, 0.25, "closed-loop poles [pole, pole - 1]"),
                      u_max=slider(50.0, 2.0, 60.0, 1.0, "torque limit |u| <= [N m]")),
        compute=upright_pendulum_compute, draw=draw, update=update, readout=readout, figsize=(12, 4.5))


def integral_action_compute(d: float = 1.0, integral_pole: float = -1.0, t_end: float = 12.0,
                            samples: int = 1200) -> dict:
    """Constant input disturbance d from t = 1 s on the CCF (3.27) (a0 = 6, a1 = -5).

    Plain state feedback u = K x places eig(A + B K) at -1, -2 (3.31)-(3.37) and
    keeps the offset (3.109); with an integrator on x1 the augmented poles
    are -1, -2 and `integral_pole` and the offset goes to zero. Returns
    ``t``, ``y_plain``, ``y_int`` (= x1), ``u_plain``, ``u_int``, the gains
    ``K`` and ``K_E`` (= [k_I, k1, k2]), the predicted ``offset`` of plain feedback, and
    ``y_per_d`` / ``u_per_d``, the largest |y| and |u| of both loops per unit of d (the
    responses are linear in d).
    """
    d = as_scalar(d, "d")
    integral_pole = as_scalar(integral_pole, "integral_pole")
    if integral_pole >= 0:
        raise ValueError(f"integral_pole must be negative: received {integral_pole!r}.")
    t = time_grid(t_end, samples)
    A, B = INTEGRAL_A, INTEGRAL_B
    K = place(A, B, [-1.0, -2.0])
    A_E, B_E = integral_augment(A, B)
    K_E = place(A_E, B_E, [-1.0, -2.0, integral_pole])
    # both loops are linear and start at rest: their responses to d are d times those to d = 1
    unit = np.where(t >= 1.0, 1.0, 0.0)
    plain = simulate(StateSpace(A + B @ K, B), t, unit.reshape(-1, 1))
    loop = integral_closed_loop(A, B, K_E)
    integ = simulate(loop, t, np.column_stack([unit, np.zeros_like(t)]))
    # (3.109) for the state vector: x_inf = -(A + B K)^-1 B d
    offset = float(-np.linalg.solve(A + B @ K, B[:, 0] * d)[0])
    y_unit = np.column_stack([plain.x[:, 0], integ.y[:, 0]])
    u_unit = np.column_stack([plain.x @ K[0], integ.x @ K_E[0]])
    return dict(t=t, y_plain=d * y_unit[:, 0], y_int=d * y_unit[:, 1], u_plain=d * u_unit[:, 0],
                u_int=d * u_unit[:, 1], K=K, K_E=K_E, offset=offset, d=d,
                y_per_d=float(np.abs(y_unit).max()), u_per_d=float(np.abs(u_unit).max()))


def integral_action_explorer() -> Explorer:
    """Sliders for the disturbance size and the integral pole: offset with and without integrator."""
    def draw(fig):
        ax_y, ax_u = course_subplots(fig, 1, 2)
        plain_style, integral_style = curve_style(0), curve_style(1)
        plain, = ax_y.plot([], [], label="state feedback u = K x (offset 3.109)", **plain_style)
        integ, = ax_y.plot([], [], label="with integral action u = K x + k_I int x1 (3.117)", **integral_style)
        off = ax_y.axhline(0, color=PALETTE["blue"], ls=":", label="predicted offset (3.109)")
        ax_y.axvline(1.0, color="0.5", ls="--", lw=0.8)
        ax_y.set(xlabel="time t [s]", ylabel="output y = x1", title="output after the disturbance at t = 1 s")
        uplain, = ax_u.plot([], [], **plain_style)
        uint, = ax_u.plot([], [], **integral_style)
        ax_u.set(xlabel="time t [s]", ylabel="control input u", title="input u (integral action ends at -d)")
        # one legend for both axes, below them, where it hides no curve
        fig.legend(handles=[plain, integ, off], loc="outside lower center", ncols=2, fontsize="small")
        for ax in (ax_y, ax_u):
            ax.grid(True, alpha=0.4)
        return dict(ax_y=ax_y, ax_u=ax_u, plain=plain, integ=integ, off=off, uplain=uplain, uint=uint)

    def update(h, r):
        h["plain"].set_data(r["t"], r["y_plain"])
        h["integ"].set_data(r["t"], r["y_int"])
        h["off"].set_ydata([r["offset"], r["offset"]])
        h["uplain"].set_data(r["t"], r["u_plain"])
        h["uint"].set_data(r["t"], r["u_int"])
        # axes that hold the largest disturbance of the slider: the response visibly grows with d
        d_max = INTEGRAL_D_MAX
        h["ax_y"].set_xlim(r["t"][0], r["t"][-1])
        h["ax_u"].set_xlim(r["t"][0], r["t"][-1])
        h["ax_y"].set_ylim(-d_max * r["y_per_d"], d_max * r["y_per_d"])
        h["ax_u"].set_ylim(-d_max * r["u_per_d"], d_max * r["u_per_d"])

    def readout(r):
        return (f"step disturbance d = {r['d']:g} at t = 1 s: offset of plain feedback {r['offset']:.3g}\n"
                f"K = [{', '.join(f'{k:.3g}' for k in r['K'][0])}], "
                f"K_E = [{', '.join(f'{k:.3g}' for k in r['K_E'][0])}]")

    return Explorer(
        title="Integral action (3.110)-(3.120) on the CCF (3.27), a0 = 6, a1 = -5",
        controls=dict(d=slider(1.0, -INTEGRAL_D_MAX, INTEGRAL_D_MAX, 0.1, "disturbance d"),
                      integral_pole=slider(-1.0, -6.0, -0.2, 0.1, "integral pole [1/s]")),
        compute=integral_action_compute, draw=draw, update=update, readout=readout, figsize=(12, 4.5))
