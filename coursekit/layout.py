"""Figure layout by estimate: margins from font sizes and tick labels, in one pass.

matplotlib's constrained and tight layouts find the margins by measuring
every tick label, axis label and title, which costs about as much as drawing
the figure again; with a dozen figures per notebook and a redraw per slider
move, measuring dominates. The space an axes grid needs follows closely from
the font sizes, the number of text lines and the characters of the tick
labels, so `fit_margins` estimates it without rendering any text and sets
it with ``subplots_adjust`` each time the figure is drawn. In lecture mode the
fonts are so large that legends and titles can outgrow their axes, which the
estimate does not model, so there the figure is measured (constrained layout)
instead: slower, but right on the projector. Constrained layout cannot handle
a colorbar that split an axes' grid cell (``fig.colorbar(im, ax=ax)``), so
such a figure keeps the estimate in lecture mode too.
"""

from __future__ import annotations

import math

__all__ = ["fit_margins"]

#: advance widths in em of the default font (DejaVu Sans) for tick-label characters
_CHAR_EM = {**dict.fromkeys("0123456789", 0.636), ".": 0.318, ",": 0.318, " ": 0.318,
            "\N{MINUS SIGN}": 0.838, "-": 0.361, "+": 0.838, "e": 0.615, "E": 0.632,
            "\N{MULTIPLICATION SIGN}": 0.838, "%": 0.950, "/": 0.337, ":": 0.337,
            "(": 0.390, ")": 0.390, "i": 0.278, "l": 0.278}
_OTHER_EM = 0.65
_LINE = 1.25         # height of a text line, in font sizes
_EDGE = 4.0          # points kept free at the figure's edge
_SUPERSCRIPT = 0.7   # size of mathtext superscripts (log-axis labels 10^k)

_hook_class = None


def fit_margins(fig):
    """Lay the figure's grid of axes out by estimated margins (fast, one draw).

    Adds to the figure an invisible artist that, each time the figure is
    drawn and before any axes is, sizes the margins and the gaps between axes
    from the tick labels, axis labels, titles and suptitle -- without
    measuring text -- and applies them with ``subplots_adjust``. Call it once
    on any figure whose axes come from ``plt.subplots`` or a GridSpec (calling
    it again changes nothing); every figure coursekit draws uses it. Colorbars
    made with ``fig.colorbar(im, ax=ax)`` or ``cax=`` in a grid cell are laid
    out with their axes; one made for several axes (``ax=[ax1, ax2]``) moves
    them by hand, and the figure then keeps matplotlib's margins. In
    lecture mode the figure is laid out by constrained layout instead. A
    layout engine set on the figure (``fig.set_layout_engine``) takes
    precedence. Returns the figure.

    Not a matplotlib layout engine on purpose: a figure with an engine is
    drawn twice by ``savefig`` and by the notebook's inline backend (once to
    lay it out, once to render it), and the first pass costs nearly as much
    as the second.
    """
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise ValueError(f"fig must be a matplotlib Figure: received {type(fig).__name__}; "
                         "pass the figure (fig, not an Axes), e.g. fig, ax = new_figure().")
    global _hook_class
    if _hook_class is None:
        _hook_class = _make_hook_class()
    if not any(isinstance(artist, _hook_class) for artist in fig.artists):
        fig.add_artist(_hook_class())
    return fig


def _make_hook_class():
    """The Artist subclass, defined on first use (matplotlib loads lazily)."""
    from matplotlib.artist import Artist
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    from .style import is_lecture_mode

    class MarginsAtDraw(Artist):
        """Draws nothing; sets the margins of its figure's axes as the figure is drawn.

        Its zorder puts it before every axes in the figure's drawing order, and
        it takes no part in tight bounding boxes.
        """

        def __init__(self):
            super().__init__()
            self.set_zorder(-math.inf)
            self.set_in_layout(False)

        def draw(self, renderer):
            fig = self.get_figure()
            if fig is None or fig.get_layout_engine() is not None:
                return
            if is_lecture_mode() and not _splits_a_cell(fig):
                for ax in fig.axes:
                    ax.title.set_wrap(True)  # a title wider than the figure breaks into lines
                ConstrainedLayoutEngine().execute(fig)
            else:
                _apply(fig)
            self.stale = False

    return MarginsAtDraw


def _apply(fig) -> None:
    """Set the margins and gaps of the figure's axes grid from their estimated needs."""
    grid = _grid_cells(fig)
    if grid is None:
        return
    (nrows, ncols), spans = grid
    width, height = fig.get_size_inches() * 72.0

    def outer(side, at_edge):
        return _EDGE + max([need[side] for rows, cols, need in spans if at_edge(rows, cols)], default=0.0)

    left = outer(0, lambda r, c: c.start == 0)
    right = outer(1, lambda r, c: c.stop == ncols)
    bottom = outer(2, lambda r, c: r.stop == nrows)
    top = outer(3, lambda r, c: r.start == 0) + _suptitle_height(fig)
    gap_w = max((_gap(spans, k, across=1) for k in range(1, ncols)), default=0.0)
    gap_h = max((_gap(spans, k, across=0) for k in range(1, nrows)), default=0.0)
    axes_w = (width - left - right - (ncols - 1) * gap_w) / ncols
    axes_h = (height - top - bottom - (nrows - 1) * gap_h) / nrows
    if axes_w <= 0 or axes_h <= 0:
        return  # the figure is too small for its labels; leave matplotlib's defaults
    fig.subplots_adjust(left=left / width, right=1 - right / width, bottom=bottom / height,
                        top=1 - top / height, wspace=gap_w / axes_w, hspace=gap_h / axes_h)


def _splits_a_cell(fig) -> bool:
    """True if an axes lies in a sub-grid of a grid cell, as after ``fig.colorbar(im, ax=ax)``:
    constrained layout cannot lay such a figure out afterwards (it divides by zero), so lecture
    mode keeps the estimate for it."""
    return any(spec is not None and spec.get_topmost_subplotspec() is not spec
               for spec in (ax.get_subplotspec() for ax in fig.axes))


def _grid_cells(fig):
    """``((nrows, ncols), [(rowspan, colspan, need), ...])`` for the figure's grid of axes.

    Each axes is placed by the cell of the figure's top-level grid it lies in, so an axes that
    shares its cell with others (``fig.colorbar(im, ax=ax)`` splits the cell between the axes
    and the colorbar) only counts the sides where it reaches the cell's edge. None when
    subplots_adjust would undo a placement: axes from different grids, or an axes moved off
    its cell (``fig.colorbar(im, ax=[ax1, ax2])`` shrinks its axes by hand).
    """
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.get_subplotspec() is not None]
    if not axes:
        return None
    grid = axes[0].get_subplotspec().get_topmost_subplotspec().get_gridspec()
    spans = []
    for ax in axes:
        spec = ax.get_subplotspec()
        cell = spec.get_topmost_subplotspec()
        box = spec.get_position(fig)
        if cell.get_gridspec() is not grid or not _same_box(ax.get_position(original=True), box):
            return None
        spans.append((cell.rowspan, cell.colspan, _edge_needs(ax, box, cell.get_position(fig))))
    return grid.get_geometry(), spans


def _same_box(a, b, tol: float = 1e-9) -> bool:
    return all(abs(p - q) <= tol for p, q in zip(a.bounds, b.bounds))


def _edge_needs(ax, box, cell) -> list:
    """The axes' needs on the sides where its box reaches the edge of its grid cell, 0 elsewhere
    (inside a shared cell, the gaps belong to the sub-grid that split it)."""
    tol = 1e-9
    reaches = (box.x0 <= cell.x0 + tol, box.x1 >= cell.x1 - tol,
               box.y0 <= cell.y0 + tol, box.y1 >= cell.y1 - tol)
    return [need if edge else 0.0 for need, edge in zip(_axes_needs(ax), reaches)]


def _gap(spans, k: int, across: int) -> float:
    """Space between grid column (across=1) or row (across=0) k-1 and k, in points."""
    if across == 1:
        before = [need[1] for rows, cols, need in spans if cols.stop == k]
        after = [need[0] for rows, cols, need in spans if cols.start == k]
    else:
        before = [need[2] for rows, cols, need in spans if rows.stop == k]
        after = [need[3] for rows, cols, need in spans if rows.start == k]
    return max(before, default=0.0) + max(after, default=0.0) + _EDGE


def _axes_needs(ax) -> list:
    """[left, right, bottom, top]: points of text and ticks outside the axes box."""
    need = [0.0, 0.0, 0.0, 0.0]
    if ax.axison:
        _add_axis(ax.yaxis, need, sides=(0, 1), overhang=3)
        _add_axis(ax.xaxis, need, sides=(2, 3), overhang=1)
    titles = [ax.get_title(loc) for loc in ("left", "center", "right")]
    lines = max(_lines(text) for text in titles)
    if lines:
        from matplotlib import rcParams
        need[3] += lines * _LINE * ax.title.get_size() + rcParams["axes.titlepad"]
    return need


def _add_axis(axis, need: list, sides, overhang: int) -> None:
    """Add one axis' tick labels, ticks and label to `need` (in place); `overhang` is the
    side (top for y, right for x) past which the last tick label sticks out."""
    labels = _tick_labels(axis)
    tick = axis.get_major_ticks(1)[0] if labels else None
    vertical = axis.axis_name == "y"
    for side, label in zip(sides, (tick.label1, tick.label2) if tick else ()):
        if not label.get_visible():
            continue
        size = label.get_size()
        across = max(_width(s, size) for s in labels) if vertical else max(_height(s, size) for s in labels)
        need[side] += tick.get_tick_padding() + tick.get_pad() + across
        # the first and last labels stick out past the axes' ends by half their length
        half = (0.5 * _LINE * size if vertical else 0.5 * _width(labels[-1], size))
        need[overhang] = max(need[overhang], half)
        if vertical and axis.major.formatter.get_offset():
            need[overhang] = max(need[overhang], _LINE * size)  # the 1e-5 above the axis
    text = axis.label.get_text()
    if text:
        side = sides[0] if axis.get_label_position() in ("left", "bottom") else sides[1]
        need[side] += axis.labelpad + _lines(text) * _LINE * axis.label.get_size()


def _tick_labels(axis) -> list:
    """The major tick labels inside the view, as strings (empty if there are none)."""
    lo, hi = sorted(axis.get_view_interval())
    locs = [loc for loc in axis.get_majorticklocs() if lo <= loc <= hi]
    return [s for s in axis.major.formatter.format_ticks(locs) if s] if locs else []


def _suptitle_height(fig) -> float:
    """Points the suptitle takes at the top; one wider than the figure is wrapped."""
    text = fig.get_suptitle()
    if not text:
        return 0.0
    artist = next(t for t in fig.texts if t.get_text() == text)
    size = artist.get_size()
    width, height = fig.get_size_inches() * 72.0
    lines = sum(math.ceil(_width(line, size) / (width - 2 * _EDGE)) for line in text.split("\n"))
    artist.set_wrap(lines > _lines(text))
    # placed with its top at 98 % of the figure height
    return 0.02 * height + lines * _LINE * size


def _lines(text: str) -> int:
    return text.count("\n") + 1 if text else 0


def _plain(s: str) -> tuple[str, str]:
    """Split a tick label into its normal and its superscript characters (mathtext)."""
    s = s.replace("$", "").replace("\\mathdefault", "").replace("\\times", "\N{MULTIPLICATION SIGN}")
    base, _, sup = s.partition("^")
    strip = str.maketrans("", "", "{}\\")
    return base.translate(strip), sup.translate(strip)


def _width(s: str, size: float) -> float:
    base, sup = _plain(s)
    em = sum(_CHAR_EM.get(c, _OTHER_EM) for c in base) + _SUPERSCRIPT * sum(_CHAR_EM.get(c, _OTHER_EM) for c in sup)
    return em * size


def _height(s: str, size: float) -> float:
    return (_LINE + (0.3 if "^" in s else 0.0)) * size * _lines(s)
