"""Figures described in words, from the data they show: their text alternative.

`describe_figure(fig)` reads a matplotlib figure the way a sighted reader does:
its title, then each plot's title, axes (with their ranges and units, as the labels
give them) and what each curve does: where it starts, its highest and lowest value
and where, and where it ends; a few isolated points (poles, equilibria) are listed.
The course website gives every figure this text as its ``alt``, so a screen reader
says what the figure shows instead of a file name.
"""

from __future__ import annotations

import numpy as np

__all__ = ["describe_figure"]

#: a curve with at most this many points drawn as markers only is read as a set of points
POINTS = 8


def describe_figure(fig) -> str:
    """A few sentences saying what `fig` (a matplotlib Figure) shows, computed from its data."""
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise ValueError(f"fig must be a matplotlib Figure: received {type(fig).__name__}; "
                         "pass the figure (fig, not an Axes).")
    title = fig.get_suptitle() if hasattr(fig, "get_suptitle") else ""
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.get_label() != "<colorbar>"]
    parts = [f"{_clean(title)}." if title else ""]
    parts += [_describe_axes(ax, k, len(axes)) for k, ax in enumerate(axes, 1)]
    return " ".join(p for p in parts if p) or "An empty figure."


def _clean(text: str) -> str:
    """`text` on one line, without mathtext dollar signs."""
    return " ".join(text.replace("$", "").split())


def _describe_axes(ax, k: int, count: int) -> str:
    # an axes sharing its x axis with the one below often leaves the label to it
    x_labels = [a.get_xlabel() for a in (ax, *ax.get_shared_x_axes().get_siblings(ax)) if a.get_xlabel()]
    x, y = _clean(x_labels[0]) if x_labels else "x", _clean(ax.get_ylabel()) or "y"
    head = f"Plot {k} of {count}" if count > 1 else "The plot"
    title = f" ({_clean(ax.get_title())})" if ax.get_title() else ""
    lo, hi = ax.get_xlim()
    scale = ", on a logarithmic scale" if ax.get_yscale() == "log" else ""
    sentences = [f"{head}{title} shows {y} against {x}, from {_num(lo)} to {_num(hi)}{scale}."]
    for line in ax.get_lines():
        if not line.get_label().startswith("_") or not _reference_line(line):
            sentences.append(_describe_line(line, x))
    return " ".join(s for s in sentences if s)


def _reference_line(line) -> bool:
    """An unlabelled horizontal or vertical line (a zero line, a marked time): not data."""
    xs, ys = (np.asarray(v, dtype=float) for v in line.get_data())
    drawn = line.get_linestyle() not in ("None", "", " ")
    return drawn and xs.size == 2 and (np.ptp(xs) == 0 or np.ptp(ys) == 0)


def _describe_line(line, x_name: str) -> str:
    xs, ys = (np.asarray(v, dtype=float) for v in line.get_data())
    keep = np.isfinite(xs) & np.isfinite(ys)
    if not line.get_visible() or keep.sum() == 0:
        return ""
    xs, ys = xs[keep], ys[keep]
    name = line.get_label()
    name = _clean(name) if name and not name.startswith("_") else "A curve"
    if line.get_linestyle() in ("None", "", " ") and xs.size <= POINTS:
        points = ", ".join(f"({_num(a)}, {_num(b)})" for a, b in zip(xs, ys))
        return f"{name}: points at {points}."
    if np.ptp(xs) == 0:
        return f"{name}: a vertical line at {x_name} = {_num(xs[0])}."
    if np.ptp(ys) == 0:
        return f"{name}: constant at {_num(ys[0])}."
    top, low = int(np.argmax(ys)), int(np.argmin(ys))
    return (f"{name}: starts at {_num(ys[0])}, highest {_num(ys[top])} at {x_name} = {_num(xs[top])}, "
            f"lowest {_num(ys[low])} at {_num(xs[low])}, ends at {_num(ys[-1])}.")


def _num(value: float) -> str:
    return f"{value:.3g}".replace("-", "−") if abs(value) >= 1e-12 else "0"
