"""The system and axes arguments of public functions: `as_system` takes a coursekit system, or one
of python-control or scipy.signal through the bridges; `figure_for` the Axes to draw into."""

from __future__ import annotations

import sys as _sys

import numpy as np

from ._validation import BRIDGES, foreign_library, type_name
from .style import new_figure
from .systems import NonlinearSystem, StateSpace

__all__ = ["as_system", "figure_for"]


_KINDS = {"any": "StateSpace or NonlinearSystem", "linear": "StateSpace", "nonlinear": "NonlinearSystem"}


def _system_received(value) -> str:
    """How a refused system argument is described: its time base, or its full type name."""
    if isinstance(value, np.ndarray):
        return f"a numpy array of shape {value.shape}"
    if hasattr(value, "is_discrete") and type(value).__module__ == "coursekit.systems":
        base, period = ("discrete", f" (dt={value.dt:g})") if value.is_discrete else ("continuous", "")
        return f"a {base}-time {type(value).__name__}{period}"
    return type_name(value)


def as_system(value, name: str = "sys", *, kind: str = "any", time: str = "", hint: str = ""):
    """Return `value` as a coursekit system, converting python-control and scipy.signal ones.

    `kind` is "any" (StateSpace or NonlinearSystem), "linear" (StateSpace) or
    "nonlinear"; `time` is "", "continuous" or "discrete". A ``control.StateSpace``
    or ``scipy.signal.StateSpace`` (also ``scipy.signal.lti(A, B, C, D)``) goes through
    the bridges `StateSpace.from_control` / `from_scipy` (the same matrices (1.24) and
    time base); one whose time base is unspecified (``dt=True``, or python-control's
    ``dt=None``) is refused, because reading it as dt = 1 or as continuous is the user's
    choice, and so is choosing the realization of a transfer function: both messages
    name the bridge. Anything else raises ValueError naming `name`, the wanted kind and
    the full type name of what was received, followed by `hint`.
    """
    library = foreign_library(value)
    if library is not None:
        value = _from_foreign(value, name, library)
    wanted = (StateSpace, NonlinearSystem) if kind == "any" else \
        StateSpace if kind == "linear" else NonlinearSystem
    right_time = not time or isinstance(value, (StateSpace, NonlinearSystem)) and \
        value.is_discrete == (time == "discrete")
    if not isinstance(value, wanted) or not right_time:
        base = f"{time}-time " if time else ""
        raise ValueError(f"{name} must be a {base}{_KINDS[kind]}: received {_system_received(value)}"
                         + (f"; {hint}" if hint else "."))
    return value


def _from_foreign(value, name: str, library: str):
    """The coursekit StateSpace of a python-control / scipy.signal state-space object (bridges)."""
    from ._bridges import realization_hint
    module = _sys.modules["control" if library == "python-control" else "scipy.signal"]
    bridge = BRIDGES[library]
    if not isinstance(value, module.StateSpace):
        raise ValueError(f"{name} must be a state-space system: received {type_name(value)}. "
                         f"{realization_hint(value)} Then convert it with {bridge}(sys).")
    dt = value.dt
    if dt is True or (dt is None and library == "python-control"):
        raise ValueError(
            f"{name} is a {library} system whose time base is unspecified (dt={dt!r}): "
            f"convert it with {bridge}(sys), which reads dt=True as a period of 1 and "
            "python-control's dt=None as continuous time, or build it with dt=0 (continuous) "
            "or the sampling period."
        )
    return getattr(StateSpace, bridge.split(".")[1])(value)


def figure_for(ax, *, figsize=None):
    """(fig, ax): a new figure when `ax` is None, else the figure of the Axes `ax` (checked).

    Anything but a matplotlib Axes raises ValueError naming `ax`, instead of an
    AttributeError deep inside the drawing.
    """
    if ax is None:
        return new_figure(1, 1, figsize=figsize)
    from matplotlib.axes import Axes
    if not isinstance(ax, Axes):
        raise ValueError(f"ax must be a matplotlib Axes: received {type(ax).__name__}; "
                         "leave it out to draw a new figure, or pass one axes of new_figure().")
    return ax.figure, ax
