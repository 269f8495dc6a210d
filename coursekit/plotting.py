"""Figures for chapter 1: time responses, state-plane trajectories, exact vs Euler.

Every function builds a new figure with `coursekit.style.new_figure` (so
`lecture_mode` applies), labels every axis with its unit, and returns the
figure; in a notebook, make it the last expression of the cell to show it.
Curves take the course's colours with a line style (or marker) each
(`coursekit.style.curve_style`), so none is told from another by colour alone.
matplotlib is imported inside the functions.
"""

from __future__ import annotations

import numpy as np

from ._arguments import figure_for
from ._validation import as_integer, as_matrix, as_text
from .style import curve_style, new_figure, text_colour

__all__ = ["plot_response", "plot_state_plane", "plot_euler_comparison"]

_WORDS = {"x": "state", "y": "output", "u": "input"}


def _names(given, letter: str, count: int, argname: str) -> list[str]:
    """Signal names: the given list, or x1, x2, ... ."""
    if given is None:
        return [f"{letter}{i + 1}" if count > 1 else letter for i in range(count)]
    names = [given] if isinstance(given, str) else [str(g) for g in given]
    if len(names) != count:
        raise ValueError(
            f"{argname} has the wrong length: received {len(names)} names, expected {count} "
            f"(one per {_WORDS[letter]} of the system)."
        )
    return names


def _units(given, count: int, argname: str) -> list[str]:
    """Units per signal: one string for all, a list, or '-' (unspecified) by default."""
    if given is None:
        return ["-"] * count
    if isinstance(given, str):
        return [given] * count
    units = [str(g) for g in given]
    if len(units) != count:
        raise ValueError(
            f"{argname} has the wrong length: received {len(units)} units, expected {count} "
            "(one per signal), or give one string for all of them."
        )
    return units


def _is_result(value) -> bool:
    """True for a `SimulationResult` (read by its fields: `simulation` imports this module)."""
    return all(hasattr(value, name) for name in ("t", "x", "y", "u", "system"))


def _check_result(result, argname: str = "result"):
    if not _is_result(result):
        raise ValueError(
            f"{argname} must be a SimulationResult (what simulate returns): received "
            f"{type(result).__name__}."
        )
    return result


def _time_label(time_unit: str) -> str:
    unit = as_text(time_unit, "time_unit", expected="a unit such as 's' or 'min'")
    return f"time t [{unit}]"


def _state_index(value, name: str, n: int) -> int:
    """A 0-based state index below n (x1 is index 0)."""
    k = as_integer(value, name, minimum=0, why="indices count from 0: x1 is 0")
    if k >= n:
        raise ValueError(f"{name} is out of range: received {k}, but the system has n = {n} states "
                         f"(indices 0 to {n - 1}; x1 is 0).")
    return k


def plot_response(result, which: str = "xu", *, state_names=None, output_names=None,
                  input_names=None, state_units=None, output_units=None, input_units=None,
                  time_unit: str = "s", title: str | None = None, figsize=None):
    """Time responses of a simulation, one stacked axis per kind of signal.

    Parameters
    ----------
    result : SimulationResult
        What `simulate` returns (``result.plot()`` calls this function).
    which : str
        Letters among ``"x"`` (states), ``"y"`` (outputs) and ``"u"`` (inputs),
        one axis each, top to bottom in the given order. ``u`` is skipped
        for a system without input.
    state_names, output_names, input_names : list of str, optional
        Legend names (default x1, x2, ..., y1, ..., u1, ...).
    state_units, output_units, input_units : str or list of str, optional
        Units for the axis labels; one string for all signals of that kind or
        one per signal (default "-", unspecified).
    time_unit : str
        Unit of the time axis (default "s"; e.g. "year" for the bank account).
    title, figsize : optional
        Figure title (default: the system's name) and size.

    Discrete-time results are drawn as markers joined by thin lines (the
    state only exists at the sampling instants).
    """
    result = _check_result(result)
    if not isinstance(which, str) or not which or set(which) - set("xyu") or len(set(which)) != len(which):
        raise ValueError(
            f"which must be a string of distinct letters among 'x', 'y', 'u': received {which!r}; "
            "e.g. which='xu' for states and inputs."
        )
    series = {"x": result.x, "y": result.y, "u": result.u}
    names_in = {"x": state_names, "y": output_names, "u": input_names}
    units_in = {"x": state_units, "y": output_units, "u": input_units}
    letters = [c for c in which if series[c].shape[1] > 0]
    if not letters:
        raise ValueError(f"which={which!r} selects no signal: the system has no input; use which='x'.")
    fig, axes = new_figure(len(letters), 1, figsize=figsize or _stacked_size(len(letters)), sharex=True)
    axes = np.atleast_1d(axes)
    discrete = getattr(result.system, "is_discrete", False)
    for ax, letter in zip(axes, letters):
        data = series[letter]
        names = _names(names_in[letter], letter, data.shape[1], f"{_WORDS[letter]}_names")
        units = _units(units_in[letter], data.shape[1], f"{_WORDS[letter]}_units")
        _draw_signals(ax, result.t, data, names, units, discrete=discrete)
        same = len(set(units)) == 1
        ax.set_ylabel(f"{_WORDS[letter]} {letter} [{units[0]}]" if same else f"{_WORDS[letter]} {letter}")
        ax.grid(True, alpha=0.4)
    axes[-1].set_xlabel(_time_label(time_unit))
    name = getattr(result.system, "name", "") or "the system"
    fig.suptitle(title if title is not None else f"Response of {name}", wrap=True)
    return fig


def _draw_signals(ax, t, data, names, units, *, discrete: bool) -> None:
    same = len(set(units)) == 1
    size = dict(markersize=4, linewidth=0.8) if discrete else {}
    for j in range(data.shape[1]):
        label = names[j] if same else f"{names[j]} [{units[j]}]"
        ax.plot(t, data[:, j], label=label, **curve_style(j, marker=discrete), **size)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def _stacked_size(rows: int) -> tuple[float, float]:
    """Default size of a figure of `rows` stacked axes: matplotlib's default size (lecture
    mode's, when on), made taller where needed to give each axes the height of ten axis-label
    font sizes, so that a rotated y label fits along its axes at any font size."""
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties
    width, height = rcParams["figure.figsize"]
    label = FontProperties(size=rcParams["axes.labelsize"]).get_size_in_points()
    return (width, max(height, rows * 10 * label / 72 + 1.2))


def _trajectory_list(trajectories, states) -> list[tuple[np.ndarray, bool]]:
    """(points, discrete) pairs: the two chosen state columns of each trajectory."""
    if trajectories is None or isinstance(trajectories, (list, tuple)) and not trajectories:
        raise ValueError("trajectories is empty: pass a SimulationResult, an (N, n) array of states, "
                         "or a list of them.")
    items = trajectories if isinstance(trajectories, (list, tuple)) else [trajectories]
    out = []
    for k, item in enumerate(items):
        if _is_result(item):
            data, discrete = item.x, item.system.is_discrete
        else:
            if np.ndim(item) != 2:
                raise ValueError(
                    f"trajectories[{k}] must be a SimulationResult or an array of shape (N, n): "
                    f"received {type(item).__name__} with shape {np.shape(item)}.")
            data, discrete = as_matrix(item, f"trajectories[{k}]"), True
        picked = [as_integer(s, "states", minimum=0, why="indices count from 0: x1 is 0") for s in states]
        if max(picked) >= data.shape[1]:
            raise ValueError(
                f"trajectories[{k}] must be an array with a column for each index in states="
                f"{tuple(picked)}: received shape {data.shape}, whose state indices go up to "
                f"{data.shape[1] - 1} (x1 is 0); choose states among them.")
        out.append((data[:, picked], discrete))
    return out


def plot_state_plane(trajectories, *, states=(0, 1), labels=None, state_names=None,
                     state_units=None, numbered: bool | None = None, equal_axes: bool = False,
                     title: str = "State-plane trajectories", ax=None, figsize=None):
    """Trajectories in the plane of two states, as in figure 1.18.

    Parameters
    ----------
    trajectories : SimulationResult, (N, n) array, or a list of them
        Each is drawn in the plane of the states ``states`` (default x1, x2).
    labels : list of str, optional
        Legend entry per trajectory (default "x(0) = [..]").
    state_names, state_units : optional
        Axis names (default x1, x2) and units (default "-").
    numbered : bool, optional
        Write the time index next to every point and join consecutive points
        with arrows (figure 1.18). Default: on for trajectories of at most
        25 points; longer ones are drawn as a line with a few arrows showing
        the direction of time.
    equal_axes : bool
        Same scale on both axes (when both states have the same unit).
    ax : matplotlib Axes, optional
        Draw into this axes instead of a new figure.

    Returns the figure.
    """
    if np.ndim(states) != 1 or len(states) != 2:
        raise ValueError(f"states must name two state indices, e.g. (0, 1): received {states!r}.")
    items = _trajectory_list(trajectories, states)
    names = _names(state_names, "x", 2, "state_names") if state_names is not None else \
        [f"x{states[0] + 1}", f"x{states[1] + 1}"]
    units = _units(state_units, 2, "state_units")
    # one string is one label (as for state_names), never split into its letters
    labels = [labels] if isinstance(labels, str) else labels if labels is not None else [
        f"x(0) = [{pts[0, 0]:g}, {pts[0, 1]:g}]" for pts, _ in items]
    if len(labels) != len(items):
        raise ValueError(f"labels has {len(labels)} entries, expected {len(items)} (one per trajectory).")
    fig, ax = figure_for(ax, figsize=figsize)
    for k, ((pts, _), label) in enumerate(zip(items, labels)):
        if numbered if numbered is not None else len(pts) <= 25:
            _numbered_points(ax, pts, style=curve_style(k, marker=True), label=label)
        else:
            _directed_line(ax, pts, style=curve_style(k), label=label)
    ax.set_xlabel(f"{names[0]} [{units[0]}]")
    ax.set_ylabel(f"{names[1]} [{units[1]}]")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.axvline(0, color="0.6", linewidth=0.8)
    if equal_axes:
        ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.25)
    ax.grid(True, alpha=0.4)
    ax.legend(loc="best")
    ax.set_title(title, wrap=True)
    return fig


def _numbered_points(ax, pts: np.ndarray, *, style: dict, label: str) -> None:
    """Points with their time index (coinciding points share a label), curved arrows between them.

    The points carry the trajectory's marker (`style`), the arrows its colour, the time labels
    its colour darkened to text contrast."""
    color = style["color"]
    ax.plot(pts[:, 0], pts[:, 1], linestyle="None", marker=style["marker"], color=color, markersize=8,
            label=label)
    for k in range(len(pts) - 1):
        ax.annotate("", xy=pts[k + 1], xytext=pts[k],
                    arrowprops=dict(arrowstyle="-|>", color=color, shrinkA=6, shrinkB=6,
                                    connectionstyle="arc3,rad=0.2", linewidth=1.2))
    groups: dict[tuple, list[int]] = {}
    for k, p in enumerate(pts):
        groups.setdefault(tuple(np.round(p, 9)), []).append(k)
    for p, times in groups.items():
        ax.annotate("t = " + ", ".join(str(k) for k in times), xy=p, xytext=(8, 8),
                    textcoords="offset points", color=text_colour(color))


def _directed_line(ax, pts: np.ndarray, *, style: dict, label: str, arrows: int = 6) -> None:
    """A long trajectory: a line in `style`, its start marked, a few arrows along it."""
    color = style["color"]
    ax.plot(pts[:, 0], pts[:, 1], label=label, **style)
    ax.plot(pts[0, 0], pts[0, 1], "o", color=color)
    ax.annotate("t = 0", xy=pts[0], xytext=(8, 8), textcoords="offset points", color=text_colour(color))
    step = max(1, len(pts) // (arrows + 1))
    for k in range(step, len(pts) - 1, step):
        ax.annotate("", xy=pts[k + 1], xytext=pts[k],
                    arrowprops=dict(arrowstyle="-|>", color=color, linewidth=1.2, mutation_scale=15))


def plot_euler_comparison(exact, approximations, *, state: int = 0, state_name: str | None = None,
                          unit: str = "-", time_unit: str = "s", title: str | None = None,
                          figsize=None):
    """Exact solution against Euler discretizations (1.43), and their errors.

    Parameters
    ----------
    exact : SimulationResult
        The continuous-time simulation (e.g. ``simulate(sys, t)``).
    approximations : SimulationResult or list of them
        Simulations of ``euler_discretize(sys, Ts)``; each is labelled with its Ts.
    state : int
        Index of the state to compare (default x1).
    state_name, unit, time_unit, title, figsize : optional
        Labels. The top axis shows the trajectories, the bottom one the error
        ``|x_Euler(k) - x(k Ts)|`` on a log scale, which makes both the
        first-order convergence and a blow-up (Ts too large) visible.
    """
    exact = _check_result(exact, "exact")
    items = approximations if isinstance(approximations, (list, tuple)) else [approximations]
    items = [_check_result(r, f"approximations[{k}]") for k, r in enumerate(items)]
    for k, res in enumerate(items):
        if not getattr(res.system, "is_discrete", False):
            raise ValueError(
                f"approximations[{k}] must be the simulation of a discrete-time system "
                "(simulate(euler_discretize(sys, Ts), t_k)): received a continuous-time result.")
    state = _state_index(state, "state", exact.x.shape[1])
    name = state_name or f"x{state + 1}"
    fig, (ax, ax_err) = new_figure(2, 1, figsize=figsize, sharex=True)
    ref = exact.x[:, state]
    ax.plot(exact.t, ref, color="k", linewidth=2, label="exact")
    span = max(float(np.ptp(ref)), 1e-12)
    for k, res in enumerate(items):
        Ts = res.system.dt
        xk = res.x[:, state]
        ax.plot(res.t, xk, markersize=3, linewidth=0.8, label=f"Euler, Ts = {Ts:g}", **curve_style(k, marker=True))
        # from k = 1 on (at k = 0 both equal x0); only inside the exact time range
        keep = (res.t <= exact.t[-1] + 1e-12) & (np.arange(res.t.size) > 0)
        err = np.abs(xk[keep] - np.interp(res.t[keep], exact.t, ref))
        ax_err.semilogy(res.t[keep], np.maximum(err, 1e-16), label=f"Ts = {Ts:g}", **curve_style(k))
    # keep the exact solution readable when an unstable approximation blows up
    ax.set_ylim(ref.min() - 0.5 * span, ref.max() + 0.5 * span)
    ax.set_xlim(exact.t[0], exact.t[-1])
    ax.set_ylabel(f"{name} [{unit}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.grid(True, alpha=0.4)
    ax_err.set_ylabel(f"|error| [{unit}]")
    ax_err.set_xlabel(_time_label(time_unit))
    ax_err.grid(True, which="both", alpha=0.3)
    ax_err.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    fig.suptitle(title if title is not None else "Exact solution against Euler discretization (1.43)", wrap=True)
    return fig
