"""A checker for figure layout, used by the tests: text outside the figure, text on text.

`text_problems(fig)` draws the figure with Agg and records every piece of text
the renderer actually draws (titles, axis labels, tick labels, offset texts,
legend entries, annotations, the suptitle, colorbar labels), each with the axes
it belongs to. It reports, as readable strings:

* text that reaches outside the figure canvas by more than `TOLERANCE` pixels;
* text of one axes overlapping text of another axes, or the figure's own text
  (suptitle, figure legend) overlapping any axes' text;
* text of one axes running into the box of another axes;
* a legend's frame overlapping text of another axes;
* two frame texts of the same axes (tick labels, axis labels, title, offset
  text) overlapping each other, e.g. crowded tick labels.

`legend_problems(fig)` reports legends that hide much of a curve of their axes.
"""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text
from matplotlib.transforms import Bbox

__all__ = ["TOLERANCE", "drawn_texts", "drawn_strings", "text_problems", "legend_problems"]

#: pixels a text may reach past the canvas or into another text (anti-aliasing, rounding)
TOLERANCE = 1.0


def _draw_calling(fig, on_text) -> object:
    """Draw `fig` with Agg, calling ``on_text(s, ismath, mtext)`` for every piece of text the
    renderer draws; return the renderer."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    renderer = canvas.get_renderer()
    original = renderer.draw_text

    def draw_text(gc, x, y, s, prop, angle, ismath=False, mtext=None):
        on_text(s, ismath, mtext)
        return original(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)

    renderer.draw_text = draw_text
    try:
        canvas.draw()
    finally:
        del renderer.draw_text
    return canvas.get_renderer()


def _draw_recording(fig) -> tuple[list[Text], object]:
    """Draw `fig` with Agg; return the Text artists drawn (in the order they were drawn, those of
    several lines last), and the renderer.

    matplotlib names the artist only for a text of one line: a text of several lines (a "\\n" in
    it, or wrapped) is drawn line by line without it, and is found here by its first line."""
    drawn: dict[int, Text] = {}
    lines: set[str] = set()

    def record(s, ismath, mtext):
        if mtext is not None:
            drawn.setdefault(id(mtext), mtext)
        elif s.strip():
            lines.add(" ".join(s.split()))

    renderer = _draw_calling(fig, record)
    for text in fig.findobj(Text):
        words = " ".join(text.get_text().split())
        if id(text) not in drawn and text.get_visible() and any(words.startswith(line) for line in lines):
            drawn[id(text)] = text
    return list(drawn.values()), renderer


def drawn_strings(fig) -> list[tuple[str, bool]]:
    """(string, drawn as mathtext) for every piece of text the Agg renderer draws in `fig`."""
    drawn = []
    _draw_calling(fig, lambda s, ismath, mtext: drawn.append((s, bool(ismath))))
    return drawn


def _owners(fig) -> dict[int, tuple[int, object]]:
    """id(Text) -> (axes index, axes) for every Text inside an axes (its axis, ticks, legend)."""
    owners = {}
    for i, ax in enumerate(fig.axes):
        for text in ax.findobj(Text):
            owners.setdefault(id(text), (i, ax))
    return owners


def _frame_texts(ax) -> set[int]:
    """ids of the texts around an axes' frame: titles, axis labels, tick labels, offset texts."""
    texts = [ax.title, *(getattr(ax, name) for name in ("_left_title", "_right_title") if hasattr(ax, name))]
    for axis in (ax.xaxis, ax.yaxis):
        texts += [axis.label, axis.get_offset_text()]
        for tick in axis.get_major_ticks() + axis.get_minor_ticks():
            texts += [tick.label1, tick.label2]
    return {id(t) for t in texts}


def drawn_texts(fig) -> list[dict]:
    """Every text drawn: dicts with ``text`` (the artist), ``box`` (window extent, clipped),
    ``owner`` (axes index or None for the figure's own), ``frame`` (True for the texts around
    an axes' frame) and ``name`` (for messages). Draws the figure."""
    texts, renderer = _draw_recording(fig)
    owners = _owners(fig)
    frames = set().union(*(_frame_texts(ax) for ax in fig.axes)) if fig.axes else set()
    out = []
    for text in texts:
        box = text.get_window_extent(renderer)
        clip = text.get_clip_box() if text.get_clip_on() else None
        if clip is not None:
            box = Bbox.intersection(box, clip)
            if box is None:
                continue
        index, ax = owners.get(id(text), (None, None))
        where = "the figure" if ax is None else f"axes {index} ({ax.get_title()!r})" if ax.get_title() \
            else f"axes {index}"
        out.append(dict(text=text, box=box, owner=index, frame=id(text) in frames,
                        name=f"{text.get_text()!r} of {where}"))
    return out


def _overlap(a, b) -> bool:
    """True if the boxes share more than TOLERANCE pixels in both directions."""
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > TOLERANCE
            and min(a.y1, b.y1) - max(a.y0, b.y0) > TOLERANCE)


def text_problems(fig) -> list[str]:
    """Every layout problem of the figure's text, as messages (empty: the layout is right)."""
    items = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    width, height = fig.canvas.get_width_height()
    problems = []
    for item in items:
        box = item["box"]
        if box.x0 < -TOLERANCE or box.y0 < -TOLERANCE or box.x1 > width + TOLERANCE \
                or box.y1 > height + TOLERANCE:
            problems.append(f"outside the figure ({width} x {height} px): {item['name']} at "
                            f"x {box.x0:.0f}..{box.x1:.0f}, y {box.y0:.0f}..{box.y1:.0f}")
    for k, a in enumerate(items):
        for b in items[k + 1:]:
            different = a["owner"] != b["owner"] or a["owner"] is None
            same_frame = a["owner"] == b["owner"] and a["frame"] and b["frame"]
            if (different or same_frame) and _overlap(a["box"], b["box"]):
                problems.append(f"overlap: {a['name']} and {b['name']}")
    boxes = [(i, ax.get_window_extent(renderer)) for i, ax in enumerate(fig.axes) if ax.get_visible()]
    for item in items:
        for i, box in boxes:
            if item["owner"] is not None and item["owner"] != i and _overlap(item["box"], box):
                problems.append(f"into axes {i}: {item['name']}")
    for i, ax in enumerate(fig.axes):
        legend = ax.get_legend()
        if legend is None or not legend.get_visible():
            continue
        frame = legend.get_window_extent(renderer)
        for item in items:
            if item["owner"] not in (i, None) and _overlap(frame, item["box"]):
                problems.append(f"overlap: the legend of axes {i} and {item['name']}")
    return problems


def legend_problems(fig, *, covered: float = 0.15) -> list[str]:
    """Legends inside their axes that hide more than `covered` of the points of one of its
    labelled lines (in display space; the figure must have been drawn)."""
    renderer = fig.canvas.get_renderer()
    problems = []
    for i, ax in enumerate(fig.axes):
        legend = ax.get_legend()
        if legend is None or not legend.get_visible():
            continue
        frame = legend.get_window_extent(renderer)
        for line in ax.get_lines():
            xy = line.get_xydata()
            if line.get_label().startswith("_") or len(xy) < 2:
                continue
            points = line.get_transform().transform(xy)
            inside = ((points[:, 0] > frame.x0) & (points[:, 0] < frame.x1)
                      & (points[:, 1] > frame.y0) & (points[:, 1] < frame.y1))
            if inside.mean() > covered:
                problems.append(f"the legend of axes {i} hides {inside.mean():.0%} of the line "
                                f"{line.get_label()!r}")
    return problems
