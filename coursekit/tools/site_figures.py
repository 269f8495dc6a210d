"""The course website's figures: drawn for the page's column, and what the page records about them.

At a 1,280-px browser window the site's theme (sphinx-book-theme) shows a notebook's outputs in a
column 688 CSS px wide (measured in Chromium; ``tests/test_site_browser.py`` checks the result).
The browser scales a wider figure down to the column, and its text with it: the 10-point tick
labels of a 13-inch figure (1,300 px) would be 7 px. So the kernel that executes a notebook for
the site draws each figure *for the column*: when the smallest text of a figure would be shown
below `MIN_TEXT_PX`, the figure is drawn with its size in inches divided by a factor z and its
resolution multiplied by z. The PNG keeps its pixel size and its shape, and everything drawn on
it (text, lines, markers) is z times larger; constrained layout lays the figure out anew at that
size. The figure object in the notebook is left as it was, and JupyterLab shows the notebooks'
figures as they are: only the site's kernel draws this way.

`install(shell)` sets it up in that kernel (the site build runs it before the notebook's first
cell): the PNG of every figure and every explorer is drawn for the column, and each gets two
more outputs the build reads and removes: its description (`ALT`, the image's ``alt``) and the
size of its smallest text in points (`SMALLEST_TEXT`, which the site records per image).
"""

from __future__ import annotations

import contextlib

from IPython.core.formatters import BaseFormatter, PNGFormatter

from .notebooks import ALT
from .site import SMALLEST_TEXT

__all__ = ["COLUMN_PX", "MIN_TEXT_PX", "smallest_text_pt", "column_zoom",
           "drawn_for_the_column", "explorer_png", "FigureOutput", "ColumnPNGFormatter", "add_output",
           "install"]

#: width in CSS px of the site's output column at a 1,280-px window
COLUMN_PX = 688
#: the smallest text a figure of the site shows, in CSS px: 11 px (the site's promise) and a
#: margin for the rounding of image sizes in the browser
MIN_TEXT_PX = 11.5


def _shown_texts(artist):
    """The visible, non-empty Text artists under `artist` (an invisible parent hides its texts)."""
    from matplotlib.text import Text
    for child in artist.get_children():
        if not child.get_visible():
            continue
        if isinstance(child, Text) and child.get_text().strip():
            yield child
        yield from _shown_texts(child)


def smallest_text_pt(fig, *, drawn: bool = False) -> float | None:
    """The font size in points of the smallest text `fig` shows (tick labels, legends, titles,
    annotations, ...), None for a figure without text. Lays the figure out (draws it without
    rendering), so that its tick labels exist, unless `drawn` says it was just drawn as it is
    (a second layout and draw would find the same texts: an explorer's frame, 40 % of its cost)."""
    if not drawn:
        fig.draw_without_rendering()
    return min((text.get_fontsize() for text in _shown_texts(fig)), default=None)


def column_zoom(fig, dpi: float | None = None) -> float:
    """The factor z (>= 1) by which `fig`, rendered at `dpi` (default: its own), is drawn for the
    column: the smallest z that shows its smallest text at `MIN_TEXT_PX` or more."""
    dpi = float(fig.dpi if dpi is None else dpi)
    smallest = smallest_text_pt(fig)
    if smallest is None:
        return 1.0
    width_px = fig.get_figwidth() * dpi
    shown_px = smallest / 72 * dpi * min(1.0, COLUMN_PX / width_px)
    return max(1.0, MIN_TEXT_PX / shown_px)


@contextlib.contextmanager
def drawn_for_the_column(fig, dpi: float | None = None):
    """While in the block, `fig` is set to be drawn for the column at `dpi` (default: its own):
    its size in inches divided by `column_zoom`, its resolution multiplied by it (the same
    pixels). Yields the zoom; restores the figure's size and resolution afterwards."""
    dpi = float(fig.dpi if dpi is None else dpi)
    zoom = column_zoom(fig, dpi)
    size, own_dpi = fig.get_size_inches().copy(), fig.dpi
    fig.set_size_inches(size / zoom)
    fig.set_dpi(dpi * zoom)
    try:
        yield zoom
    finally:
        fig.set_size_inches(size)
        fig.set_dpi(own_dpi)


def explorer_png(explorer) -> bytes:
    """The static figure of `explorer` for the site: at its natural resolution, drawn for the column."""
    with drawn_for_the_column(explorer.fig, explorer.natural_dpi):
        png = explorer.frames.frame()
    explorer.frames.frame()      # the explorer's own frame again, at the size it had
    return png


class FigureOutput(BaseFormatter):
    """A display formatter that adds ``function(fig)`` (a string) to the display data of every
    matplotlib figure shown, and with ``explorers=True`` of every explorer (for its figure).

    It recognises figures itself instead of by a registered type: the inline backend removes
    every formatter's entry for figures each time it is switched on."""

    def __init__(self, format_type: str, function, *, explorers: bool, **kwargs):
        super().__init__(format_type=format_type, **kwargs)
        self.function, self.explorers = function, explorers

    def __call__(self, obj):
        from matplotlib.figure import Figure

        from ..explorers import Explorer
        fig = obj.fig if self.explorers and isinstance(obj, Explorer) else obj
        return self.function(fig) if isinstance(fig, Figure) else None


class ColumnPNGFormatter(PNGFormatter):
    """IPython's PNG formatter, which draws each figure for the site's column while the printer
    registered for figures (the inline backend's) makes its PNG."""

    def __call__(self, obj):
        from matplotlib.figure import Figure
        if not isinstance(obj, Figure):
            return super().__call__(obj)
        with drawn_for_the_column(obj):
            return super().__call__(obj)


def add_output(shell, format_type: str, function, *, explorers: bool) -> None:
    """Make `shell` add ``function(fig)`` under `format_type` to the display data of every figure
    it shows (and of every explorer, with `explorers`): see `FigureOutput`."""
    display = shell.display_formatter
    display.formatters[format_type] = FigureOutput(format_type, function, explorers=explorers, parent=display)
    display.active_types = [*display.active_types, format_type]


def install(shell) -> None:
    """Set up `shell` (the kernel executing a notebook for the site): figures and explorers drawn
    for the column, each with its description (`ALT`) and smallest text size (`SMALLEST_TEXT`)."""
    from ..describe import describe_figure
    from ..explorers import Explorer
    display = shell.display_formatter
    old = display.formatters["image/png"]
    png = ColumnPNGFormatter(parent=display)
    png.type_printers.update(old.type_printers)
    png.deferred_printers.update(old.deferred_printers)
    # a printer registered for explorers takes the place of the static figure of their bundle
    png.for_type(Explorer, explorer_png)
    display.formatters["image/png"] = png
    add_output(shell, ALT, describe_figure, explorers=False)
    add_output(shell, SMALLEST_TEXT, lambda fig: repr(smallest_text_pt(fig)), explorers=True)
    from . import static_explorers        # the explorers' frames, live on the page without a kernel
    static_explorers.install(shell, column=True)
