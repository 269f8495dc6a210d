"""Frames of an explorer figure: a full draw when the axes change, blitting otherwise.

The artists an update moves (matplotlib marks them *stale*) are made *animated*; a full draw
without them is kept as the background, and a frame restores it and draws the moving artists and
every later artist that can meet them (a legend on the data), so it shows what a full draw would.
A full draw happens again only when the background changes (limits, labels, size, a new artist).
"""

from __future__ import annotations

import struct
import zlib
from operator import attrgetter

import numpy as np

__all__ = ["FrameRenderer", "encode_png"]


def encode_png(rgba, dpi: float) -> bytes:
    """PNG bytes of an RGBA buffer, fast: rows unfiltered (a figure compresses about as well so; Pillow's
    filter chosen row by row took 3/4 of the time), zlib level 1, no alpha channel when all is opaque."""
    pixels = np.asarray(rgba)
    if pixels[..., 3].min() == 255:
        pixels = pixels[..., :3]
    height, width, channels = pixels.shape
    rows = np.zeros((height, 1 + width * channels), dtype=np.uint8)   # each row: filter 0, its bytes
    rows[:, 1:].reshape(height, width, channels)[...] = pixels
    chunks = [(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2 if channels == 3 else 6, 0, 0, 0)),
              (b"pHYs", struct.pack(">IIB", *[round(dpi / 0.0254)] * 2, 1)),    # dots per metre
              (b"IDAT", zlib.compress(rows, 1)), (b"IEND", b"")]
    return b"\x89PNG\r\n\x1a\n" + b"".join(struct.pack(">I", len(data)) + kind + data
                                         + struct.pack(">I", zlib.crc32(kind + data)) for kind, data in chunks)


class FrameRenderer:
    """Renders successive frames of one figure as PNG bytes, blitting where it can; ``full_draws``
    and ``blits`` count how the frames were made, `reset` makes the next frame a full draw."""

    def __init__(self, fig):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        self.fig = fig
        self.canvas = FigureCanvasAgg(fig)
        self.moving: set = set()
        self._animated: list = []
        self._background = None
        self._key = self._layout = self._meets_key = None    # _meets: artist -> meets its axes' data
        self.full_draws = self.blits = 0

    def reset(self) -> None:
        """Forget the background: the next frame is a full draw (`relayout` forgets the layout)."""
        self._background = None

    def frame(self) -> bytes:
        """The figure as it is now, as PNG bytes (blitted when only moving artists changed). The
        artists changed since the last frame (all before the first) move from the second on."""
        self.render()
        return encode_png(self.canvas.buffer_rgba(), self.fig.dpi)

    def relayout(self) -> None:
        """Lay the figure out anew at the next full draw, even when its text measures as before."""
        self._layout = None

    def changed(self) -> set:
        """The artists that can move and changed since they were last drawn (matplotlib's *stale*)."""
        return {a for a in self._children() if a.stale}

    def render(self) -> None:
        """`frame` without the PNG: ``canvas.buffer_rgba()`` then shows the figure as it is now."""
        changed = self.changed() if self.full_draws else set()
        new, self.moving = changed - self.moving, self.moving | changed
        if self._background is None or new or self.state() != self._key:
            self._full_draw()
        else:
            self.canvas.restore_region(self._background)
            self._draw_animated()
            self.blits += 1

    def _children(self):
        """What can move: the axes' and the figure's children but the axes, their axis and patch."""
        from matplotlib.axes import Axes
        from matplotlib.axis import Axis
        for parent in (*self.fig.axes, self.fig):
            yield from (a for a in parent.get_children()
                        if a is not parent.patch and not isinstance(a, (Axes, Axis)))

    def _text(self):
        """The text and scales around the axes, and the figure's size and resolution."""
        axes = tuple((ax.get_xlabel(), ax.get_ylabel(), ax.get_title(), ax.get_visible(), ax.get_xscale(),
                      ax.get_yscale()) for ax in self.fig.axes)
        return self.fig.dpi, tuple(self.fig.get_size_inches()), axes, tuple(t.get_text() for t in self.fig.texts)

    def state(self):
        """What the background shows besides the animated artists."""
        return self._text(), tuple((ax.get_xlim(), ax.get_ylim(), ax.get_position().bounds) for ax in self.fig.axes)

    def _animated_now(self) -> list:
        """Per axes and for the figure, in drawing order: the moving children and those drawn after
        them that can meet them (inside the axes: a legend on the data, not a title); [] (a full
        draw each frame) when an axes or an axis is among them."""
        from matplotlib.axes import Axes
        from matplotlib.axis import Axis
        out, key = [], (self._text(), tuple(ax.get_position().bounds for ax in self.fig.axes))
        if key != self._meets_key:
            self._meets_key, self._meets = key, {}
        for parent in (*self.fig.axes, self.fig):
            order = sorted((a for a in parent.get_children() if a is not parent.patch), key=attrgetter("zorder"))
            first = next((i for i, a in enumerate(order) if a in self.moving), None)
            if first is not None:
                out += [a for a in order[first:]
                        if a in self.moving or parent is self.fig or self._meets_axes(a, parent)]
        return [] if any(isinstance(a, (Axes, Axis)) for a in out) else out

    def _meets_axes(self, artist, ax) -> bool:
        """Whether `artist` can be drawn on the data area of `ax`: measured once while the text and
        layout stay (a legend's extent is a tenth of a full draw), unless placed in data coordinates."""
        from matplotlib.spines import Spine
        placed = [artist.get_transform(), getattr(artist, "get_offset_transform", artist.get_transform)()]
        on_data = (artist.get_position()[0] == "data" if isinstance(artist, Spine)   # else on an edge
                   else any(any(t.contains_branch_seperately(ax.transData)) for t in placed))
        if artist not in self._meets or on_data:
            self._meets[artist] = artist.get_window_extent(self.canvas.get_renderer()).overlaps(ax.bbox.padded(3))
        return self._meets[artist]

    def _full_draw(self) -> None:
        for artist in self._animated:
            artist.set_animated(False)
        self._animated = self._animated_now()
        for artist in self._animated:
            artist.set_animated(True)
        self._draw_background()
        self._background = self.canvas.copy_from_bbox(self.fig.bbox) if self._animated else None
        self._draw_animated()
        for artist in self._children():      # drawn, or never drawn (an empty title)
            artist.stale = False
        self._key = self.state()
        self.full_draws += 1

    def _draw_background(self) -> None:
        """Draw the figure without the animated artists, laid out again (half a full draw) only when
        its text may measure otherwise (strings, widest tick label), not when only limits move."""
        widest = [max(map(len, a.get_major_formatter().format_ticks(a.get_major_locator()())), default=0)
                  for ax in self.fig.axes for a in (ax.xaxis, ax.yaxis)]
        layout, engine = (self._text(), widest), self.fig.get_layout_engine()
        if layout != self._layout or engine is None:
            self._layout = layout
            return self.canvas.draw()
        self.fig.set_layout_engine("none")   # the axes stay where the last layout put them
        try:
            self.canvas.draw()
        finally:
            self.fig.set_layout_engine(engine)

    def _draw_animated(self) -> None:
        for artist in self._animated:
            artist.draw(self.canvas.get_renderer())
            artist.stale = False
