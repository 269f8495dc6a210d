"""The machinery shared by every explorer: sliders that redraw one figure as they move.

An explorer is three plain functions and a set of controls:

* ``compute(**params)`` -- pure numerics, no plotting, unit-tested without a
  browser (this is where the course's algorithms are called);
* ``draw(fig)`` -- builds the axes and empty artists once, returns handles;
* ``update(handles, result)`` -- moves the artists' data to a new result.

`Explorer` wires them to ipywidgets controls that report every move while a
slider is dragged (``continuous_update=True``; the widget front end keeps at
most one change in flight and sends only the latest value, so a redraw never
falls behind the hand) and shows the figure in a `FigureView`. Each frame is
drawn by a `FrameRenderer`: the axes, ticks and labels are drawn once and
reused while only curves and titles move, so a frame costs a few tens of
milliseconds instead of a full draw.

While an explorer is on screen, the browser also asks the kernel, one at a
time, for the frames of the slider positions around the current ones (the
slider under the pointer first; see `FigureView`) and keeps them; a slider
moved to a position it holds shows that frame at once, without waiting for the
kernel. The kernel draws such a frame without touching the controls or what is
shown (`Explorer.frame_for`). Every callback (a slider moved, a frame asked
for, a screen report) runs on the kernel's main thread (`HomeThread`), since a
front end may hand widget messages to another kernel thread.

The figure is rendered at the pixel size it is shown with: the view reports
the screen's device pixel ratio and the room available (the output width, and
the visible height less the explorer's controls), and the figure is scaled
down to fit. In `coursekit.lecture_mode` (switched on before the explorer is
built) the figure also grows to fill the room, and the text in the figure and
in the controls is larger.

The explorer also carries a static PNG of the figure (at its natural size) in
its display data, so a renderer without a live kernel (GitHub, nbviewer, an
exported HTML page, the course website) shows the figure for the default
parameters instead of an empty widget area.
"""

from __future__ import annotations

import base64
from collections import OrderedDict
from typing import Any, Callable

import numpy as np

from ._frames import FrameRenderer, encode_png
from ._home import HomeThread

__all__ = ["Explorer", "slider", "int_slider", "dropdown", "figure_png", "rescale"]

#: an explorer is never shrunk below this fraction of its natural size to fit the screen
MIN_SCALE = 0.45

#: in lecture mode an explorer grows up to this factor to fill the room it has
LECTURE_MAX_SCALE = 2.0

#: how many recent frames an explorer keeps, for settings shown again
FRAME_CACHE_SIZE = 128

#: significant digits of a slider value in a frame's key: the browser's slider and its
#: frames-ahead requests may reach the same position by different float roundings
KEY_DIGITS = 12


def _control_layout():
    import ipywidgets as widgets
    return widgets.Layout(width="auto")


def slider(value: float, min: float, max: float, step: float, description: str, *,
           readout_format: str = ".3g"):
    """A FloatSlider that reports every move while it is dragged."""
    import ipywidgets as widgets
    return widgets.FloatSlider(value=value, min=min, max=max, step=step, description=description,
                               continuous_update=True, readout_format=readout_format,
                               style={"description_width": "initial"}, layout=_control_layout())


def int_slider(value: int, min: int, max: int, description: str, *, step: int = 1):
    """An IntSlider that reports every move while it is dragged."""
    import ipywidgets as widgets
    return widgets.IntSlider(value=value, min=min, max=max, step=step, description=description,
                             continuous_update=True, style={"description_width": "initial"},
                             layout=_control_layout())


def dropdown(options, value, description: str):
    """A Dropdown for a discrete choice (e.g. which controller)."""
    import ipywidgets as widgets
    return widgets.Dropdown(options=options, value=value, description=description,
                            style={"description_width": "initial"}, layout=_control_layout())


def rescale(*axes, min_span: float = 0.0) -> None:
    """Fit each axes' view to the data its artists hold now (after ``set_data`` in an update).

    With `min_span`, the vertical view spans at least that much, centred on the data: a
    response that stays at a constant (a pendulum started upright) is drawn flat instead of
    its numerical noise, a millionth of a unit, filling the axes.
    """
    for ax in axes:
        ax.relim()
        low, high = ax.dataLim.intervaly
        if np.isfinite(low) and np.isfinite(high) and high - low < min_span:
            # widen the data limits, not the view: the axes stays autoscaled (and snapped)
            middle, x = (low + high) / 2, ax.dataLim.x0
            ax.update_datalim([(x, middle - min_span / 2), (x, middle + min_span / 2)])
        ax.autoscale_view()


def figure_png(fig) -> bytes:
    """Render a matplotlib figure to PNG bytes, at the figure's dpi (one Agg draw)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return encode_png(canvas.buffer_rgba(), fig.dpi)


def _is_slider(widget) -> bool:
    """A FloatSlider or IntSlider (the controls the browser steps through ahead of the hand)."""
    import ipywidgets as widgets
    return isinstance(widget, (widgets.FloatSlider, widgets.IntSlider))


def settings_now(controls: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """The controls' settings as the browser sees them (a slider's value, a choice's index) and
    as parameters, each control read once: a front end may change the controls from another
    thread while a frame is drawn, and a frame must be labelled with the settings it was drawn
    for."""
    values, params = {}, {}
    for name, w in controls.items():
        if hasattr(w, "index"):
            values[name], params[name] = w.index, w.value
        else:
            values[name] = params[name] = w.value
    return values, params


def requested_params(controls: dict[str, Any], values) -> dict[str, Any] | None:
    """The parameters for settings `values` the browser asks a frame for, or None when they do
    not fit: every control named, each slider at a finite number within its range (a whole one
    for an IntSlider), every other control at its current setting."""
    if not isinstance(values, dict) or set(values) != set(controls):
        return None
    shown, now = settings_now(controls)
    params = {}
    for name, w in controls.items():
        value = values[name]
        if not _is_slider(w):
            if value != shown[name]:
                return None
            params[name] = now[name]
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
            return None
        if not w.min - 1e-9 * abs(w.step) <= value <= w.max + 1e-9 * abs(w.step):
            return None
        if isinstance(w.value, int):
            if value != int(value):
                return None
            value = int(value)
        params[name] = float(value) if isinstance(w.value, float) else value
    return params


def _fit_scale(natural_px, screen: dict, largest: float = 1.0) -> float:
    """The factor (at most `largest`) by which a figure of `natural_px` (width, height) fits the
    reported room."""
    width, height = (float(screen.get(key) or 0) for key in ("width", "height"))
    scale = largest
    if width > 0:
        scale = min(scale, width / natural_px[0])
    if height > 0:
        scale = min(scale, height / natural_px[1])
    return max(scale, MIN_SCALE)


class Explorer:
    """A figure whose parameters are set with sliders.

    Parameters
    ----------
    title : str
        Shown above the controls.
    controls : dict of name -> widget
        Each widget's value is passed to `compute` under its name.
    compute : callable
        ``compute(**params) -> result``; pure, no plotting.
    draw : callable
        ``draw(fig) -> handles``; creates axes and artists on the given figure.
    update : callable
        ``update(handles, result) -> None``; sets the artists' data.
    figsize : tuple, optional
        Natural figure size in inches (shown at the figure's dpi, 100 pixels
        per inch by default); default from matplotlib's settings. The figure
        is shown smaller when the screen has less room; in lecture mode it
        also grows (up to `LECTURE_MAX_SCALE` times) to fill the room.

    Attributes
    ----------
    frames_ahead : bool
        Class-wide switch, read when the widget is built: whether the browser asks for the
        frames of the slider positions next to the current settings while the explorer is on
        screen (default True). Set ``Explorer.frames_ahead = False`` where the kernel's CPU is
        scarce; every update is then a round trip to the kernel.
    """

    frames_ahead: bool = True

    def __init__(self, *, title: str, controls: dict[str, Any], compute: Callable[..., Any],
                 draw: Callable[[Any], Any], update: Callable[[Any, Any], None], figsize=None):
        from matplotlib import rcParams
        from matplotlib.figure import Figure

        from ..layout import fit_margins
        from ..style import is_lecture_mode
        self.title = title
        self.controls = dict(controls)
        self._compute = compute
        self._update = update
        self.lecture = is_lecture_mode()
        self.fig = fit_margins(Figure(figsize=figsize or rcParams["figure.figsize"]))
        self.natural_dpi = float(self.fig.dpi)
        self.handles = draw(self.fig)
        self.screen: dict = {}
        self._shown_values, self._shown_params = settings_now(self.controls)
        self.result = self._compute(**self._shown_params)
        # update, then watch the update repeated: the artists it touches are the ones that move
        self._update(self.handles, self.result)
        self.frames = FrameRenderer(self.fig)
        self._update(self.handles, self.result)
        self._cache: OrderedDict = OrderedDict()
        self._png = self.frames.frame()
        self._remember(self._frame_key(self._shown_params), self.result, self._png)
        self._widget = None
        self._view = None

    @property
    def params(self) -> dict[str, Any]:
        """The current value of every control, by name."""
        return {name: w.value for name, w in self.controls.items()}

    @property
    def png(self) -> bytes:
        """The figure as last drawn (PNG bytes, at the size it is shown with)."""
        return self._png

    def refresh(self) -> None:
        """Recompute for the current control values and redraw the figure.

        Settings shown before (a slider dragged back over its values) come from a small cache
        of recent frames, keyed by the settings and the resolution, instead of being computed
        and drawn again; the figure's artists are still updated, so they always match what is
        shown.
        """
        self._shown_values, self._shown_params = settings_now(self.controls)
        key = self._frame_key(self._shown_params)
        cached = self._cache.get(key)
        if cached is not None:
            self._cache.move_to_end(key)
            self.result, self._png = cached
            self._update(self.handles, self.result)
            self._send()
            return
        self.result = self._compute(**self._shown_params)
        self._update(self.handles, self.result)
        self._show()

    def frame_for(self, params: dict[str, Any]) -> bytes:
        """The frame (PNG bytes) for the settings `params`, from the cache or computed and
        drawn, without changing the controls or the frame shown.

        What the browser asks for ahead of the hand. The figure's artists are put back to the
        settings shown afterwards, so the next frame or `static_png` draws those.
        """
        key = self._frame_key(params)
        cached = self._cache.get(key)
        if cached is not None:
            return cached[1]
        result = self._compute(**params)
        try:
            self._update(self.handles, result)
            png = self.frames.frame()
        finally:                     # also when the update or the drawing fails halfway
            self._update(self.handles, self.result)
        self._remember(key, result, png)
        return png

    def forget_frames(self) -> None:
        """Forget the remembered frames, so that the next `refresh` computes and draws anew
        (what a benchmark of the redraw times)."""
        self._cache.clear()

    def _frame_key(self, params: dict[str, Any]):
        values = tuple((name, float(f"{value:.{KEY_DIGITS}g}") if isinstance(value, float) else value)
                       for name, value in params.items())
        return values, self.fig.dpi

    def _remember(self, key, result, png: bytes) -> None:
        self._cache[key] = (result, png)
        self._cache.move_to_end(key)
        while len(self._cache) > FRAME_CACHE_SIZE:
            self._cache.popitem(last=False)

    def static_png(self) -> bytes:
        """The figure for the current settings at its natural size (what a static page shows)."""
        if self.fig.dpi == self.natural_dpi:
            return self._png
        shown = self.fig.dpi
        self.fig.set_dpi(self.natural_dpi)
        png = self.frames.frame()
        self.fig.set_dpi(shown)
        self.frames.frame()
        return png

    def _show(self) -> None:
        """Draw a frame of the figure as it is now, remember it and send it to the view."""
        self._png = self.frames.frame()
        self._remember(self._frame_key(self._shown_params), self.result, self._png)
        self._send()

    def _send(self) -> None:
        if self._view is not None:
            ratio = float(self.screen.get("ratio") or 1.0)
            height, width = self.frames.canvas.buffer_rgba().shape[:2]
            with self._view.hold_sync():
                self._view.png = self._png
                self._view.values = self._shown_values
                self._view.css_width = width / ratio
                self._view.css_height = height / ratio
                self._view.alt = self._alt_text()

    def _on_latest_screen(self) -> None:
        self._on_screen({"new": self._view.screen})

    def _on_screen(self, change) -> None:
        """Render at the size the figure is shown with: scaled to fit, at the screen's pixel ratio."""
        self.screen = dict(change["new"] or {})
        ratio = float(self.screen.get("ratio") or 1.0)
        natural = self.fig.get_size_inches() * self.natural_dpi
        largest = LECTURE_MAX_SCALE if self.lecture else 1.0
        dpi = self.natural_dpi * _fit_scale(natural, self.screen, largest) * ratio
        if abs(dpi - self.fig.dpi) > 1e-6:
            self.fig.set_dpi(dpi)
            self.forget_frames()         # frames at the old resolution are not shown again
            if self._view is not None:
                self._view.generation += 1   # nor those the browser holds
        self._show()

    def _on_view_msg(self, view, content, buffers) -> None:
        """Answer the browser's request for a frame ahead of the hand: ``{"type": "frame",
        "values": ..., "generation": n, "view": id}`` gets the frame (PNG as the message's
        buffer; values, generation and the asking view's id sent back), or a
        ``"no-frame"`` reply when the request does not fit the controls or the settings cannot
        be computed (the browser then asks for other settings; moving a slider there shows the
        error as usual)."""
        if not isinstance(content, dict) or content.get("type") != "frame":
            return
        reply = {"type": "no-frame", **{key: content.get(key) for key in ("values", "generation", "view")}}
        params = requested_params(self.controls, content.get("values"))
        if params is None or content.get("generation") != view.generation:
            view.send(reply)
            return
        try:
            png = self.frame_for(params)
        except Exception:   # noqa: BLE001 - the user meets the error when moving there
            view.send(reply)
            return
        view.send({**reply, "type": "frame"}, [png])

    def _settings(self) -> str:
        return ", ".join(f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v!r}"
                         for k, v in self._shown_params.items())

    def _alt_text(self) -> str:
        return f"{self.title} ({self._settings()})"

    @property
    def widget(self):
        """The live widget: a title, the controls and the figure."""
        if self._widget is None:
            import ipywidgets as widgets

            from ._view import FigureView
            self._view = FigureView(png=self._png, alt=self._alt_text(), controls=self.controls,
                                    values=self._shown_values, ahead=bool(self.frames_ahead),
                                    css_width=float(self.frames.canvas.buffer_rgba().shape[1]),
                                    css_height=float(self.frames.canvas.buffer_rgba().shape[0]))
            # every callback on the kernel's main thread, whichever thread a message arrives on
            home = HomeThread()
            self._view.observe(lambda change: home.run(self._on_latest_screen, key="screen"), names="screen")
            self._view.on_msg(lambda view, content, buffers: home.run(self._on_view_msg, view, content, buffers))
            for w in self.controls.values():
                w.observe(lambda change: home.run(self.refresh, key="refresh"), names="value")
            header = widgets.HTML(f"<b>{self.title}</b>")
            header.add_class("ck-title")
            column = "270px" if self.lecture else "300px"
            boxes = widgets.GridBox(list(self.controls.values()), layout=widgets.Layout(
                grid_template_columns=f"repeat(auto-fill, minmax({column}, 1fr))", width="100%"))
            boxes.add_class("ck-controls")
            self._widget = widgets.VBox([header, boxes, self._view])
            self._widget.add_class("ck-explorer")
            if self.lecture:
                self._widget.add_class("ck-lecture")
        return self._widget

    def _repr_mimebundle_(self, include=None, exclude=None):
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude)
        bundle["image/png"] = base64.b64encode(self.static_png()).decode("ascii")
        bundle["text/plain"] = f"{self.title} (static figure for {self._settings()})"
        return bundle

    def __repr__(self) -> str:
        return f"<Explorer {self.title!r}: {', '.join(self.controls)}>"
