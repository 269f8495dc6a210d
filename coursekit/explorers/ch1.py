"""Explorers of chapter 1: the Euler step, and the mass-spring-damper parameters.

Each explorer is a pure ``*_compute`` function (numbers only, unit-tested)
and a ``*_explorer()`` factory that wires it to sliders.
"""

from __future__ import annotations

import numpy as np

from .. import models
from .._validation import MAX_SAMPLES, as_scalar, time_grid
from ..realization import euler_discretize
from ..simulation import simulate
from ..systems import StateSpace
from ..stability import format_poles
from ..style import PALETTE, course_subplots, curve_style
from ._base import Explorer, dropdown, slider
from .limits import rescale

__all__ = ["EULER_EXAMPLES", "euler_compute", "euler_explorer", "msd_compute", "msd_explorer"]

#: The systems the Euler explorer offers: (system, x0, t_end, state unit; "" for a dimensionless
#: state, shown with no unit: a unit "-" reads as a minus sign).
EULER_EXAMPLES = {
    "first order (1.12)": (StateSpace([[-3.0]], name="y' = -3 y"), [6.0], 3.0, ""),
    "mass-spring-damper (1.57)": (models.mass_spring_damper(m=1.0, d=0.5, k=2.0), [1.0, 0.0], 15.0, "m"),
}


def _euler_limit(A: np.ndarray) -> float:
    """Largest Ts with |1 + Ts lambda| < 1 for every eigenvalue lambda of A.

    0 when A has an eigenvalue with Re >= 0: then no step makes Euler stable.
    """
    lam = np.linalg.eigvals(A)
    if np.any(lam.real >= 0):
        return 0.0
    # |1 + Ts lam|^2 < 1  <=>  Ts < -2 Re(lam) / |lam|^2
    return float(np.min(-2 * lam.real / np.abs(lam) ** 2))


def euler_compute(Ts: float, example: str = "first order (1.12)", samples: int = 1500) -> dict:
    """Exact response against its Euler discretization (1.43) for the step `Ts`.

    Returns a dict with the exact curve ``t, x`` (first state, `samples`
    points), the Euler samples ``tk, xk``, the exact value at those times
    ``xk_exact``, ``max_error``, the spectral radius ``rho`` of ``I + Ts A``,
    ``stable`` (rho < 1), the stability limit ``Ts_max`` and the ``unit``.
    """
    Ts = as_scalar(Ts, "Ts", positive=True)
    if not isinstance(example, str) or example not in EULER_EXAMPLES:
        raise ValueError(f"example must be one of {list(EULER_EXAMPLES)}: received {example!r}.")
    sys, x0, t_end, unit = EULER_EXAMPLES[example]
    t = time_grid(t_end, samples)
    if t_end / Ts > MAX_SAMPLES:
        raise ValueError(f"Ts is too small: {t_end / Ts:.3g} Euler steps over {t_end:g} s; take Ts >= "
                         f"{t_end / MAX_SAMPLES:.2g} s.")
    exact = simulate(sys, t, x0=x0)
    disc = euler_discretize(sys, Ts)
    tk = np.arange(int(np.floor(t_end / Ts + 1e-9)) + 1) * Ts
    euler = simulate(disc, tk, x0=x0)
    # the exact solution at the sampling instants, x(k Ts) = e^{A k Ts} x0
    xk_exact = simulate(sys, tk, x0=x0).x[:, 0] if tk.size > 1 else np.asarray(x0[:1], float)
    rho = float(max(abs(np.linalg.eigvals(disc.A))))
    return dict(t=t, x=exact.x[:, 0], tk=tk, xk=euler.x[:, 0], xk_exact=xk_exact,
                max_error=float(np.max(np.abs(euler.x[:, 0] - xk_exact))), rho=rho,
                stable=rho < 1.0, Ts_max=_euler_limit(sys.A), Ts=Ts, unit=unit, example=example)


def euler_explorer() -> Explorer:
    """Sliders for the Euler step Ts: exact solution, Euler samples and error."""
    def draw(fig):
        ax, ax_err = course_subplots(fig, 2, 1, sharex=True)
        euler = curve_style(1)            # dashed vermillion, with points while they can be told apart
        exact, = ax.plot([], [], color=PALETTE["black"], linewidth=2, label="exact")
        approx, = ax.plot([], [], marker="o", markersize=3, linewidth=0.8, label="Euler (1.43)", **euler)
        err, = ax_err.semilogy([], [], **euler)
        ax.set_ylabel("x1")
        ax.set_title("first state: exact and Euler samples")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
        ax.grid(True, alpha=0.4)
        ax_err.set_ylabel("|x_Euler(k) - x(k Ts)|")
        ax_err.set_xlabel("time t [s]")
        ax_err.grid(True, which="both", alpha=0.3)
        return dict(ax=ax, ax_err=ax_err, exact=exact, approx=approx, err=err)

    def update(h, r):
        h["exact"].set_data(r["t"], r["x"])
        h["approx"].set_data(r["tk"], r["xk"])
        h["approx"].set_marker("o" if r["tk"].size <= 80 else "None")
        # from k = 1 on: at k = 0 both start at x0 and the error is exactly zero
        h["err"].set_data(r["tk"][1:], np.maximum(np.abs(r["xk"] - r["xk_exact"])[1:], 1e-16))
        # fixed per system: the exact curve with room for the Euler samples near it (samples that
        # blow up leave the axes; the error plot below shows how far)
        span = max(float(np.ptp(r["x"])), 1e-12)
        # a little room before t = 0 keeps the first time label clear of the error axis' lowest one
        h["ax"].set_xlim(-0.02 * r["t"][-1], r["t"][-1])
        h["ax"].set_ylim(r["x"].min() - 0.5 * span, r["x"].max() + 0.5 * span)
        unit = f" [{r['unit']}]" if r["unit"] else ""
        h["ax"].set_ylabel(f"x1{unit}")
        h["ax_err"].set_ylabel(f"|error|{unit}")
        rescale(h["ax_err"])

    def readout(r):
        verdict = "< 1: stable" if r["stable"] else ">= 1: UNSTABLE"
        error = f"{r['max_error']:.2g} {r['unit']}".rstrip()
        return (f"{r['example']}, Ts = {r['Ts']:.3g} s: largest error {error}\n"
                f"max |eig(I + Ts A)| = {r['rho']:.3f} {verdict} (Euler is stable for Ts < {r['Ts_max']:.3g} s)")

    return Explorer(
        title="Euler discretization (1.43): step Ts against the exact solution",
        controls=dict(Ts=slider(0.1, 0.01, 1.0, 0.01, "Ts [s]"),
                      example=dropdown(list(EULER_EXAMPLES), "first order (1.12)", "system")),
        compute=euler_compute, draw=draw, update=update, readout=readout, figsize=(8, 5.5))


def msd_compute(m: float, d: float, k: float, experiment: str = "step", t_end: float = 20.0,
                samples: int = 1500) -> dict:
    """Response of the mass-spring-damper (1.54)/(1.57) for the parameters m, d, k.

    ``experiment="step"``: u = 1 N from rest (the position settles at 1/k);
    ``"initial"``: u = 0 from y(0) = 1 m, y'(0) = 0.
    Returns ``t, y`` (position), ``v`` (velocity), ``u``, the natural
    frequency ``omega_n = sqrt(k/m)``, the damping ratio
    ``zeta = d / (2 sqrt(k m))`` and the ``poles`` (eigenvalues of A).
    """
    m = as_scalar(m, "m", positive=True)
    k = as_scalar(k, "k", positive=True)
    d = as_scalar(d, "d")
    if not np.all(np.isfinite([k / m, d / m])):
        raise ValueError(f"m, d, k give a system beyond the float range (k/m = {k / m:g}, d/m = {d / m:g}): "
                         "pass a mass that is not negligible against the spring and the damper.")
    if not isinstance(experiment, str) or experiment not in ("step", "initial"):
        raise ValueError(f"experiment must be 'step' or 'initial': received {experiment!r}.")
    sys = models.mass_spring_damper(m=m, d=d, k=k)
    t = time_grid(t_end, samples)
    samples = t.size
    if experiment == "step":
        res = simulate(sys, t, u=np.ones((samples, 1)))
    else:
        res = simulate(sys, t, x0=[1.0, 0.0])
    return dict(t=t, y=res.x[:, 0], v=res.x[:, 1], u=res.u[:, 0], omega_n=float(np.sqrt(k / m)),
                zeta=float(d / (2 * np.sqrt(k * m))), poles=np.linalg.eigvals(sys.A),
                experiment=experiment, m=m, d=d, k=k)


def msd_explorer() -> Explorer:
    """Sliders for m, d, k of the mass-spring-damper: response and poles."""
    def draw(fig):
        ax, ax_p = course_subplots(fig, 1, 2, width_ratios=[2.2, 1])
        y, = ax.plot([], [], label="position y [m]", **curve_style(0))
        v, = ax.plot([], [], label="velocity y' [m/s]", **curve_style(1))
        ax.set_xlabel("time t [s]")
        ax.set_ylabel("y [m], y' [m/s]")
        ax.set_title("response")
        ax.legend(loc="best", fontsize="small")
        ax.grid(True, alpha=0.4)
        poles, = ax_p.plot([], [], "x", markersize=10, markeredgewidth=2, color=PALETTE["vermillion"])
        ax_p.axvline(0, color="0.5", linewidth=0.8)
        ax_p.axhline(0, color="0.5", linewidth=0.8)
        ax_p.set_xlabel("Re s [1/s]")
        ax_p.set_ylabel("Im s [rad/s]")
        ax_p.set_title("poles = eig(A)")
        ax_p.grid(True, alpha=0.4)
        return dict(ax=ax, ax_p=ax_p, y=y, v=v, poles=poles)

    def update(h, r):
        h["y"].set_data(r["t"], r["y"])
        h["v"].set_data(r["t"], r["v"])
        h["poles"].set_data(r["poles"].real, r["poles"].imag)
        h["ax"].set_xlim(0, r["t"][-1])
        rescale(h["ax"])
        rescale(h["ax_p"], axis="both", min_span=1.0)

    def readout(r):
        poles = format_poles(r["poles"])
        return (f"{r['experiment']} response, m = {r['m']:g} kg, d = {r['d']:g} N s/m, k = {r['k']:g} N/m\n"
                f"damping ratio zeta = {r['zeta']:.3f}, natural frequency omega_n = {r['omega_n']:.3f} rad/s, "
                f"poles {poles} 1/s")

    return Explorer(
        title="Mass-spring-damper (1.54): parameters m, d, k against the response",
        controls=dict(m=slider(1.0, 0.1, 5.0, 0.1, "m [kg]"),
                      d=slider(0.5, 0.0, 5.0, 0.05, "d [N s/m]"),
                      k=slider(2.0, 0.1, 10.0, 0.1, "k [N/m]"),
                      experiment=dropdown(["step", "initial"], "step", "experiment")),
        compute=msd_compute, draw=draw, update=update, readout=readout, figsize=(11, 4.5))
