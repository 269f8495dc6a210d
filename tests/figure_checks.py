"""Checks that a figure can be read by every student, used by the tests: colours, line styles, contrast.

`style_problems(fig)` reports, as readable strings:

* a line or a labelled patch in a colour outside `coursekit.PALETTE` (greys, which differ from
  each other in lightness only, are allowed: a colour-blind reader sees them as they are);
* two curves of one axes that differ by colour alone: lines with different labels (an unlabelled
  line counts by its colour; a straight unlabelled reference line, such as a zero line, does not
  count) must differ in line style or marker (two lines of one colour and look, one labelled and
  one not, are more of the same curve; two of different labels are told apart by nothing);
* a curve that does not start where its label or its axes' title says it starts (`start_problems`:
  "start 10 deg", "x0 = -2", "released from 2 rad", "x(0) = [1, 0]"), in sign and unit;
* drawn text with less than 4.5:1 contrast (WCAG 2.1 1.4.3) against what it is drawn on: the
  legend's frame for legend text, a text's own box, the axes for text inside an axes, and the
  figure elsewhere, each painted over the layers below it and over a white page.
"""

from __future__ import annotations

import itertools
import re

import numpy as np
from matplotlib.colors import to_hex, to_rgba
from matplotlib.lines import Line2D

import coursekit as ck
from layout_check import drawn_texts

__all__ = ["MIN_TEXT_CONTRAST", "COVERED", "style_problems", "figure_report", "colour_problems", "curve_problems", "contrast_problems",
           "start_problems"]

#: WCAG 2.1 AA for text (1.4.3)
MIN_TEXT_CONTRAST = 4.5
#: a legend inside its axes may hide at most this fraction of the points of a curve (as in
#: tests/test_figure_layout.py)
COVERED = 0.2

_PALETTE = {to_hex(c) for c in ck.PALETTE.values()}


def style_problems(fig) -> list[str]:
    """Every problem of `fig` this module checks for (empty: none). Draws the figure."""
    return colour_problems(fig) + curve_problems(fig) + contrast_problems(fig)


def _grey(colour) -> bool:
    r, g, b, _ = to_rgba(colour)
    return max(r, g, b) - min(r, g, b) < 1e-6


def _colours(artist) -> list:
    """The colours an artist paints: a line's line and marker colours, a patch's or collection's faces."""
    if isinstance(artist, Line2D):
        out = [artist.get_color()]
        if artist.get_marker() not in ("None", "", " ", None):
            out += [c for c in (artist.get_markerfacecolor(), artist.get_markeredgecolor())
                    if not (isinstance(c, str) and c == "none")]
        return out
    faces = artist.get_facecolor()
    return list(np.atleast_2d(faces)) if np.size(faces) else []


def _where(ax, index: int) -> str:
    return f"axes {index} ({ax.get_title()!r})" if ax.get_title() else f"axes {index}"


def colour_problems(fig) -> list[str]:
    """Lines, and patches or collections with a legend label, in a colour neither of the palette
    nor grey."""
    problems = []
    for i, ax in enumerate(fig.axes):
        labelled = [a for a in (*ax.patches, *ax.collections) if not a.get_label().startswith("_")]
        for artist in (*ax.get_lines(), *labelled):
            for colour in _colours(artist):
                if to_rgba(colour)[3] > 0 and not _grey(colour) and to_hex(colour) not in _PALETTE:
                    problems.append(f"colour {to_hex(colour)} is not in the palette: {artist.get_label()!r} "
                                    f"of {_where(ax, i)}")
    return problems


def _reference(line) -> bool:
    """An unlabelled straight horizontal or vertical line (a zero line, a marked time): not a curve."""
    xs, ys = (np.asarray(v, dtype=float) for v in line.get_data())
    return line.get_label().startswith("_") and xs.size == 2 and (np.ptp(xs) == 0 or np.ptp(ys) == 0)


def _identity(line) -> str:
    label = line.get_label()
    return label if not label.startswith("_") else f"an unlabelled {to_hex(line.get_color())} curve"


def _look(line) -> tuple:
    marker = line.get_marker()
    return line.get_linestyle(), "None" if marker in ("None", "", " ", None) else str(marker)


def curve_problems(fig) -> list[str]:
    """Pairs of curves of one axes that differ by colour alone (or by nothing: see the module)."""
    problems = []
    for i, ax in enumerate(fig.axes):
        curves = {}
        for line in ax.get_lines():
            if line.get_visible() and (line.get_alpha() is None or line.get_alpha() > 0) and not _reference(line):
                curves.setdefault(_identity(line), (_look(line), to_hex(line.get_color())))
        for (a, (look_a, colour_a)), (b, (look_b, colour_b)) in itertools.combinations(curves.items(), 2):
            labelled = not a.startswith("an unlabelled") and not b.startswith("an unlabelled")
            if look_a == look_b and (colour_a != colour_b or labelled):
                how = "colour alone" if colour_a != colour_b else "nothing"
                problems.append(f"{a!r} and {b!r} of {_where(ax, i)} differ by {how} "
                                f"(both line style {look_a[0]!r}, marker {look_a[1]!r})")
    return problems


#: a start stated in a curve's label: "start 10 deg", "x0 = -2", "nonlinear pendulum, 0.6 rad"
_LABEL_START = re.compile(r"(?:\bstart\s+|\bx0 = )(-?\d+(?:\.\d+)?)(?:\s*(deg|rad)\b)?|, (-?\d+(?:\.\d+)?) (deg|rad)$")
#: a start stated in a title: "released from 2 rad"; "x(0) = [1, 0, 0]"
_TITLE_FROM = re.compile(r"\bfrom (-?\d+(?:\.\d+)?) (deg|rad)\b")
_TITLE_VECTOR = re.compile(r"\bx\(0\) = \[([-\d., ]+)\]")


def _curves(ax) -> list:
    """The curves of `ax` that can have a start: neither a point nor a straight level line (axhline)."""
    def level(line):
        xs, ys = (np.asarray(v, dtype=float) for v in line.get_data())
        return xs.size == 2 and (np.ptp(xs) == 0 or np.ptp(ys) == 0)
    return [line for line in ax.get_lines() if line.get_visible() and np.size(line.get_xdata()) > 1
            and not level(line)]


def _first(line) -> tuple[float, float]:
    x, y = (np.asarray(v, dtype=float) for v in line.get_data())
    return float(x[0]), float(y[0])


def _unit_ok(ax, unit) -> bool:
    """A stated unit is the unit of the axes' vertical axis (no unit stated: any)."""
    return unit is None or f"[{unit}]" in ax.get_ylabel()


def _stated(pattern, text: str) -> tuple[float, str | None] | None:
    """(value, unit or None) of the first start `pattern` finds in `text`, or None."""
    found = pattern.search(text)
    if not found:
        return None
    value, unit = (found.groups() + (None,))[:2] if found.group(1) is not None else found.groups()[2:4]
    return float(value), unit


def _stated_starts(ax) -> dict:
    """{curve: (x0 or None, y0)}: the starts the curves' labels or the axes' title state."""
    curves, stated = _curves(ax), {}
    for line in curves:
        found = _stated(_LABEL_START, line.get_label()) or _stated(_TITLE_FROM, ax.get_title())
        if found and _first(line)[0] == 0 and _unit_ok(ax, found[1]):
            stated[line] = (None, found[0])
    vector = _TITLE_VECTOR.search(ax.get_title())
    if vector and not stated:
        values = [float(v) for v in vector.group(1).split(",")]
        if len(curves) == 1 and _first(curves[0])[0] != 0:          # a state plane: the point x(0)
            stated[curves[0]] = tuple(values[:2])
        elif len(curves) == len(values):                              # one curve per state
            stated.update({line: (None, v) for line, v in zip(curves, values)})
    return stated


def start_problems(fig) -> list[str]:
    """Curves of a time response (from t = 0) that do not start at the value their label or
    their axes' title states, and a state-plane curve that does not start at the stated x(0)."""
    problems = []
    for i, ax in enumerate(fig.axes):
        for line, (x0, y0) in _stated_starts(ax).items():
            x, y = _first(line)
            if not np.isclose(y, y0, atol=1e-6) or (x0 is not None and not np.isclose(x, x0, atol=1e-6)):
                shown, said = ((f"{y:g}", f"{y0:g}") if x0 is None else (f"({x:g}, {y:g})", f"({x0:g}, {y0:g})"))
                problems.append(f"{_identity(line)!r} of {_where(ax, i)} starts at {shown}, its text states {said}")
    return problems


def _paint(colour, below) -> tuple:
    """`colour` with its alpha painted over the opaque colour `below`: an opaque RGB."""
    *rgb, alpha = to_rgba(colour)
    return tuple(alpha * np.asarray(rgb) + (1 - alpha) * np.asarray(to_rgba(below)[:3]))


def _legends(fig) -> dict:
    """id(text) -> legend, for the texts of every legend (of an axes or of the figure)."""
    legends = [*(ax.get_legend() for ax in fig.axes), *fig.legends]
    return {id(t): lg for lg in legends if lg is not None for t in (*lg.get_texts(), lg.get_title())}


def _ground(box, fig, renderer) -> tuple:
    """The opaque colour under the centre of `box` (display coordinates): an axes or the figure."""
    page = _paint(fig.patch.get_facecolor(), "white")
    x, y = (box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2
    for ax in reversed(fig.axes):
        if ax.get_visible() and ax.patch.get_visible() and ax.get_window_extent(renderer).contains(x, y):
            return _paint(ax.patch.get_facecolor(), page)
    return page


def _background(item, fig, renderer, legends) -> tuple:
    text = item["text"]
    legend = legends.get(id(text))
    if legend is not None:
        frame = legend.get_frame()
        ground = _ground(legend.get_window_extent(renderer), fig, renderer)
        return _paint(frame.get_facecolor(), ground) if legend.get_frame_on() else ground
    ground = _ground(item["box"], fig, renderer)
    patch = text.get_bbox_patch()
    return _paint(patch.get_facecolor(), ground) if patch is not None and patch.get_visible() else ground


def contrast_problems(fig) -> list[str]:
    """Drawn texts with less than `MIN_TEXT_CONTRAST` against their background."""
    items = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    legends = _legends(fig)
    problems = []
    for item in items:
        text = item["text"]
        if not text.get_text().strip():
            continue
        colour = to_rgba(text.get_color(), text.get_alpha())
        ratio = ck.contrast_ratio(colour, _background(item, fig, renderer, legends))
        if ratio < MIN_TEXT_CONTRAST:
            problems.append(f"contrast {ratio:.2f}:1 (below {MIN_TEXT_CONTRAST}): {item['name']} in "
                            f"{to_hex(colour, keep_alpha=True)}")
    return problems


def figure_report(fig) -> dict:
    """Problems of `fig` by kind: ``style`` (`style_problems`), ``start`` (`start_problems`),
    ``layout`` (text outside the figure
    or on other text, legends hiding curves: `layout_check`) and ``site layout`` (the same, with
    the figure drawn for the website's column: `coursekit.tools.site_figures`)."""
    from coursekit.tools.site_figures import drawn_for_the_column
    from layout_check import legend_problems, text_problems

    def layout():
        return text_problems(fig) + legend_problems(fig, covered=COVERED)
    report = {"style": style_problems(fig), "layout": layout(), "start": start_problems(fig)}
    with drawn_for_the_column(fig) as zoom:
        report["site layout"] = [f"{problem} (drawn {zoom:.2f} times larger)" for problem in layout()]
    return report
