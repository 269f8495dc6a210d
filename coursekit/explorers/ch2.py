"""Explorers of chapter 2: a rest-to-rest trajectory planner and a robot path planner.

Each explorer is a pure ``*_compute`` function (numbers only, unit-tested)
and a ``*_explorer()`` factory that wires it to sliders.
"""

from __future__ import annotations

import math

import numpy as np

from .. import models
from .._validation import MAX_SPAN, as_scalar, as_series, as_time_grid, as_vector, time_grid
from ..flatness import plan_robot
from ..simulation import simulate
from ..style import PALETTE, course_subplots, curve_style
from ..trajectory import feedforward, poly_trajectory
from ._base import Explorer, int_slider, slider
from .limits import Y_EDGE, is_moving, rescale, round_value

__all__ = ["planner_compute", "time_shown", "planner_explorer", "robot_planner_compute",
           "robot_planner_explorer", "drive_robot"]

#: the plant of the trajectory planner: mass-spring-damper (2.27) [kg, N s/m, N/m]
PLANNER_PLANT = dict(m=1.0, d=0.5, k=2.0)
#: the largest target coordinate [m] and end speed [m/s] of the robot planner (sliders: 6 m, 2 m/s)
ROBOT_RANGE = 1e6
#: the robot planner's targets lie in [-TARGET_MAX, TARGET_MAX] along x1 and x2 [m] (its sliders)
TARGET_MAX = 6.0
#: height over width of the robot planner's path axes (x1 and x2 drawn on one scale)
PATH_BOX = 0.75


def planner_compute(T: float = 3.0, target: float = 1.0, mass_error: float = 0.0, r: int = 2,
                    samples: int = 1000) -> dict:
    """Rest-to-rest move of the mass-spring-damper from y = 0 to y = `target` [m] in `T` [s].

    Plans the polynomial of degree 2r - 1 with y_d(0) = 0, y_d(T) = target and
    derivatives 1..r-1 zero at both ends (r = 2: the cubic (2.40); r = 3 also
    makes the acceleration, hence u_d, continuous at 0 and T), computes
    u_d = k y_d + d y_d' + m y_d'' (2.30), i.e. (2.25) with a = [k/m, d/m],
    b = 1/m, and applies it to the plant whose mass is off by `mass_error`
    percent, then holds u = k target from T to `time_shown` (T) (2 T to 3 T).
    The two parts are simulated one after the other, so the jump of the
    cubic's u_d at T is taken exactly. Returns ``t, yd, ud, y`` (time-major
    arrays over `samples` times, T one of them),
    ``end_error`` = |y(T) - target| and the parameters.
    """
    T = as_scalar(T, "T", positive=True)
    target = as_scalar(target, "target")
    mass_error = as_scalar(mass_error, "mass_error")
    if mass_error <= -100.0:
        raise ValueError(f"mass_error must be above -100 %: received {mass_error!r} (the plant's mass "
                         "would be zero or negative).")
    m, d, k = PLANNER_PLANT["m"], PLANNER_PLANT["d"], PLANNER_PLANT["k"]
    r = int(as_scalar(r, "r", positive=True, integer=True, limit=20,
                      limit_why="poly_trajectory is exact to rounding for up to 20 conditions per end"))
    if r < 2:
        raise ValueError(f"r must be >= 2: received {r}; the two states y, y' need two boundary "
                         "conditions at each end (2.31).")
    zeros = [0.0] * (r - 1)
    traj = poly_trajectory(T, [0.0] + zeros, [target] + zeros)
    ud = feedforward([k / m, d / m], 1.0 / m, traj)
    end = time_grid(time_shown(T), samples, t_end_name="T")[-1]    # checks the span and `samples`
    before = max(2, round((samples - 1) * T / end) + 1)               # samples on [0, T], the rest after
    t_plan, t_held = np.linspace(0.0, T, before), np.linspace(T, end, max(2, samples - before + 1))
    u_plan, after = ud(t_plan), np.ones(t_held.size - 1)
    plant = models.mass_spring_damper(m=m * (1.0 + mass_error / 100.0), d=d, k=k)
    planned = simulate(plant, t_plan, u=u_plan.reshape(-1, 1)).x
    # after T the plan holds y_d = target, so u_d = k * target: a step of u where r = 2
    held = simulate(plant, t_held - T, u=np.full((t_held.size, 1), k * target), x0=planned[-1]).x
    return dict(t=np.concatenate([t_plan, t_held[1:]]), yd=np.concatenate([traj(t_plan), target * after]),
                ud=np.concatenate([u_plan, k * target * after]), y=np.concatenate([planned[:, 0], held[1:, 0]]),
                end_error=float(abs(planned[-1, 0] - target)), T=T, target=target, mass_error=mass_error, r=r)


def time_shown(T: float) -> float:
    """How long the trajectory planner shows the move of horizon `T`: 2 T rounded up to a multiple
    of the largest of 1, 2, 5 times a power of ten not above T, so 2 T to 3 T (T = 3 s: 6 s;
    3.1 s to 4 s: 8 s). Ten ends cover T from 0.5 s to 10 s, so a step of the T slider keeps
    the time axis (a redraw of the curves alone) but where 2 T passes one of them."""
    T = as_scalar(T, "T", positive=True, limit=MAX_SPAN / 3,
                  limit_why=f"the move is shown for up to 3 T, and a time grid spans at most {MAX_SPAN:g} s")
    step = round_value(T)
    return math.ceil(2.0 * T / step - 1e-9) * step


def planner_explorer() -> Explorer:
    """Sliders for the horizon T, the target and a mass error: y_d, u_d and the simulated y."""
    def draw(fig):
        # one time axis for both, kept equal by update: not sharex, whose label placement measures
        # the other axes' tick labels too, at each full draw (a step of T across a `time_shown` end)
        ax_y, ax_u = course_subplots(fig, 2, 1)
        ax_y.tick_params(labelbottom=False)
        yd, = ax_y.plot([], [], color=PALETTE["black"], linestyle="--", label="planned y_d")
        y, = ax_y.plot([], [], label="simulated y", **curve_style(0))
        ax_y.set_ylabel("position y [m]")
        ax_y.grid(True, alpha=0.4)
        ud, = ax_u.plot([], [], label="u_d (2.30), held at k y(T) after T", **curve_style(1))
        ax_u.set_ylabel("force u [N]")
        ax_u.set_xlabel("time t [s]")
        ax_u.grid(True, alpha=0.4)
        # one legend below both axes, where it hides no curve (two beside them took a fifth of a
        # full draw, and a step of T across a `time_shown` end is one: the time axis moves)
        fig.legend(handles=[yd, y, ud], loc="outside lower center", ncols=3, fontsize="small")
        marks = [ax.axvline(0, color="0.5", linestyle=":") for ax in (ax_y, ax_u)]
        # y=1: atop the axes, where matplotlib puts it with no tick labels or offset text above,
        # not searched for again at each full draw (7 % of one)
        ax_y.set_title("planned and simulated position (dotted: the horizon T)", y=1.0)
        for line in (yd, y, ud):
            line.sticky_edges.x.append(0.0)    # time starts at 0: no room before it
        return dict(ax_y=ax_y, ax_u=ax_u, yd=yd, y=y, ud=ud, marks=marks)

    def update(h, r):
        h["yd"].set_data(r["t"], r["yd"])
        h["y"].set_data(r["t"], r["y"])
        h["ud"].set_data(r["t"], r["ud"])
        for line in h["marks"]:
            line.set_xdata([r["T"], r["T"]])
        rescale(h["ax_y"], h["ax_u"])
        rescale(h["ax_u"], axis="x", fill=1.0)   # the time axis: exactly [0, time_shown(T)] at rest
        h["ax_y"].set_xlim(h["ax_u"].get_xlim())

    def readout(r):
        speed = np.abs(np.gradient(r["yd"], r["t"]))
        fastest = int(np.argmax(speed))
        return (f"degree {2 * r['r'] - 1} move to {r['target']:g} m in T = {r['T']:g} s, "
                f"mass error {r['mass_error']:g} %\nplanned peak speed {speed[fastest]:.3g} m/s at "
                f"t = {r['t'][fastest]:.2g} s, peak force {np.max(np.abs(r['ud'])):.3g} N, "
                f"|y(T) - target| = {r['end_error']:.2g} m")

    return Explorer(
        title="Trajectory planner (2.30), (2.40): mass-spring-damper m = 1 kg, d = 0.5 N s/m, k = 2 N/m",
        controls=dict(T=slider(3.0, 0.5, 10.0, 0.1, "horizon T [s]"),
                      target=slider(1.0, -2.0, 2.0, 0.1, "target y(T) [m]"),
                      mass_error=slider(0.0, -30.0, 30.0, 1.0, "mass error [%]"),
                      r=int_slider(2, 2, 4, "boundary conditions r")),
        compute=planner_compute, draw=draw, update=update, readout=readout, figsize=(9, 6))


def robot_planner_compute(x_T: float = 4.0, y_T: float = 2.0, heading_deg: float = 90.0,
                          T: float = 6.0, speed: float = 1.0, samples: int = 500) -> dict:
    """Flat plan for the two-wheeled robot (2.94)-(2.102) from (0, 0, 0) to (x_T, y_T, heading).

    Uses `plan_robot` (cubic F = (x1, x2) with speed `speed` [m/s] at both
    ends) and drives the plan open loop on the nonlinear model (1.10), with
    the input u_d = psi_u sampled at the `samples` times and linear in between.
    Returns the planned ``path`` and the ``driven`` path (shape (N, 3):
    x1, x2, theta), the inputs ``u`` (N, 2), ``end_error`` (distance [m]
    between driven and target position), ``min_speed`` and ``message``.
    When the plan is singular (zero speed), the paths are empty and
    ``message`` says why.
    """
    # a manoeuvre of metres: far beyond, |F'|^2 leaves the float range and the planner's
    # message about a singular plan would be the wrong explanation
    room = dict(limit=ROBOT_RANGE, limit_why="the robot plans manoeuvres of metres at walking speed")
    x_T, y_T = as_scalar(x_T, "x_T", **room), as_scalar(y_T, "y_T", **room)
    heading = np.deg2rad(as_scalar(heading_deg, "heading_deg"))
    T = as_scalar(T, "T", positive=True)
    speed = as_scalar(speed, "speed", **room)
    t = time_grid(T, samples, t_end_name="T")
    target = np.array([x_T, y_T, heading])
    empty = np.empty((0, 3))
    try:
        plan = plan_robot([0.0, 0.0, 0.0], target, T, speed=speed)
    except ValueError as err:
        return dict(t=t, path=empty, driven=empty, u=np.empty((0, 2)), end_error=float("nan"),
                    min_speed=0.0, target=target, T=T, message=str(err).split(":")[0])
    u = plan.u(t)
    # the input samples, linear in between (as a digital controller replays them), drive the model
    driven = drive_robot(t, u, plan.x0)
    end_error = float(np.hypot(*(driven[-1, :2] - target[:2])))
    return dict(t=t, path=plan.x(t), driven=driven, u=u, end_error=end_error,
                min_speed=plan.min_speed, target=target, T=T,
                message=f"end error {end_error:.1e} m, min speed {plan.min_speed:.2f} m/s")


def drive_robot(t, u, x0) -> np.ndarray:
    """Drive the two-wheeled robot (1.10) with inputs linear between the samples; (N, 3) states.

    Exact up to rounding, and a hundred times faster than a general ODE solver,
    because (1.10) is a cascade: theta' = u2 does not depend on the position,
    so with u2 linear on each interval theta is quadratic there (found in closed
    form), and x1' = u1 cos(theta), x2' = u1 sin(theta) are integrals of known
    smooth functions, taken on each interval by 5-point Gauss-Legendre
    quadrature (exact for polynomials of degree 9). On the planner's inputs,
    even where the robot turns by a radian within one interval, this agrees
    with 16-point quadrature to 1e-13, while ``simulate`` (an adaptive ODE
    solver, stepping across the input's kinks) stays about 1e-8 away even at
    ``rtol=1e-13``.
    """
    t = as_time_grid(t, "t")
    u = as_series(u, "u", samples=t.size, channels=2, channels_why="u1 (speed) and u2 (turn rate)")
    x0 = as_vector(x0, "x0", size=3, why="x1, x2, theta")
    h = np.diff(t)[:, None]
    nodes, weights = np.polynomial.legendre.leggauss(5)
    s, w = (nodes + 1.0) / 2.0, weights / 2.0          # on [0, 1]
    turn = u[:, 1]
    theta = x0[2] + np.concatenate([[0.0], np.cumsum(np.diff(t) * (turn[:-1] + turn[1:]) / 2.0)])
    # on [t_k, t_k + h]: theta = theta_k + h (u2_k s + (u2_k+1 - u2_k) s^2 / 2), u = u_k + (u_k+1 - u_k) s
    theta_s = theta[:-1, None] + h * (turn[:-1, None] * s + np.diff(turn)[:, None] * s**2 / 2.0)
    inputs_s = u.T[:, :-1, None] + np.diff(u, axis=0).T[:, :, None] * s    # (2, N-1, nodes)
    # the model's own rates (1.10) at the nodes; x1', x2' do not depend on the position (0 here)
    states_s = np.stack([np.zeros_like(theta_s), np.zeros_like(theta_s), theta_s])
    rates = models.two_wheeled_robot().f(states_s, inputs_s)[:2]
    steps = h * (rates @ w).T
    position = x0[:2] + np.concatenate([[[0.0, 0.0]], np.cumsum(steps, axis=0)])
    return np.column_stack([position, theta])


def _arrow_tip(points, tx: float, ty: float, th: float) -> np.ndarray:
    """Where the target-pose arrow ends, about: the quiver draws it a twelfth of the view's
    width long, and with equal scales the view is at most about 1.5 times as wide as it is
    high; so the data limits hold the arrow too."""
    span = np.ptp(points, axis=0)
    length = max(span[0], 1.5 * span[1], 1.0) / 10.0
    return np.array([[tx + length * np.cos(th), ty + length * np.sin(th)]])


def _rescale_off_ticks(ax, names: str, **kwargs) -> None:
    """`rescale` of the axes `names` ("x", "y" or "xy"), and limits it changed moved out by 5 % of
    their span: at rest it rounds them to a round step, where a tick falls on the frame and, at a
    corner, the first tick labels of the two axes meet (large fonts). Limits kept stay as they are."""
    before = {name: getattr(ax, f"get_{name}lim")() for name in names}
    rescale(ax, axis="both" if names == "xy" else names, **kwargs)
    for name, old in before.items():
        low, high = getattr(ax, f"get_{name}lim")()
        if (low, high) != old:
            getattr(ax, f"set_{name}lim")(low - 0.05 * (high - low), high + 0.05 * (high - low))


def _scope_range(ax, values, *, share: float = 0.1) -> None:
    """The vertical view of `ax` for `values` as an oscilloscope's range switch sets it: each end at
    the smallest of 1, 2, 5 times a power of ten at least 1.05 times the data's reach that side of
    0 and `share` of the other end, then `Y_EDGE` of the span out. For data whose size changes by
    decades as a slider moves (the turn rate: 0.5 to 80 rad/s), where `rescale`'s round steps move
    at nearly every step: these move about 3 times a decade. While a control moves, `rescale`'s
    growing limits; no finite value: kept."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if is_moving():
        return rescale(ax)
    if values.size == 0:
        return
    top, bottom = 1.05 * max(values.max(), 0.0), 1.05 * max(-values.min(), 0.0)
    high, low = (round_value(end, up=True) if end > 0 else 0.0
                 for end in (max(top, share * bottom), max(bottom, share * top)))
    if high == low == 0.0:
        high = low = 1.0
    edge = Y_EDGE * (high + low)
    ax.set_ylim(-low - edge, high + edge)


def _same_scale(ax) -> None:
    """Widen the narrower of the axes' limits about its middle, so that a metre is as long on
    x2 as on x1 in the box of fixed aspect: limits set from the data alone (`rescale`), not by
    matplotlib's equal aspect, which adjusts them at each draw from where the layout put the
    axes (the figure of a setting then depended on the figures drawn before)."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    ratio = ax.get_box_aspect()
    if (y1 - y0) < ratio * (x1 - x0):
        half = ratio * (x1 - x0) / 2
        ax.set_ylim((y0 + y1) / 2 - half, (y0 + y1) / 2 + half)
    else:
        half = (y1 - y0) / ratio / 2
        ax.set_xlim((x0 + x1) / 2 - half, (x0 + x1) / 2 + half)


def robot_planner_explorer() -> Explorer:
    """Sliders for the target pose: planned path (flatness) and the path the robot drives."""
    def draw(fig):
        ax, ax_u = course_subplots(fig, 1, 2, width_ratios=[1.3, 1])
        path, = ax.plot([], [], color=PALETTE["black"], linestyle="--", label="planned path F_d")
        driven, = ax.plot([], [], alpha=0.8, label="driven (model 1.10)", **curve_style(0))
        goal = ax.quiver([0.0], [0.0], [1.0], [0.0], color=PALETTE["vermillion"], scale=12, label="target pose",
                         zorder=3)
        ax.plot([0], [0], "ko")
        ax.set_xlabel("x1 [m]")
        ax.set_ylabel("x2 [m]")
        ax.set_box_aspect(PATH_BOX)         # its limits keep x1 and x2 on one scale (_same_scale)
        ax.set_title("path in the plane")
        ax.grid(True, alpha=0.4)
        u1, = ax_u.plot([], [], label="speed u1 [m/s]", **curve_style(0))
        u2, = ax_u.plot([], [], label="turn rate u2 [rad/s]", **curve_style(1))
        for line in (u1, u2):
            line.sticky_edges.x.append(0.0)    # time starts at 0: no room before it
        ax_u.set_xlabel("time t [s]")
        ax_u.set_ylabel("u1 [m/s], u2 [rad/s]")
        ax_u.set_title("inputs psi_u (2.102)")
        # one legend below the axes: out of the data, drawn with the background, not at every
        # frame (a "best" place inside the axes was searched anew at each frame: half its time)
        fig.legend(handles=[path, driven, goal, u1, u2], loc="outside lower center", ncols=3,
                   fontsize="small")
        ax_u.grid(True, alpha=0.4)
        return dict(ax=ax, ax_u=ax_u, path=path, driven=driven, goal=goal, u1=u1, u2=u2)

    def update(h, r):
        h["path"].set_data(r["path"][:, 0], r["path"][:, 1])
        h["driven"].set_data(r["driven"][:, 0], r["driven"][:, 1])
        tx, ty, th = r["target"]
        h["goal"].set_offsets([[tx, ty]])
        h["goal"].set_UVC([np.cos(th)], [np.sin(th)])
        tu = r["t"][:r["u"].shape[0]]
        h["u1"].set_data(tu, r["u"][:, 0])
        h["u2"].set_data(tu, r["u"][:, 1])
        # the turn rate spans decades over the targets (0.5 rad/s ahead, 80 behind): limits from the
        # 1-2-5 series, which a step of a target keeps (5 changes over x_T's 25 values, not 18)
        _scope_range(h["ax_u"], r["u"])
        rescale(h["ax_u"], axis="x", fill=1.0)   # the time axis: exactly [0, T] at rest
        # the data limits of the path axes from its points, start and target: not relim(), which
        # in newer matplotlib counts the arrow at a place that moves with the view, so the view
        # would widen at every update; and the corners of the targets' square, so a step of a
        # target keeps the plane's limits (a blitted frame, not a full draw) while the paths stay in it
        h["ax"].ignore_existing_data_limits = True
        corners = TARGET_MAX * np.array([[-1.0, -1.0], [1.0, 1.0]])
        points = np.vstack([r["path"][:, :2], r["driven"][:, :2], [[0.0, 0.0], [tx, ty]], corners])
        tip = _arrow_tip(points, tx, ty, th)
        h["ax"].update_datalim(np.vstack([points, tip]))
        _rescale_off_ticks(h["ax"], "xy", relim=False, fill=0.9)
        _same_scale(h["ax"])

    def readout(r):
        tx, ty, th = r["target"]
        return (f"two-wheeled robot to ({tx:g} m, {ty:g} m, {np.rad2deg(th):g} deg) in {r['T']:g} s\n"
                f"{r['message']}")

    return Explorer(
        title="Two-wheeled robot planner (2.94)-(2.102): flat outputs F = (x1, x2)",
        controls=dict(x_T=slider(4.0, -TARGET_MAX, TARGET_MAX, 0.5, "target x1 [m]"),
                      y_T=slider(2.0, -TARGET_MAX, TARGET_MAX, 0.5, "target x2 [m]"),
                      heading_deg=slider(90.0, -180.0, 180.0, 15.0, "target heading [deg]"),
                      T=slider(6.0, 1.0, 20.0, 0.5, "horizon T [s]"),
                      speed=slider(1.0, -2.0, 2.0, 0.1, "end speed [m/s]")),
        compute=robot_planner_compute, draw=draw, update=update, readout=readout, figsize=(11, 5))
