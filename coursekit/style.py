"""Figure style for the course: default sizes, and `lecture_mode` for a projector.

Every figure coursekit makes is created with `new_figure`, which reads the
current matplotlib settings, so switching `lecture_mode` on before building
a plot or an explorer makes it readable from the back of a lecture hall.
In a notebook, `lecture_mode` also enlarges the notebook's own text
(`coursekit.notebook_style`).
"""

from __future__ import annotations

import numpy as np

from ._validation import as_flag, as_integer, as_vector
from .notebook_style import show_lecture_text

__all__ = ["lecture_mode", "is_lecture_mode", "new_figure", "fit_margins", "LECTURE_STYLE"]

#: space around each axes' decorations and at the figure's edges, in inches (4 points)
_PAD = 4 / 72
#: extra space between neighbouring axes, as a fraction of the figure's width (height)
_SPACE = 0.02

#: matplotlib settings applied by ``lecture_mode(True)``.
LECTURE_STYLE = {
    "figure.figsize": (12.0, 6.5),
    "figure.dpi": 100,
    "font.size": 17,
    "axes.titlesize": 20,
    "axes.labelsize": 18,
    "xtick.labelsize": 15,
    "ytick.labelsize": 15,
    "legend.fontsize": 15,
    "lines.linewidth": 3.0,
    "lines.markersize": 9,
    "axes.linewidth": 1.5,
    "grid.linewidth": 1.0,
}

_saved: dict | None = None


def lecture_mode(on: bool = True) -> None:
    """Switch large fonts, thick lines and big figures on (or back off).

    Affects every figure created afterwards: notebook plots, coursekit's
    plotting helpers and explorers built after the call. Called in a notebook
    cell (JupyterLab 4, Notebook 7), it also enlarges the notebook's own text at
    once: markdown, code, outputs and widgets, in every cell (it displays an
    invisible style output, see `coursekit.notebook_style`). ``lecture_mode(False)``
    restores the matplotlib settings that were in force before it was switched
    on and the notebook's text sizes. Outside a notebook only the figure
    settings change.
    """
    on = as_flag(on, "on", hint="call lecture_mode() to switch on, lecture_mode(False) to switch off")
    import matplotlib as mpl
    global _saved
    if on:
        if _saved is None:
            _saved = {key: mpl.rcParams[key] for key in LECTURE_STYLE}
        mpl.rcParams.update(LECTURE_STYLE)
    elif _saved is not None:
        mpl.rcParams.update(_saved)
        _saved = None
    show_lecture_text(on)


def is_lecture_mode() -> bool:
    """True while lecture mode is on."""
    return _saved is not None


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize=None, **subplot_kw):
    """A matplotlib Figure with a grid of axes, outside pyplot's global state.

    Returns ``(fig, axes)`` like ``plt.subplots``. The figure is not shown
    automatically; display it with ``IPython.display.display(fig)`` or return
    it as the last expression of a notebook cell.
    """
    from matplotlib.figure import Figure
    nrows = as_integer(nrows, "nrows", minimum=1, why="one row of axes at least")
    ncols = as_integer(ncols, "ncols", minimum=1, why="one column of axes at least")
    if figsize is not None:
        size = as_vector(figsize, "figsize", size=2, why="(width, height) in inches")
        if np.any(size <= 0):
            raise ValueError(f"figsize must be positive: received {tuple(size)}; "
                             "give (width, height) in inches, e.g. (8, 4).")
        figsize = tuple(size)
    fig = fit_margins(Figure(figsize=figsize))
    axes = fig.subplots(nrows, ncols, squeeze=True, **subplot_kw)
    return fig, axes


def fit_margins(fig):
    """Lay `fig` out with matplotlib's constrained layout and the course's pads; returns `fig`.

    Each time the figure is drawn, its margins and the gaps between its axes are measured
    from the text they hold (tick labels, axis labels, titles, colorbars, legends placed
    outside the axes, the suptitle), so all of it stays inside the figure and clear of the
    neighbouring axes at any font size, lecture mode included. Every figure coursekit draws
    uses it (`new_figure`). Call it before adding colorbars; a figure that already has a
    layout engine keeps it. Raises ValueError if `fig` is not a Figure, or if a colorbar was
    added without an engine in a way constrained layout cannot lay out.
    """
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise ValueError(f"fig must be a matplotlib Figure: received {type(fig).__name__}; "
                         "pass the figure (fig, not an Axes), e.g. fig, ax = new_figure().")
    if fig.get_layout_engine() is not None:
        return fig
    if any(spec is not None and spec.get_topmost_subplotspec() is not spec
           for spec in (ax.get_subplotspec() for ax in fig.axes)):
        raise ValueError("fig has a colorbar that splits an axes' grid cell (fig.colorbar(im, ax=ax) "
                         "called before fit_margins), which constrained layout cannot lay out: "
                         "call ck.fit_margins(fig) first, then add the colorbar.")
    fig.set_layout_engine("constrained", w_pad=_PAD, h_pad=_PAD, wspace=_SPACE, hspace=_SPACE)
    return fig


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
