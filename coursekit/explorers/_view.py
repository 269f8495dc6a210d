"""The browser side of an explorer: its figure at the screen's own pixel size, and its styling.

`FigureView` is a small custom widget (anywidget: JavaScript shipped as a
string, no build step, and it works in JupyterLab, Notebook 7, VS Code and
Colab). It shows the PNG the kernel sends as an ``<img>`` whose CSS size is
the PNG's pixel size divided by the screen's device pixel ratio, so the image
is never scaled by the browser: crisp on an ordinary and on a high-density
screen. It reports back the device pixel ratio and the room the figure has
(the output area's width, and the height of the notebook's visible area less
the explorer's title and controls), so the kernel can render the figure at
exactly the size it is shown and keep the controls and the figure on screen
together.

Its stylesheet lays out the explorer's controls (the label above a slider that
fills its column, so a long label cannot squeeze the track) and, for an
explorer built in lecture mode (CSS class ``ck-lecture``), enlarges the
widgets' text through the ipywidgets CSS variables.
"""

from __future__ import annotations

import anywidget
import traitlets

__all__ = ["FigureView"]

_ESM = r"""
function room(el) {
  const area = el.closest(".jp-OutputArea-output") || el.parentElement || el;
  const width = area.clientWidth;
  const scroller = el.closest(".jp-WindowedPanel-outer, .jp-Notebook, .jp-NotebookPanel-notebook");
  const visible = scroller ? scroller.clientHeight : window.innerHeight;
  const explorer = el.closest(".ck-explorer");
  const others = explorer
    ? explorer.getBoundingClientRect().height - el.getBoundingClientRect().height : 0;
  return { width: Math.floor(width), height: Math.floor(visible - others - 16) };
}

function render({ model, el }) {
  const img = document.createElement("img");
  img.className = "ck-explorer-figure";
  img.alt = model.get("alt");
  el.classList.add("ck-figure-view");
  el.appendChild(img);
  let url = null;

  function show() {
    const data = model.get("png");
    if (!data || data.byteLength === 0) return;
    const next = URL.createObjectURL(new Blob([data], { type: "image/png" }));
    const previous = url;
    url = next;
    img.onload = () => { if (previous) URL.revokeObjectURL(previous); };
    img.style.width = model.get("css_width") + "px";
    img.style.height = model.get("css_height") + "px";
    img.src = next;
  }

  let pending = null;
  function report() {
    pending = null;
    if (!el.isConnected) return;
    const r = room(el);
    const now = { width: r.width, height: r.height, ratio: window.devicePixelRatio || 1 };
    const old = model.get("screen") || {};
    if (now.width > 0 && (Math.abs((old.width || 0) - now.width) > 2 ||
        Math.abs((old.height || 0) - now.height) > 2 || old.ratio !== now.ratio)) {
      model.set("screen", now);
      model.save_changes();
    }
  }
  function schedule() { if (pending === null) pending = setTimeout(report, 150); }

  model.on("change:png", show);
  show();
  const observer = new ResizeObserver(schedule);
  observer.observe(el.closest(".jp-OutputArea-output") || el.parentElement || el);
  window.addEventListener("resize", schedule);
  schedule();
  return () => {
    observer.disconnect();
    window.removeEventListener("resize", schedule);
    if (url) URL.revokeObjectURL(url);
  };
}
export default { render };
"""

_CSS = r"""
.ck-explorer .ck-controls > .widget-slider { flex-wrap: wrap; height: auto; width: auto; }
.ck-explorer .ck-controls > .widget-slider > .widget-label { width: 100% !important; max-width: none;
  text-align: left; line-height: 1.3; height: auto; white-space: normal; }
.ck-explorer .ck-controls > .widget-slider > .slider-container { flex: 1 1 150px; min-width: 150px; }
.ck-explorer .ck-controls > .widget-dropdown { height: auto; flex-wrap: wrap; width: auto; }
.ck-explorer .ck-controls > .widget-dropdown > .widget-label { width: 100% !important; max-width: none;
  text-align: left; line-height: 1.3; }
.ck-explorer .ck-figure-view img.ck-explorer-figure { max-width: none; display: block; }
.ck-explorer.ck-lecture { --jp-widgets-font-size: 20px; --jp-widgets-inline-height: 40px;
  --jp-widgets-slider-handle-size: 22px; font-size: 20px; }
.ck-explorer.ck-lecture .ck-title { font-size: 22px; }
"""


class FigureView(anywidget.AnyWidget):
    """An ``<img>`` shown at its natural pixel size; reports the screen it is shown on.

    Traits: ``png`` (the image, bytes), ``css_width``/``css_height`` (its size
    in CSS pixels, set by the kernel), ``screen`` (set by the browser:
    ``width``/``height`` of the room for the figure in CSS pixels and the
    device pixel ``ratio``) and ``alt`` (the image's text alternative).
    """

    _esm = _ESM
    _css = _CSS
    png = traitlets.Bytes(b"").tag(sync=True)
    css_width = traitlets.Float(0.0).tag(sync=True)
    css_height = traitlets.Float(0.0).tag(sync=True)
    screen = traitlets.Dict({}).tag(sync=True)
    alt = traitlets.Unicode("").tag(sync=True)
