"""The explorers' limit policy: `rescale` fits an axes' view to its data; `moving` says a hand moves a control.

At rest the limits depend on the data alone, so a setting's figure is the same after a drag,
after key steps, fresh, and in the website's frames (`coursekit.tools.static_explorers`): the
data padded to fill `fill` of the view, each end moved out to a multiple of a round step (1, 2
or 5 times a power of ten) no larger than the padding, so that stepping a slider redraws the
limits only every few steps; a vertical axis then gains `Y_EDGE` of its span either way (no tick
label on the frame's corner). While a control moves (drawn inside `moving`) the limits only grow,
leaving the data `MOVING_FILL` of them and `Y_EDGE` / 2 of a vertical span off the frame.
"""

from __future__ import annotations

import contextlib
import contextvars
import math

import numpy as np

from .._validation import as_scalar

__all__ = ["rescale", "round_value", "moving", "is_moving", "SETTLE_S", "MOVING_FILL", "Y_EDGE"]

#: seconds between moves of a control that make them one drag; a frame follows once it rests
SETTLE_S = 0.3
#: while a control moves, limits that grow leave the data this fraction of them
MOVING_FILL = 0.6
#: at rest a vertical axis' limits move out by this part of their span (no tick on the corner)
Y_EDGE = 0.05

_MOVING = contextvars.ContextVar("moving", default=False)


@contextlib.contextmanager
def moving():
    """Within: the frames follow a control a hand moves, and `rescale` only grows the limits."""
    token = _MOVING.set(True)
    try:
        yield
    finally:
        _MOVING.reset(token)


def is_moving() -> bool:
    """Whether the frame being drawn follows a moving control (inside `moving`)."""
    return _MOVING.get()


def rescale(*axes, axis: str = "y", min_span: float = 0.0, fill: float = 0.8, relim: bool = True) -> None:
    """Fit the view of each of `axes` to its artists' data (call it in an update), by the module's
    policy. `axis` is ``"y"``, ``"x"`` or ``"both"``; a log axis is fitted in decades; the limits
    never pass an artist's ``sticky_edges`` (a time axis from 0). With `min_span` the view spans at
    least that much, centred (a constant is drawn flat, not its rounding noise magnified);
    ``fill=1`` fits the data exactly; with ``relim=False`` the data are the data limits the update
    set (``ax.update_datalim``).
    """
    if axis not in ("x", "y", "both"):
        raise ValueError(f"axis must be 'x', 'y' or 'both': received {axis!r}.")
    if not (isinstance(fill, (int, float)) and 0 < fill <= 1):
        raise ValueError(f"fill must be a number in (0, 1], the part of the view the data fill: "
                         f"received {fill!r}.")
    min_span = as_scalar(min_span, "min_span")
    for ax in axes:
        if relim:
            ax.relim()
        for name in ("xy" if axis == "both" else axis):
            _fit(ax, name, min_span, fill)


def round_value(value: float, up: bool = False) -> float:
    """The largest of 1, 2, 5 times a power of ten at most `value` > 0 (`up`: the smallest at least it)."""
    series = 10.0 ** math.floor(math.log10(value)) * np.array([1.0, 2.0, 5.0, 10.0])
    return float(series[series >= value * (1 - 1e-12)].min() if up else series[series <= value * (1 + 1e-12)].max())


def _at_rest(lo: float, hi: float, fill: float, edge: float) -> tuple[float, float]:
    """The limits for data in [lo, hi] at rest: padded to `fill`, rounded out to a round step,
    then moved out by `edge` of their span."""
    pad = (hi - lo) * (1 / fill - 1) / 2
    if pad <= 0:
        return lo, hi
    step = round_value(pad)
    low, high = math.floor((lo - pad) / step + 1e-9) * step, math.ceil((hi + pad) / step - 1e-9) * step
    return low - edge * (high - low), high + edge * (high - low)


def _fit(ax, name: str, min_span: float, fill: float) -> None:
    """`rescale` for one axis of `ax`, in the axis' scale (decades on a log axis)."""
    scale = getattr(ax, f"{name}axis").get_transform()
    with np.errstate(all="ignore"):
        lo, hi = scale.transform(getattr(ax.dataLim, f"interval{name}"))
        view = np.sort(scale.transform(getattr(ax, f"get_{name}lim")()))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return                                   # no data yet (or none a log axis can show)
    if hi - lo < min_span:
        lo, hi = (lo + hi - min_span) / 2, (lo + hi + min_span) / 2
    if not hi - lo > 1e-9 * max(abs(lo), abs(hi)):      # a constant: 5 % of it either way (or 0.05)
        lo, hi = lo - 0.05 * (abs(lo) or 1.0), hi + 0.05 * (abs(lo) or 1.0)
    edge = Y_EDGE if name == "y" else 0.0
    if is_moving() and not getattr(ax, f"get_autoscale{name}_on")():
        if view[0] + edge / 2 * np.ptp(view) <= lo and hi <= view[1] - edge / 2 * np.ptp(view):
            return                               # a hand moves a control: kept while the data fit
        pad = (hi - lo) * (1 / min(fill, MOVING_FILL) - 1) / 2
        span = max(hi + pad, view[1]) - min(lo - pad, view[0])
        low, high = min(lo - pad, view[0], lo - edge * span), max(hi + pad, view[1], hi + edge * span)
    else:
        low, high = _at_rest(lo, hi, fill, edge)
    with np.errstate(all="ignore"):   # sticky edges: no room past them (a time axis' start)
        sticky = scale.transform([s for a in ax.get_children() for s in getattr(a.sticky_edges, name)])
    low = max([low, *(s for s in sticky if low < s <= lo)])
    high = min([high, *(s for s in sticky if hi <= s < high)])
    getattr(ax, f"set_{name}lim")(*scale.inverted().transform([low, high]))
