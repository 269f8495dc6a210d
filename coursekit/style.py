"""Figure style for the course: colours every reader tells apart, sizes, and `lecture_mode`.

Colours: `PALETTE` holds Okabe and Ito's colour-blind-safe colours that stand out against a
white background (3:1 at least, WCAG 2.1 1.4.11), and `COURSE_STYLE` gives the curves of an
axes these colours together with a line style each (`CURVE_STYLES`), so that two curves never
differ by colour alone. coursekit applies it to every figure it makes (`new_figure`,
`course_subplots`); a notebook applies it to its own plots with matplotlib's
``plt.style.use(ck.COURSE_STYLE)``. Text keeps 4.5:1 against its background (`contrast_ratio`,
`text_colour`).

Sizes: every figure coursekit makes is created with `new_figure`, which reads the current
matplotlib settings, so switching `lecture_mode` on before building a plot or an explorer
makes it readable from the back of a lecture hall. In a notebook, `lecture_mode` also enlarges
the notebook's own text (`coursekit.notebook_style`).
"""

from __future__ import annotations

import numpy as np

from ._validation import as_flag, as_integer, as_vector
from .notebook_style import show_lecture_text

__all__ = ["lecture_mode", "is_lecture_mode", "new_figure", "course_subplots", "fit_margins",
           "LECTURE_STYLE", "PALETTE", "CURVE_STYLES", "COURSE_STYLE", "curve_style",
           "contrast_ratio", "text_colour"]

#: The course's colours, from Okabe and Ito's palette for colour-blind readers ("Color Universal
#: Design", 2008), keeping those with at least 3:1 contrast against white (their orange, sky blue
#: and yellow have less). The first four colour the curves, in this order; black is for the
#: reference a figure compares with (the exact solution, the true state, a plan).
PALETTE = {
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "bluish green": "#009E73",
    "reddish purple": "#CC79A7",
    "black": "#000000",
}

#: Colour and line style of the first, second, ... curve of an axes (a fifth curve takes the
#: first style again: give it a marker).
CURVE_STYLES = tuple({"color": PALETTE[name], "linestyle": style} for name, style in
                     zip(("blue", "vermillion", "bluish green", "reddish purple"), ("-", "--", "-.", ":")))


def _course_style() -> dict:
    from cycler import cycler
    return {"axes.prop_cycle": cycler(color=[s["color"] for s in CURVE_STYLES])
            + cycler(linestyle=[s["linestyle"] for s in CURVE_STYLES])}


#: matplotlib settings of the course's figures: ``plt.style.use(ck.COURSE_STYLE)`` in a notebook,
#: ``matplotlib.rc_context(ck.COURSE_STYLE)`` around a figure of one's own.
COURSE_STYLE = _course_style()


#: the marker of the k-th curve, where the curves are (also) drawn as points; five of them, so
#: that a fifth curve, which takes the first colour and line style again, has a marker of its own
_MARKERS = ("o", "s", "^", "D", "v")


def curve_style(k: int, *, marker: bool = False) -> dict:
    """``color`` and ``linestyle`` of the k-th curve (0-based) of an axes, as keyword arguments
    of ``ax.plot``: the course's colours in order, each with its own line style. With
    ``marker=True`` also a ``marker`` of its own (circle, square, triangle up, diamond, triangle
    down): for curves drawn as points, which have no line style to tell them apart, and for a
    fifth curve and more (twenty curves in one axes all look different)."""
    k = as_integer(k, "k", minimum=0, why="curves count from 0")
    marker = as_flag(marker, "marker")
    style = dict(CURVE_STYLES[k % len(CURVE_STYLES)])
    return {**style, "marker": _MARKERS[k % len(_MARKERS)]} if marker else style


def _rgba(value, name: str) -> tuple:
    """`value` as an RGBA tuple; anything that is not a matplotlib colour raises ValueError naming `name`."""
    from matplotlib.colors import to_rgba
    try:
        return to_rgba(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a matplotlib colour (a name such as 'black', a hex string such as "
                         f"'#0072B2', 'C1', or an RGB(A) tuple in [0, 1]): received {value!r}.") from None


def _linear_rgb(rgb) -> np.ndarray:
    """sRGB components made linear in light (WCAG 2.1's definition of relative luminance)."""
    c = np.asarray(rgb)
    return np.where(c <= 0.03928, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _over(rgba, below) -> np.ndarray:
    """The colour `rgba` (with its alpha) painted over the opaque RGB `below`: an opaque RGB."""
    *rgb, alpha = rgba
    return alpha * np.asarray(rgb) + (1 - alpha) * np.asarray(below)


def contrast_ratio(foreground, background="white") -> float:
    """WCAG 2.1's contrast ratio (L1 + 0.05) / (L2 + 0.05) of two colours, from 1 to 21.

    L is the relative luminance 0.2126 R + 0.7152 G + 0.0722 B of the linear sRGB components.
    Any matplotlib colour is accepted; a translucent `background` is painted over white (the
    page) first, then a translucent `foreground` over it. Text needs 4.5 (1.4.3), the lines
    and marks of a figure 3 (1.4.11).
    """
    front, back = _rgba(foreground, "foreground"), _rgba(background, "background")
    back = _over(back, np.ones(3))
    weights = np.array([0.2126, 0.7152, 0.0722])
    light = sorted((float(weights @ _linear_rgb(c)) for c in (_over(front, back), back)), reverse=True)
    return (light[0] + 0.05) / (light[1] + 0.05)


def text_colour(colour, background="white") -> str:
    """`colour` darkened (mixed with black) just enough for text: 4.5:1 against `background`.

    For a label written in the colour of its curve: ``text_colour(PALETTE["vermillion"])``.
    Returns a hex string; a colour that is dark enough already comes back unchanged.
    """
    from matplotlib.colors import to_hex
    rgb = np.asarray(_rgba(colour, "colour")[:3])
    _rgba(background, "background")
    for darker in np.linspace(0.0, 1.0, 101):
        if contrast_ratio(rgb * (1 - darker), background) >= 4.5:
            return to_hex(rgb * (1 - darker))
    raise ValueError(f"background must leave room for dark text: no shade of {colour!r} reaches "
                     f"4.5:1 against {background!r}; use a light background.")


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
    if figsize is not None:
        size = as_vector(figsize, "figsize", size=2, why="(width, height) in inches")
        if np.any(size <= 0):
            raise ValueError(f"figsize must be positive: received {tuple(size)}; "
                             "give (width, height) in inches, e.g. (8, 4).")
        figsize = tuple(size)
    fig = fit_margins(Figure(figsize=figsize))
    return fig, course_subplots(fig, nrows, ncols, **subplot_kw)


def course_subplots(fig, nrows: int = 1, ncols: int = 1, **subplot_kw):
    """``fig.subplots(nrows, ncols, **subplot_kw)`` with the course's colours and line styles
    (`COURSE_STYLE`): for an explorer's ``draw(fig)``, whose figure the explorer makes."""
    import matplotlib as mpl
    _check_figure(fig)
    nrows = as_integer(nrows, "nrows", minimum=1, why="one row of axes at least")
    ncols = as_integer(ncols, "ncols", minimum=1, why="one column of axes at least")
    with mpl.rc_context(COURSE_STYLE):
        return fig.subplots(nrows, ncols, squeeze=True, **subplot_kw)


def _check_figure(fig) -> None:
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise ValueError(f"fig must be a matplotlib Figure: received {type(fig).__name__}; "
                         "pass the figure (fig, not an Axes), e.g. fig, ax = new_figure().")


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
    _check_figure(fig)
    if fig.get_layout_engine() is not None:
        return fig
    if any(spec is not None and spec.get_topmost_subplotspec() is not spec
           for spec in (ax.get_subplotspec() for ax in fig.axes)):
        raise ValueError("fig has a colorbar that splits an axes' grid cell (fig.colorbar(im, ax=ax) "
                         "called before fit_margins), which constrained layout cannot lay out: "
                         "call ck.fit_margins(fig) first, then add the colorbar.")
    fig.set_layout_engine("constrained", w_pad=_PAD, h_pad=_PAD, wspace=_SPACE, hspace=_SPACE)
    return fig


