"""The machinery shared by every explorer: sliders that redraw one figure.

An explorer is three plain functions and a set of controls:

* ``compute(**params)`` -- pure numerics, no plotting, unit-tested without a
  browser (this is where the course's algorithms are called);
* ``draw(fig)`` -- builds the axes and empty artists once, returns handles;
* ``update(handles, result)`` -- moves the artists' data to a new result.

`Explorer` wires them to ipywidgets sliders (``continuous_update=False``, so
the figure is recomputed when the slider is released) and shows the figure as
an image widget. It also carries a static PNG of the figure in its display
data, so a renderer without a live widget front-end (GitHub, nbviewer, an
exported HTML) shows the figure for the default parameters instead of a bare
widget repr.

Exported HTML: ``jupyter nbconvert --to html --execute`` stores the widget
state, and the page's embedded widget manager (loaded from unpkg.com) draws
the widget with the figure from that state; with
``--ExecutePreprocessor.store_widget_state=False`` the page shows the static
PNG as a plain image, which also works offline.
"""

from __future__ import annotations

import base64
import io
from typing import Any, Callable

__all__ = ["Explorer", "slider", "int_slider", "dropdown", "figure_png", "rescale"]


def slider(value: float, min: float, max: float, step: float, description: str, *,
           readout_format: str = ".3g"):
    """A FloatSlider that fires on release (``continuous_update=False``)."""
    import ipywidgets as widgets
    return widgets.FloatSlider(value=value, min=min, max=max, step=step, description=description,
                               continuous_update=False, readout_format=readout_format,
                               style={"description_width": "initial"},
                               layout=widgets.Layout(width="320px"))


def int_slider(value: int, min: int, max: int, description: str, *, step: int = 1):
    """An IntSlider that fires on release (``continuous_update=False``)."""
    import ipywidgets as widgets
    return widgets.IntSlider(value=value, min=min, max=max, step=step, description=description,
                             continuous_update=False, style={"description_width": "initial"},
                             layout=widgets.Layout(width="320px"))


def dropdown(options, value, description: str):
    """A Dropdown for a discrete choice (e.g. which controller)."""
    import ipywidgets as widgets
    return widgets.Dropdown(options=options, value=value, description=description,
                            style={"description_width": "initial"})


def rescale(*axes) -> None:
    """Fit each axes' view to the data its artists hold now (after ``set_data`` in an update)."""
    for ax in axes:
        ax.relim()
        ax.autoscale_view()


def figure_png(fig) -> bytes:
    """Render a matplotlib figure to PNG bytes, at the figure's dpi.

    One Agg draw (which also sets the margins, see
    `coursekit.layout.fit_margins`) and a PNG encode, without the extra
    passes `savefig` may make. The Agg canvas is attached to the figure once
    and reused, so its renderer is kept between slider moves. zlib level 1
    encodes in about half the time of the default level, for a PNG about
    15 % larger.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.image import imsave
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    buf = io.BytesIO()
    imsave(buf, canvas.buffer_rgba(), format="png", dpi=fig.dpi,
           pil_kwargs={"compress_level": 1})
    return buf.getvalue()


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
        Figure size in inches; default from matplotlib's settings (so
        `lecture_mode` enlarges it).
    """

    def __init__(self, *, title: str, controls: dict[str, Any], compute: Callable[..., Any],
                 draw: Callable[[Any], Any], update: Callable[[Any, Any], None], figsize=None):
        from matplotlib.figure import Figure
        from ..layout import fit_margins
        self.title = title
        self.controls = dict(controls)
        self._compute = compute
        self._update = update
        self.fig = fit_margins(Figure(figsize=figsize))
        self.handles = draw(self.fig)
        self.result = None
        self._png = b""
        self._widget = None
        self.refresh()

    @property
    def params(self) -> dict[str, Any]:
        """The current value of every control, by name."""
        return {name: w.value for name, w in self.controls.items()}

    def refresh(self) -> None:
        """Recompute for the current control values and redraw the figure."""
        self.result = self._compute(**self.params)
        self._update(self.handles, self.result)
        self._png = figure_png(self.fig)
        if self._widget is not None:
            self._image.value = self._png

    def _on_change(self, change) -> None:
        self.refresh()

    @property
    def widget(self):
        """The live widget: a title, the controls and the figure image."""
        if self._widget is None:
            import ipywidgets as widgets
            self._image = widgets.Image(value=self._png, format="png",
                                        layout=widgets.Layout(max_width="100%"))
            for w in self.controls.values():
                w.observe(self._on_change, names="value")
            header = widgets.HTML(f"<b>{self.title}</b>")
            boxes = widgets.GridBox(list(self.controls.values()),
                                    layout=widgets.Layout(grid_template_columns="repeat(2, 340px)"))
            self._widget = widgets.VBox([header, boxes, self._image])
        return self._widget

    def _repr_mimebundle_(self, include=None, exclude=None):
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude)
        bundle["image/png"] = base64.b64encode(self._png).decode("ascii")
        settings = ", ".join(f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v!r}"
                             for k, v in self.params.items())
        bundle["text/plain"] = f"{self.title} (static figure for {settings})"
        return bundle

    def __repr__(self) -> str:
        return f"<Explorer {self.title!r}: {', '.join(self.controls)}>"
