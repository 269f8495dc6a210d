"""The browser side of an explorer: its figure at the screen's own pixel size, and its styling.

`FigureView` is a small anywidget (JavaScript as a string, no build step). It shows the kernel's
PNG as an ``<img>`` at the PNG's pixel size over the device pixel ratio (never scaled), and
reports the pixel ratio and the room the figure has when shown and when that room changes; it
asks for nothing else, so while nobody touches a control the kernel does no work. The image
carries the text alternative; a polite live region announces it once a control has rested. The
explorer's controls keep the keys pressed on them from the notebook's shortcuts.
"""

from __future__ import annotations

import anywidget
import traitlets

__all__ = ["FigureView"]

_ESM = r"""
const SETTLE_MS = 800;   // a control this long at rest: the live region announces the figure

function room(el) {
  const area = el.closest(".jp-OutputArea-output") || el.parentElement || el;
  const scroller = el.closest(".jp-WindowedPanel-outer, .jp-Notebook, .jp-NotebookPanel-notebook");
  const visible = scroller ? scroller.clientHeight : window.innerHeight;
  const explorer = el.closest(".ck-explorer");
  const others = explorer
    ? explorer.getBoundingClientRect().height - el.getBoundingClientRect().height : 0;
  return { width: Math.floor(area.clientWidth), height: Math.floor(visible - others - 16),
           ratio: window.devicePixelRatio || 1 };
}

function render({ model, el }) {
  const img = document.createElement("img");
  img.className = "ck-explorer-figure";
  el.classList.add("ck-figure-view");
  const live = document.createElement("div");
  live.className = "ck-live";
  live.setAttribute("role", "status");
  live.setAttribute("aria-live", "polite");
  el.append(img, live);
  let url = null, settle = null, pending = null;

  function show() {
    const data = model.get("png");
    if (!data || data.byteLength === 0) return;
    const previous = url;
    url = URL.createObjectURL(new Blob([data], { type: "image/png" }));
    img.onload = () => { if (previous) URL.revokeObjectURL(previous); };
    img.style.width = model.get("css_width") + "px";
    img.style.height = model.get("css_height") + "px";
    img.src = url;
  }
  function describe() {
    img.alt = model.get("alt");
    clearTimeout(settle);
    settle = setTimeout(() => { live.textContent = model.get("alt"); }, SETTLE_MS);
  }
  function report() {
    pending = null;
    if (!el.isConnected) return;
    nameControls();
    const now = room(el), old = model.get("screen") || {};
    if (now.width > 0 && (Math.abs((old.width || 0) - now.width) > 2 ||
        Math.abs((old.height || 0) - now.height) > 2 || old.ratio !== now.ratio)) {
      model.set("screen", now);
      model.save_changes();
    }
  }
  function schedule() { if (pending === null) pending = setTimeout(report, 150); }
  // a slider's handle gets its label as its accessible name (ipywidgets leaves it unnamed); Lumino
  // matches no shortcut on data-lm-suppress-shortcuts, so arrow keys step the slider, not the cells
  let explorer = null;
  function nameControls() {
    if (!explorer && (explorer = el.closest(".ck-explorer"))) {
      named.observe(explorer, { childList: true, subtree: true });
    }
    for (const control of explorer?.querySelectorAll(".ck-controls > .widget-slider") || []) {
      const handle = control.querySelector('[role="slider"]:not([aria-label])');
      const label = control.querySelector(".widget-label")?.textContent.trim();
      if (handle && label) handle.setAttribute("aria-label", label);
    }
    const keyed = '.ck-controls [role="slider"], .ck-controls select, .ck-controls input';
    for (const control of explorer?.querySelectorAll(keyed) || []) {
      control.setAttribute("data-lm-suppress-shortcuts", "true");
    }
  }
  const named = new MutationObserver(nameControls);

  model.on("change:png", show);
  model.on("change:alt", describe);
  show();
  img.alt = model.get("alt");
  const resized = new ResizeObserver(schedule);
  resized.observe(el.closest(".jp-OutputArea-output") || el.parentElement || el);
  window.addEventListener("resize", schedule);
  schedule();
  return () => {
    model.off("change:png", show);
    model.off("change:alt", describe);
    resized.disconnect();
    named.disconnect();
    window.removeEventListener("resize", schedule);
    clearTimeout(settle);
    clearTimeout(pending);
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
.ck-explorer .ck-readout { font-variant-numeric: tabular-nums; line-height: 1.4; min-height: 2.8em; }
.ck-explorer .ck-error { color: var(--jp-error-color1, #b00020); }  /* 5:1 in the light and dark themes */
.ck-explorer .ck-figure-view img.ck-explorer-figure { max-width: none; display: block; }
.ck-explorer .ck-live { position: absolute; width: 1px; height: 1px; overflow: hidden;
  clip-path: inset(50%); white-space: nowrap; }
.ck-explorer.ck-lecture { --jp-widgets-font-size: 20px; --jp-widgets-inline-height: 40px;
  --jp-widgets-slider-handle-size: 22px; font-size: 20px; }
.ck-explorer.ck-lecture .ck-title { font-size: 22px; }
"""


class FigureView(anywidget.AnyWidget):
    """An ``<img>`` at its natural pixel size: ``png``, ``css_width``/``css_height`` and ``alt``
    set by the kernel; ``screen`` (``width``/``height`` of the room in CSS pixels, the pixel
    ``ratio``) set by the browser."""

    _esm = _ESM
    _css = _CSS
    png = traitlets.Bytes(b"").tag(sync=True)
    css_width = traitlets.Float(0.0).tag(sync=True)
    css_height = traitlets.Float(0.0).tag(sync=True)
    screen = traitlets.Dict({}).tag(sync=True)
    alt = traitlets.Unicode("").tag(sync=True)
