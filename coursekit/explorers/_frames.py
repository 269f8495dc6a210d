"""Frames of an explorer figure: a full draw when the axes change, blitting otherwise.

While a slider is dragged, an explorer redraws its figure many times a second.
Most of a full matplotlib draw goes into the parts that do not move: axes,
ticks, tick labels, grid, axis labels and the layout. `FrameRenderer` draws
those once into a background (matplotlib's blitting: the moving artists are
marked *animated*, so a normal draw leaves them out, and are drawn on top of a
restored copy of the background), and draws the whole figure again only when
something in the background changes: a view limit, an axis label, the figure
size or resolution, the number of lines of a moving text. (A figure with an
axes of fixed aspect ratio, whose limits follow its place, is drawn whole.) The
layout that matplotlib's constrained layout finds for a full draw is kept per
state of the text around the axes, so a state seen before is not measured again,
and so is the background drawn for it (up to `BACKGROUND_BYTES`), so a slider
dragged back over the states it passed is not drawn whole again either.

Three rules make every frame identical to a fresh draw of the same figure:

* view limits are widened to round numbers outside them (`snap_limits`), so
  they change in steps while a parameter moves and the background is reused
  between the steps;
* in each axes, every artist drawn after the first moving one (matplotlib draws
  an axes' children by zorder) that can meet a moving one is redrawn with it:
  a legend over a moving curve, or the axes frame, stays on top as in a full
  draw, while a legend beside the axes stays in the background;
* a full draw starts constrained layout from the axes' grid cells, so the same
  state is laid out the same way whatever came before.

The moving artists are found by matplotlib's own bookkeeping: setting data or
text marks an artist *stale*, so after the explorer's update the stale artists
are the ones that move.
"""

from __future__ import annotations

import io
from operator import attrgetter

import numpy as np

__all__ = ["FrameRenderer", "snap_limits", "encode_png", "LAYOUTS_KEPT", "BACKGROUND_BYTES"]

#: how many layouts a renderer keeps (one per state of the text around the axes)
LAYOUTS_KEPT = 64
#: the bytes of backgrounds a renderer keeps (one per state laid out; 3.7 MB at 1164 x 800 px)
BACKGROUND_BYTES = 64 * 1024 * 1024


def encode_png(rgba, dpi: float) -> bytes:
    """PNG bytes of an RGBA buffer, fast: zlib level 1 (half the time of the default level, for a
    file about 15 % larger), and without the alpha channel when every pixel is opaque (a
    quarter less to compress)."""
    from PIL import Image   # matplotlib's own image library
    pixels = np.asarray(rgba)
    if pixels[..., 3].min() == 255:
        pixels = np.ascontiguousarray(pixels[..., :3])
    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, format="png", compress_level=1, dpi=(dpi, dpi))
    return buf.getvalue()


def _outer_ticks(axis, lo: float, hi: float, *, coarse: bool) -> tuple[float, float]:
    """The nearest round numbers at or outside [lo, hi]: the axis' own major ticks, or with
    `coarse` on a linear axis multiples of a step of about a quarter of the range (1, 2, 2.5
    or 5 times a power of ten), which change only every few ticks. (lo, hi) if none."""
    from matplotlib.ticker import MaxNLocator
    locator = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]) \
        if coarse and axis.get_scale() == "linear" else axis.get_major_locator()
    ticks = np.asarray(locator.tick_values(lo, hi), dtype=float)
    tol = 1e-9 * (hi - lo)
    below, above = ticks[ticks <= lo + tol], ticks[ticks >= hi - tol]
    return (below.max() if below.size else lo), (above.min() if above.size else hi)


def _with_margin(axis, lo: float, hi: float, margin: float) -> tuple[float, float]:
    """[lo, hi] widened by `margin` of its length on each side, in the axis' scale (log too)."""
    scale = axis.get_transform()
    a, b = scale.transform([lo, hi])
    pad = margin * (b - a)
    return tuple(scale.inverted().transform([a - pad, b + pad]))


def snap_limits(ax, *, done=None, skip=()) -> dict:
    """Put the view limits of `ax` on round numbers that change in steps, not continuously.

    The data range of an autoscaled axis, and limits set by hand that are not
    on the axis' own ticks, are widened to round numbers about a quarter of the
    range apart (`_outer_ticks`); limits set by hand on the axis' ticks (a time
    axis [0, T]) are kept. All get the axes' usual margin, so that no tick label
    sits on a corner. The limits then stay put while
    the data move between those numbers. (An axes with a fixed aspect ratio
    widens one of them further when it is drawn.)

    `done` is what the previous call returned: limits set by hand that are still
    the snapped ones are left as they are (snapping them again would widen them
    at every call). The axes named in `skip` ("x", "y") are left alone: an axis
    shared with an axes snapped before has been snapped with it. Returns the
    limits now, by axis name.
    """
    done = done or {}
    margins = dict(zip("xy", ax.margins()))
    for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
        if name in skip:
            continue
        get, set_ = getattr(ax, f"get_{name}lim"), getattr(ax, f"set_{name}lim")
        auto = getattr(ax, f"get_autoscale{name}_on")()
        data = getattr(ax.dataLim, f"interval{name}")
        lo, hi = get()
        if not auto and done.get(name) == (lo, hi):
            continue
        flipped = lo > hi
        lo, hi = sorted((lo, hi))
        if auto:
            if not (np.all(np.isfinite(data)) and data[0] < data[1]):
                continue                     # no data to fit yet
            lo, hi = data
        elif not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            continue
        # limits set by hand on the axis' own ticks (a time axis [0, T]) stay; data ranges and
        # limits that follow the data (a pole plot's extent) go to coarse round numbers
        on_ticks = not auto and np.allclose(_outer_ticks(axis, lo, hi, coarse=False), (lo, hi))
        snapped = _with_margin(axis, *_outer_ticks(axis, lo, hi, coarse=not on_ticks), margins[name])
        if np.all(np.isfinite(snapped)) and snapped[0] < snapped[1]:   # not on a log axis with data <= 0
            set_(snapped[::-1] if flipped else snapped, auto=None)
    return {"x": ax.get_xlim(), "y": ax.get_ylim()}


def _paint_area(artist, renderer):
    """Where `artist` may paint, in display pixels: its clip box when it is clipped (a curve
    stays inside its axes whatever its data), else its extent now; None when unknown (an Axes or
    Axis, which are never left out)."""
    from matplotlib.axes import Axes
    from matplotlib.axis import Axis
    if isinstance(artist, (Axes, Axis)):
        return None
    box = artist.get_clip_box() if artist.get_clip_on() else None
    return box if box is not None else artist.get_window_extent(renderer)


def _overlaps(a, b, pad: float = 2.0) -> bool:
    """True unless both boxes are known and more than `pad` pixels apart."""
    if a is None or b is None:
        return True
    return not (a.x1 + pad < b.x0 or b.x1 + pad < a.x0 or a.y1 + pad < b.y0 or b.y1 + pad < a.y0)


def _is_stale(artist) -> bool:
    return any(a.stale for a in artist.findobj())


class FrameRenderer:
    """Renders successive frames of one figure as PNG, blitting where it can.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, with its axes and artists built; it gets an Agg canvas of
        its own. The artists that change after the renderer is made are the
        ones that move (see `forget_changes`).

    Call `frame` after every change of the figure's artists. ``full_draws``
    and ``blits`` count how each frame was made; ``reuses`` counts the blits
    onto a background kept from an earlier visit of the same state of the axes.
    """

    def __init__(self, fig):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        self.fig = fig
        self.canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
        self._moving: set = set()          # the artists that changed since the background was made
        self._redraw: list = []            # drawn over the background each frame, in drawing order
        self._background = None
        self._key = None
        self._snapped: dict = {}           # the limits snap_limits left, by axes
        self._layouts: dict = {}           # axes places found by the layout engine, by state
        self._backgrounds: dict = {}       # (background, redraw list) by layout key, for _moving
        self.full_draws = 0
        self.blits = 0
        self.reuses = 0
        self.forget_changes()

    def forget_changes(self) -> None:
        """Mark every artist as unchanged, so that the next `frame` sees only what changes after
        this call (done when the renderer is made)."""
        for unit in self._units():
            for artist in unit.findobj():
                artist.stale = False

    def frame(self) -> bytes:
        """Snap the view limits, draw the figure (blitting if possible) and return its PNG."""
        self._snap()
        moving = self._changed_units()
        if self._background is None or not moving <= self._moving or self._fixed_aspect():
            # an axes with a fixed aspect ratio sets its limits from its place as it is drawn:
            # such a figure is drawn whole every time
            self._full_draw(self._moving | moving)
        elif self._layout_key() == self._key or self._reuse_background():
            self._blit()
        else:
            self._full_draw(self._moving)
        return encode_png(self.canvas.buffer_rgba(), self.fig.dpi)

    def _snap(self) -> None:
        """Snap the view limits of every axes (`snap_limits`), each shared axis once: snapping
        the second axes of a shared time axis again would widen the limits the first one got
        (a time axis [0, 10] went to [-6, 16])."""
        snapped = []
        for ax in self.fig.axes:
            # an axes with a fixed aspect ratio widens its limits itself to the box when drawn;
            # limits snapped by hand there would be cut to the box instead, data and all
            if ax.get_aspect() != "auto":
                continue
            skip = [name for name in "xy"
                    if any(getattr(ax, f"get_shared_{name}_axes")().joined(ax, other) for other in snapped)]
            self._snapped[ax] = snap_limits(ax, done=self._snapped.get(ax), skip=skip)
            snapped.append(ax)

    # --- what changed ------------------------------------------------------------------------

    def _units(self):
        """The artists matplotlib draws as one piece: each axes' children and the figure's,
        except the axes themselves and their x and y axis (those belong to the background)."""
        from matplotlib.axes import Axes
        from matplotlib.axis import Axis
        for ax in self.fig.axes:
            yield from (a for a in ax.get_children() if a is not ax.patch and not isinstance(a, Axis))
        yield from (a for a in self.fig.get_children()
                    if a is not self.fig.patch and not isinstance(a, Axes))

    def _changed_units(self) -> set:
        return {unit for unit in self._units() if _is_stale(unit)}

    def _layout_key(self):
        """Everything the background depends on, besides the artists that are redrawn: what the
        layout depends on (`_layout_state`), the places of the axes and the resolution."""
        places = tuple(ax.get_position().bounds for ax in self.fig.axes)
        return self.fig.dpi, places, self._layout_state()

    # --- drawing -----------------------------------------------------------------------------

    def _redraw_list(self, moving: set) -> list | None:
        """Per axes and then for the figure, in zorder, the moving children and the still ones
        drawn after the first moving one that can meet a moving one; None when a moving artist
        cannot be blitted (an image, or one that an axes or axis is drawn after)."""
        from matplotlib.axes import Axes
        from matplotlib.axis import Axis
        from matplotlib.image import AxesImage
        renderer = self.canvas.get_renderer()
        out = []
        for parent in (*self.fig.axes, self.fig):
            children = [a for a in parent.get_children() if a is not parent.patch]
            order = sorted(children, key=attrgetter("zorder"))
            first = next((i for i, a in enumerate(order) if a in moving), None)
            if first is None:
                continue
            areas = [_paint_area(a, renderer) for a in order[first:] if a in moving]
            # a still artist drawn later than a moving one is redrawn over it only where they can
            # meet: a legend beside the axes stays in the background, one inside is redrawn
            tail = [a for a in order[first:]
                    if a in moving or any(_overlaps(_paint_area(a, renderer), area) for area in areas)]
            if any(isinstance(a, (Axes, Axis, AxesImage)) for a in tail):
                return None
            out.extend(tail)
        return out

    def _full_draw(self, moving: set) -> None:
        """Draw the figure without the moving artists (the background), keep it, draw them on top."""
        redraw = self._redraw_list(moving)
        moving, redraw = (moving, redraw) if redraw is not None else (set(), [])
        if moving != self._moving:
            self._backgrounds.clear()        # they leave out other artists
        self._moving = moving
        self._animate(redraw)
        self._draw_background()
        self._background = self.canvas.copy_from_bbox(self.fig.bbox) if self._redraw else None
        self._draw_redraw_list()
        self._key = self._layout_key()
        if self._background is not None:
            self._keep_background()
        self.full_draws += 1

    def _animate(self, redraw: list) -> None:
        """Make `redraw` the artists drawn over the background: only they are animated (left
        out of a full draw)."""
        for artist in self._redraw:
            artist.set_animated(False)
        self._redraw = redraw
        for artist in self._redraw:
            artist.set_animated(True)

    def _keep_background(self) -> None:
        """Keep the background just drawn for its layout key, within `BACKGROUND_BYTES`: a
        slider dragged back and forth passes the same few states of the axes again and again."""
        self._backgrounds.pop(self._key, None)
        self._backgrounds[self._key] = (self._background, self._redraw)
        width, height = self.canvas.get_width_height(physical=True)
        while len(self._backgrounds) > 1 and len(self._backgrounds) * 4 * width * height > BACKGROUND_BYTES:
            self._backgrounds.pop(next(iter(self._backgrounds)))

    def _reuse_background(self) -> bool:
        """Put back the background kept for the figure's state, if any, with its axes places:
        True when it was put back (the moving artists are then drawn over it as in a blit)."""
        places = self._layouts.get(self._layout_state())
        if places is None:
            return False
        self._place(places)
        key = self._layout_key()
        kept = self._backgrounds.pop(key, None)
        if kept is None:
            return False
        self._backgrounds[key] = kept        # used last: dropped last
        self._background, redraw = kept
        self._animate(redraw)
        self._key = key
        self.reuses += 1
        return True

    def _draw_background(self) -> None:
        """Draw the figure, laying it out only for a state not laid out before.

        Constrained layout measures every tick label and title: as much work again as the draw
        itself. Its result depends only on what it measures, so it is kept for each state of the
        text around the axes (view limits, scales, axis labels, the number of lines of the
        titles and of the moving texts) and put back, without measuring, when a slider returns
        to a state laid out before.
        """
        engine = self.fig.get_layout_engine()
        if engine is None:
            self.canvas.draw()
            return
        # an axes with a fixed aspect ratio sets its limits from its place: lay it out each time
        state = None if self._fixed_aspect() else self._layout_state()
        places = self._layouts.get(state)
        if places is None:
            self._restart_layout()
            self.canvas.draw()
            if state is None:
                # the aspect sets the limits from the place before the layout moves the axes:
                # a second draw lets both agree (matplotlib's own figures settle the same way)
                self.canvas.draw()
            if state is not None:
                self._layouts[state] = [ax.get_position(original=True).bounds for ax in self.fig.axes]
            while len(self._layouts) > LAYOUTS_KEPT:
                self._layouts.pop(next(iter(self._layouts)))
            return
        self._place(places)
        self.fig.set_layout_engine("none")
        try:
            self.canvas.draw()
        finally:
            self.fig.set_layout_engine(engine)

    def _place(self, places: list) -> None:
        """Put the axes where a layout kept in `_layouts` placed them."""
        for ax, place in zip(self.fig.axes, places):
            ax.set_position(place)
            ax.set_in_layout(True)           # set_position takes an axes out of the layout

    def _fixed_aspect(self) -> bool:
        return any(ax.get_aspect() != "auto" for ax in self.fig.axes)

    def _layout_state(self):
        """What the layout of the figure depends on, besides its fixed text (see `_draw_background`)."""
        def lines(text):
            return text.get_text().count("\n") if text.get_text() else -1

        axes = tuple((ax.get_xlim(), ax.get_ylim(), ax.get_xscale(), ax.get_yscale(), ax.get_xlabel(),
                      ax.get_ylabel(), tuple(lines(t) for t in (ax.title, *ax.texts)), ax.get_visible())
                     for ax in self.fig.axes)
        return tuple(self.fig.get_size_inches()), axes, tuple(lines(t) for t in self.fig.texts)

    def _restart_layout(self) -> None:
        """Put each axes back in its grid cell before a layout engine places it: constrained
        layout starts from the axes' current places (their size sets the ticks it measures),
        so without this the figure after a drag could differ by a pixel from a fresh one."""
        if self.fig.get_layout_engine() is None:
            return
        for ax in self.fig.axes:
            spec = ax.get_subplotspec()
            if spec is not None and ax.get_in_layout():
                ax.set_position(spec.get_position(self.fig))
                ax.set_in_layout(True)       # set_position takes an axes out of the layout

    def _blit(self) -> None:
        self.canvas.restore_region(self._background)
        self._draw_redraw_list()
        self.blits += 1

    def _draw_redraw_list(self) -> None:
        renderer = self.canvas.get_renderer()
        for artist in self._redraw:
            artist.draw(renderer)
        self.forget_changes()
