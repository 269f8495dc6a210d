"""Figure layout: matplotlib's constrained layout, with the course's spacing.

`fit_margins` hands a figure to matplotlib's constrained layout engine, which
measures every tick label, axis label, title, legend placed outside its axes,
colorbar and suptitle each time the figure is drawn, and sizes the margins and
the gaps between axes to fit them. Because it measures the text as drawn, the
layout stays right for any font size and font family: lecture mode, a serif
font, ``font.size: 18``. Measuring costs time at every draw (matplotlib measures
the text of every axes twice, so a draw takes about one and a half to three times as
long as one with fixed margins); the explorers keep their slider redraws fast by
other means.

Two things constrained layout does not do, and `fit_margins` adds: a suptitle
or an axes title wider than the figure breaks into lines instead of running
off its edges, and it breaks only at spaces outside mathtext, so that a
formula in ``$...$`` is never cut in two (and its halves drawn as raw text).
What it cannot do is keep a title wider than its own axes out of the
neighbouring axes' title; coursekit's figures keep their titles short enough
(or on two lines) for that, and a test checks every one of them.
"""

from __future__ import annotations

import functools

__all__ = ["fit_margins"]

#: space around each axes' decorations and at the figure's edges, in inches (4 points)
_W_PAD = _H_PAD = 4 / 72
#: extra space between neighbouring axes, as a fraction of the figure's width (height)
_WSPACE = _HSPACE = 0.02

_engine_class = None


def fit_margins(fig):
    """Lay the figure out with constrained layout; returns the figure.

    Sets on `fig` matplotlib's constrained layout engine with the course's
    pads (4 points around each axes' text, 2 % of the figure between axes): each time the figure is
    drawn, its margins and the gaps between its axes are measured from the
    text they hold, so tick labels, axis labels, titles, colorbars, legends
    placed outside the axes and the suptitle stay inside the figure and clear
    of the neighbouring axes, whatever the font size (lecture mode too). A
    suptitle or title wider than the figure is wrapped onto several lines.
    Every figure coursekit draws uses it (`coursekit.style.new_figure`).

    Call it before adding colorbars (``fig.colorbar(im, ax=ax)`` then makes room
    in a way the engine can lay out); a figure that already has a layout engine
    (``fig.set_layout_engine``, ``plt.subplots(layout=...)``) keeps it, and calling
    `fit_margins` again changes nothing. Raises ValueError if `fig` is not a
    Figure, or if a colorbar was added to it, without an engine, in a way
    constrained layout cannot handle.
    """
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise ValueError(f"fig must be a matplotlib Figure: received {type(fig).__name__}; "
                         "pass the figure (fig, not an Axes), e.g. fig, ax = new_figure().")
    if fig.get_layout_engine() is not None:
        return fig
    if _splits_a_cell(fig):
        raise ValueError("fig has a colorbar that splits an axes' grid cell (fig.colorbar(im, ax=ax) "
                         "called before fit_margins), which constrained layout cannot lay out: "
                         "call ck.fit_margins(fig) first, then add the colorbar.")
    global _engine_class
    if _engine_class is None:
        _engine_class = _make_engine_class()
    fig.set_layout_engine(_engine_class(w_pad=_W_PAD, h_pad=_H_PAD, wspace=_WSPACE, hspace=_HSPACE))
    return fig


def _splits_a_cell(fig) -> bool:
    """True if an axes lies in a sub-grid of a grid cell, as after ``fig.colorbar(im, ax=ax)``
    on a figure without a layout engine (constrained layout divides by zero on it)."""
    return any(spec is not None and spec.get_topmost_subplotspec() is not spec
               for spec in (ax.get_subplotspec() for ax in fig.axes))


def _make_engine_class():
    """The engine class, defined on first use (matplotlib loads lazily)."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    class CourseLayout(ConstrainedLayoutEngine):
        """Constrained layout that first lets the suptitle and the axes titles wrap at the
        figure's edges (matplotlib's ``Text.set_wrap``), so that none runs off the figure,
        breaking their lines only at spaces outside mathtext (`_wrap_outside_math`)."""

        def execute(self, fig):
            for text in _titles(fig):
                text.set_wrap(True)
                text._get_wrapped_text = functools.partial(_wrap_outside_math, text)
            return super().execute(fig)

    return CourseLayout


def _titles(fig) -> list:
    """The suptitle (if any) and every axes' three titles."""
    suptitle = fig.get_suptitle()
    texts = [t for t in fig.texts if suptitle and t.get_text() == suptitle][:1]
    for ax in fig.axes:
        texts += [ax.title, *(getattr(ax, name) for name in ("_left_title", "_right_title")
                              if hasattr(ax, name))]
    return texts


def _wrap_outside_math(text) -> str:
    """The string of `text` broken into lines that fit the figure, at spaces outside ``$...$``.

    matplotlib's own wrapping (``Text._get_wrapped_text``, which this replaces on the titles)
    breaks at any space, also inside a mathtext formula, whose halves are then drawn as raw
    text with their dollar signs. Here a formula stays whole on one line; otherwise the
    lines are filled the same way: as many words as fit the width matplotlib allows the
    text (``Text._get_wrap_line_width``), measured as drawn.
    """
    if not text.get_wrap() or text.get_usetex():
        return text.get_text()
    width = text._get_wrap_line_width()
    lines = []
    for source_line in text.get_text().split("\n"):
        words = _words_outside_math(source_line)
        while words:
            count = _words_that_fit(words, width, text._get_rendered_text_width)
            lines.append(" ".join(words[:count]))
            words = words[count:]
    return "\n".join(lines)


def _words_that_fit(words: list[str], width: float, measure) -> int:
    """How many of `words` go on one line: the most whose line, joined by spaces, `measure`s at
    most `width` pixels, and at least one.

    Each line is measured as drawn. A title redrawn for every slider position carries numbers
    that change, so those measurements are new each time (about a millisecond each): rather
    than measuring the line once per word added, the count is guessed from the widths of the
    single words (most of which matplotlib has measured before) and then settled by measuring
    the line with that many words and with one more, usually two measurements per line. A
    line is wider for every word added, so this is the count that adding words one at a time
    until the next would not fit arrives at.
    """
    space = measure("x x") - 2 * measure("x")
    count, used = 0, -space
    for word in words:
        used += space + measure(word)
        if used > width:
            break
        count += 1

    def fits(k: int) -> bool:
        return k == 1 or measure(" ".join(words[:k])) <= width

    count = max(count, 1)
    while not fits(count):
        count -= 1
    while count < len(words) and fits(count + 1):
        count += 1
    return count


def _words_outside_math(line: str) -> list[str]:
    """`line` split at the spaces outside its ``$...$`` formulas (at every space if its dollar
    signs do not pair up, as matplotlib then draws it as plain text)."""
    dollars = [k for k, char in enumerate(line) if char == "$" and (k == 0 or line[k - 1] != "\\")]
    if len(dollars) < 2 or len(dollars) % 2:
        return line.split(" ")
    words, start, inside = [], 0, False
    for k, char in enumerate(line):
        if k in dollars:
            inside = not inside
        elif char == " " and not inside:
            words.append(line[start:k])
            start = k + 1
    return words + [line[start:]]
