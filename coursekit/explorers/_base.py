"""The machinery shared by every explorer: controls that redraw one figure as they move.

An explorer is controls and plain functions: ``compute(**params)``, pure numerics; ``draw(fig)``,
which builds axes and empty artists once and returns handles; ``update(handles, result)``, which
moves the artists' data and sets the limits (`limits.rescale`); optionally ``readout(result)``, the
numbers shown next to the controls. A `FrameRenderer` draws each frame (blitting while the axes
stay), a `FigureView` shows it; callbacks run on the kernel's main thread (`HomeThread`). The
display data carry a static PNG for pages without a kernel, after a fallback output (`_fallback`).
"""

from __future__ import annotations

import base64
import functools
import html
from typing import Any, Callable

from .._validation import as_scalar
from ..describe import describe_figure
from ._fallback import publish_fallback
from ._frames import FrameRenderer
from .limits import SETTLE_S, moving

__all__ = ["Explorer", "slider", "int_slider", "dropdown"]

#: an explorer is never shrunk below this fraction of its natural size to fit the screen
MIN_SCALE = 0.45
#: in lecture mode an explorer grows up to this factor to fill the room it has
LECTURE_MAX_SCALE = 2.0


def _range(value, min, max, step, description):
    """The slider's numbers, checked: finite, min < max, step > 0, min <= value <= max."""
    if not isinstance(description, str) or not description.strip():
        raise ValueError(f"description must be a non-empty string naming the quantity and its unit: "
                         f"received {description!r}.")
    value, low, high = (as_scalar(v, n) for v, n in ((value, "value"), (min, "min"), (max, "max")))
    step = as_scalar(step, "step", positive=True)
    if not low < high:
        raise ValueError(f"min must be below max: received min={low:g}, max={high:g}.")
    if not low <= value <= high:
        raise ValueError(f"value must lie in [min, max] = [{low:g}, {high:g}]: received {value:g}.")
    return value, low, high, step


#: the controls' label above the whole width: the full description, with its unit
_STYLE = dict(style={"description_width": "initial"}, layout={"width": "auto"})


def slider(value: float, min: float, max: float, step: float, description: str, *,
           readout_format: str = ".3g"):
    """A FloatSlider that reports every move while it is dragged; `description` names the
    quantity with its unit (it is also the slider's accessible name)."""
    import ipywidgets as widgets
    value, min, max, step = _range(value, min, max, step, description)
    return widgets.FloatSlider(value=value, min=min, max=max, step=step, description=description,
                               continuous_update=True, readout_format=readout_format, **_STYLE)


def int_slider(value: int, min: int, max: int, description: str, *, step: int = 1):
    """An IntSlider that reports every move while it is dragged."""
    import ipywidgets as widgets
    numbers = _range(value, min, max, step, description)
    if any(x != int(x) for x in numbers):
        raise ValueError(f"value, min, max and step must be whole numbers: received {numbers}.")
    value, min, max, step = (int(x) for x in numbers)
    return widgets.IntSlider(value=value, min=min, max=max, step=step, description=description,
                             continuous_update=True, **_STYLE)


def dropdown(options, value, description: str):
    """A Dropdown for a discrete choice (e.g. which system); `value` is one of `options`."""
    import ipywidgets as widgets
    if isinstance(options, str) or not hasattr(options, "__iter__") or not list(options):
        raise ValueError(f"options must be a non-empty list of choices: received {options!r}.")
    options = list(options)
    if value not in options:
        raise ValueError(f"value must be one of the options {options}: received {value!r}.")
    _range(0, 0, 1, 1, description)
    return widgets.Dropdown(options=options, value=value, description=description, **_STYLE)


class Explorer:
    """A figure whose parameters are set with sliders and dropdowns.

    Parameters
    ----------
    title : str
        Shown above the controls.
    controls : dict of name -> widget
        Made with `slider`, `int_slider` or `dropdown`; each value is passed to `compute`
        under its name.
    compute : callable
        ``compute(**params) -> result``; pure, no plotting.
    draw : callable
        ``draw(fig) -> handles``; creates axes and artists on the given figure.
    update : callable
        ``update(handles, result) -> None``; sets the artists' data and the view limits.
    readout : callable, optional
        ``readout(result) -> str``: the numbers to read, shown next to the controls (a new
        line for each ``"\\n"``) and part of the figure's text alternative.
    figsize : tuple, optional
        Natural figure size in inches (100 pixels per inch); default from matplotlib's
        settings. The figure is shown smaller when the screen has less room.

    A `compute` that fails for the first settings raises ValueError; one that fails for
    settings a hand moves to leaves the figure as it was and says why in the readout.
    """

    def __init__(self, *, title: str, controls: dict[str, Any], compute: Callable[..., Any],
                 draw: Callable[[Any], Any], update: Callable[[Any, Any], None],
                 readout: Callable[[Any], str] | None = None, figsize=None):
        from matplotlib import rc_context, rcParams
        from matplotlib.figure import Figure

        from ..style import COURSE_STYLE, fit_margins, is_lecture_mode
        self._check(title, controls, dict(compute=compute, draw=draw, update=update, readout=readout))
        self.title, self.controls = title, dict(controls)
        self._compute, self._update, self._readout = compute, update, readout
        self._results = functools.lru_cache(maxsize=128)(lambda settings: compute(**dict(settings)))
        self.lecture = is_lecture_mode()
        self.fig = fit_margins(Figure(figsize=figsize or rcParams["figure.figsize"]))
        self.natural_dpi = float(self.fig.dpi)
        with rc_context(COURSE_STYLE):     # the course's colours and a line style per curve
            self.handles = draw(self.fig)
        self.screen, self.error = {}, None     # the room reported by the view; why a setting failed
        try:
            self.apply(self.params)
        except Exception as error:   # noqa: BLE001 - the user's function, named in the message
            raise ValueError(f"the explorer {title!r} could not show its first settings {self.params}: "
                             f"{type(error).__name__}: {error}; fix compute/update or the controls' "
                             "initial values") from error
        self.frames = FrameRenderer(self.fig)
        self.png = self.frames.frame()     # the figure as last drawn, at the size it is shown with
        self._widget = self._view = self._text = None
        from ._home import HomeThread
        self._home = HomeThread()
        self._settle, self._last_move = None, float("-inf")
        for w in self.controls.values():
            w.observe(lambda change: self._home.run(self._moved, key="refresh"), names="value")

    @staticmethod
    def _check(title, controls, functions: dict) -> None:
        import ipywidgets as widgets
        if not isinstance(title, str):
            raise TypeError(f"title must be a string: received {type(title).__name__}.")
        if not isinstance(controls, dict) or not controls:
            raise ValueError("controls must be a non-empty dict of name -> control, e.g. "
                             "{'k': slider(1.0, 0.0, 5.0, 0.1, 'k [N/m]')}.")
        for name, w in controls.items():
            if not isinstance(w, widgets.ValueWidget):
                raise TypeError(f"controls[{name!r}] must be a control made with slider, int_slider or "
                                f"dropdown: received {type(w).__name__}.")
        for name, func in functions.items():
            if func is not None and not callable(func):
                raise TypeError(f"{name} must be a function: received {type(func).__name__} {func!r}.")

    @property
    def params(self) -> dict[str, Any]:
        """The current value of every control, by name."""
        return {name: w.value for name, w in self.controls.items()}

    @property
    def text(self) -> str:
        """The readout for the settings shown (or why they could not be shown)."""
        if self.error:
            return f"No figure for these settings: {self.error}"
        try:
            return self._readout(self.result) if self._readout else ""
        except Exception as error:   # noqa: BLE001 - the user's function; the figure stays right
            return f"The readout failed: {type(error).__name__}: {error}"

    @property
    def alt(self) -> str:
        """The figure's text alternative: the title, the settings and the readout."""
        return self.alt_for(self.text)

    def alt_for(self, text: str, params: dict | None = None) -> str:
        """The text alternative for the readout `text` and the settings `params` (default: the controls')."""
        settings = ", ".join(f"{k} = {v:g}" if isinstance(v, (int, float)) else f"{k} = {v}"
                             for k, v in (self.params if params is None else params).items())
        return f"{self.title}. Settings: {settings}." + (f" {text}".replace("\n", "; ") if text else "")

    def apply(self, params: dict) -> None:
        """Compute for the settings `params` and update the artists (not drawn; raises what compute raises)."""
        result = self._results(tuple(params.items()))   # a setting dragged over again: not recomputed
        self._update(self.handles, result)
        self.result = result

    def refresh(self) -> None:
        """Recompute for the controls' current values and redraw the figure."""
        try:
            self.apply(self.params)
            self.error = None
        except Exception as error:   # noqa: BLE001 - shown to the student; the lecture goes on
            self.error = f"{type(error).__name__}: {error}"
        else:
            self.png = self.frames.frame()
        self._send()

    def _moved(self) -> None:
        """A control moved. In a kernel (an event loop runs), a move less than `SETTLE_S` after the
        last frame ended is part of a drag: drawn inside `moving` (the limits only grow), and a frame
        at rest follows once the controls rest (it sends nothing when it is the frame shown); a
        single step is drawn at rest."""
        loop = self._home.loop
        if loop is None or not loop.is_running():
            return self.refresh()
        try:
            if loop.time() - self._last_move > SETTLE_S:   # a single step: drawn at rest at once
                return self.refresh()
            if self._settle is not None:
                self._settle.cancel()
            with moving():
                self.refresh()
            self._settle = loop.call_later(SETTLE_S, self.refresh)
        finally:       # from the end of this frame: a slow frame does not split a drag into steps
            self._last_move = loop.time()

    def static_png(self) -> bytes:
        """The figure for the current settings at its natural size (what a static page shows)."""
        if self.fig.dpi == self.natural_dpi:
            return self.png
        shown = self.fig.dpi
        self.fig.set_dpi(self.natural_dpi)
        png = self.frames.frame()
        self.fig.set_dpi(shown)
        self.frames.frame()
        return png

    def _readout_html(self, text: str) -> str:
        lines = html.escape(text).split("\n")
        css = "ck-readout ck-error" if self.error else "ck-readout"
        return f'<div class="{css}">' + "<br>".join(lines) + "</div>"

    def _send(self) -> None:
        if self._view is None:
            return
        ratio, text = float(self.screen.get("ratio") or 1.0), self.text   # the readout, run once a frame
        height, width = self.frames.canvas.get_width_height(physical=True)[::-1]
        with self._view.hold_sync():
            self._view.png = self.png
            self._view.css_width, self._view.css_height = width / ratio, height / ratio
            self._view.alt = self.alt_for(text)
        self._text.value = self._readout_html(text)

    def _on_screen(self, screen: dict) -> None:
        """Render at the size the figure is shown with: scaled to fit the reported room (at most
        its natural size, `LECTURE_MAX_SCALE` in lecture mode), at the screen's pixel ratio."""
        self.screen = dict(screen or {})
        ratio = float(self.screen.get("ratio") or 1.0)
        room = [float(self.screen.get(key) or 0) / size for key, size in
                zip(("width", "height"), self.fig.get_size_inches() * self.natural_dpi)]
        scale = max(min([LECTURE_MAX_SCALE if self.lecture else 1.0, *(r for r in room if r > 0)]), MIN_SCALE)
        dpi = self.natural_dpi * scale * ratio
        if abs(dpi - self.fig.dpi) > 1e-6:
            self.fig.set_dpi(dpi)
            self.png = self.frames.frame()
        self._send()

    @property
    def widget(self):
        """The live widget: the title, the controls, the readout and the figure."""
        if self._widget is None:
            import ipywidgets as widgets

            from ._view import FigureView
            width, height = self.frames.canvas.get_width_height(physical=True)
            self._view = FigureView(png=self.png, alt=self.alt, css_width=float(width),
                                    css_height=float(height))
            self._text = widgets.HTML(self._readout_html(self.text)).add_class("ck-readout-box")
            self._view.observe(lambda change: self._home.run(lambda: self._on_screen(self._view.screen),
                                                             key="screen"), names="screen")
            header = widgets.HTML(f"<b>{html.escape(self.title)}</b>").add_class("ck-title")
            column = "270px" if self.lecture else "300px"
            boxes = widgets.GridBox(list(self.controls.values()), layout=widgets.Layout(
                grid_template_columns=f"repeat(auto-fill, minmax({column}, 1fr))", width="100%")
            ).add_class("ck-controls")
            self._widget = widgets.VBox([header, boxes, self._text, self._view]).add_class("ck-explorer")
            if self.lecture:
                self._widget.add_class("ck-lecture")
        return self._widget

    def _repr_mimebundle_(self, include=None, exclude=None):
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude)
        png = self.static_png()
        bundle["image/png"] = base64.b64encode(png).decode("ascii")
        bundle["text/plain"] = repr(self)
        publish_fallback(self, png)   # shown before the widget where it cannot be (a reopened notebook)
        return bundle

    def __repr__(self) -> str:   # the text a page without a kernel shows for the figure: its alt and data
        return f"{self.alt} {describe_figure(self.fig)}"
