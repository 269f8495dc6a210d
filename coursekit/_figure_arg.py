"""The ``ax`` argument of the plotting functions: draw into it, or into a new course figure."""

from __future__ import annotations

from .style import new_figure

__all__ = ["figure_for"]


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
