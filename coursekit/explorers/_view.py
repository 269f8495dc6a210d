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
import ipywidgets as widgets
import traitlets

__all__ = ["FigureView"]

_ESM = r"""
const SLIDERS = new Set(["FloatSliderModel", "IntSliderModel"]);
const FRAME_BYTES = 48 * 1024 * 1024;  // the frames a view keeps, at most
const REPLY_TIMEOUT_MS = 30000;        // a request unanswered this long is given up

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

// true while cells of the notebook showing `el` run or wait to run (JupyterLab and Notebook
// show them as [*]): each widget message the kernel gets then makes it flush the running
// cell's figures, on another thread where the front end uses kernel subshells
function cellsRunning(el) {
  const notebook = el.closest(".jp-Notebook");
  if (!notebook) return false;
  return Array.from(notebook.querySelectorAll(".jp-InputPrompt"))
    .some(prompt => prompt.textContent.includes("*"));
}

// the controls' models, in order: [{name, model}]
async function controlModels(model) {
  const refs = Object.entries(model.get("controls") || {});
  return Promise.all(refs.map(async ([name, ref]) => ({
    name, model: await model.widget_manager.get_model(String(ref).replace(/^IPY_MODEL_/, "")),
  })));
}

// a setting as the kernel's settings_now gives it: a choice's index, another control's value
function setting(m) {
  const index = m.get("index");
  return index === undefined ? m.get("value") : index;
}

// the positions of a slider around `value`: the nearest few both ways (a key step), then on
// towards the farther end of the range (where a hand has room to go), then towards the nearer
// one; one step apart after the first few, so the kernel mostly redraws only what moved
const NEAREST = 3;
function* positions(m, value) {
  const min = m.get("min"), max = m.get("max"), step = m.get("step");
  if (!(step > 0) || !(max > min)) return;
  const count = Math.floor((max - min) / step + 1e-9);
  const here = Math.round((value - min) / step);
  const at = i => Number((min + i * step).toPrecision(12));
  for (let k = 1; k <= NEAREST; k++) {
    for (const i of [here + k, here - k]) if (i >= 0 && i <= count) yield at(i);
  }
  const up = count - here >= here;
  for (const direction of up ? [1, -1] : [-1, 1]) {
    for (let i = here + direction * (NEAREST + 1); i >= 0 && i <= count; i += direction) yield at(i);
  }
}

// frames by settings: the kernel's and those asked for ahead of the hand
class Frames {
  constructor() { this.list = []; this.bytes = 0; this.generation = null; this.refused = []; }
  same(a, b, controls) {
    return controls.every(({ name, model }) => {
      const x = a[name], y = b[name];
      if (x === y) return true;
      const step = SLIDERS.has(model.get("_model_name")) ? model.get("step") : 0;
      return typeof x === "number" && typeof y === "number" && Math.abs(x - y) <= 1e-6 * step;
    });
  }
  find(values, controls) {
    return this.list.find(f => this.same(f.values, values, controls)) || null;
  }
  isRefused(values, controls) { return this.refused.some(v => this.same(v, values, controls)); }
  add(frame) {
    this.list.push(frame);
    this.bytes += frame.size;
  }
  // drop the frames used least recently, except those `keep` accepts, until `bytes` remain
  trim(keep, bytes) {
    const order = this.list.filter(f => !keep(f)).sort((a, b) => a.used - b.used);
    while (this.bytes > bytes && order.length) {
      const f = order.shift();
      this.list.splice(this.list.indexOf(f), 1);
      this.bytes -= f.size;
      URL.revokeObjectURL(f.url);
    }
  }
  clear(generation, shown) {
    for (const f of this.list) if (f !== shown) URL.revokeObjectURL(f.url);
    this.list = []; this.bytes = 0; this.refused = []; this.generation = generation;
  }
}

function render({ model, el }) {
  const img = document.createElement("img");
  img.className = "ck-explorer-figure";
  img.alt = model.get("alt");
  el.classList.add("ck-figure-view");
  el.appendChild(img);

  const frames = new Frames();
  frames.generation = model.get("generation");
  let controls = null;     // [{name, model}] once resolved
  let latest = null;       // the kernel's last frame
  let shown = null;
  let asked = null;        // the request in flight: {values, timer}
  let visible = false;
  let focus = null;        // name of the control under the pointer or with the focus
  let clock = 0;
  const me = Math.random().toString(36).slice(2);   // replies to another view of this model
                                                   // are frames too, but not this view's answer

  const current = () => Object.fromEntries(controls.map(({ name, model: m }) => [name, setting(m)]));

  function frameOf(data, values, generation) {
    const blob = new Blob([data], { type: "image/png" });
    return { values, generation, url: URL.createObjectURL(blob), size: blob.size, used: ++clock,
             width: model.get("css_width"), height: model.get("css_height") };
  }

  // show the frame of the controls' settings if there is one, else the kernel's last frame
  function display() {
    const match = controls ? frames.find(current(), controls) : null;
    const frame = match || latest;
    if (!frame || frame === shown) return;
    const previous = shown;
    frame.used = ++clock;
    shown = frame;
    img.onload = () => {   // a frame dropped from the list while shown is released once replaced
      if (previous && !frames.list.includes(previous) && previous !== shown) {
        URL.revokeObjectURL(previous.url);
      }
    };
    img.style.width = frame.width + "px";
    img.style.height = frame.height + "px";
    img.src = frame.url;
    img.dataset.frame = match && match.ahead ? "ahead" : "kernel";
  }

  // frames on the cross of the current settings (all but one control there) are kept first
  function nearby(frame) {
    if (frame === shown || frame === latest) return true;
    const now = current();
    const off = controls.filter(c => !frames.same({ [c.name]: frame.values[c.name] },
                                                  { [c.name]: now[c.name] }, [c]));
    return off.length <= 1;
  }

  function keep(frame) {
    frames.add(frame);
    if (frames.bytes > FRAME_BYTES) frames.trim(f => f === frame || (controls ? nearby(f) : f === shown),
                                                0.75 * FRAME_BYTES);
    el.dataset.held = frames.list.length;   // for tests and the curious: frames held
  }

  function fromKernel() {
    const data = model.get("png");
    if (!data || data.byteLength === 0) return;
    const generation = model.get("generation");
    if (generation !== frames.generation) newGeneration();
    const values = model.get("values") || {};
    const known = controls ? frames.find(values, controls) : null;
    if (known) {
      latest = known;
    } else {
      latest = frameOf(data, values, generation);
      keep(latest);
    }
    display();
    ask();
  }

  // the kernel's frames changed resolution: the frames held are not shown again
  function newGeneration() {
    frames.clear(model.get("generation"), shown);
    latest = null;
  }

  function nextSettings() {
    const now = current();
    const sliders = controls.filter(c => SLIDERS.has(c.model.get("_model_name")));
    sliders.sort((a, b) => (b.name === focus) - (a.name === focus));
    const walks = sliders.map(c => ({ c, it: positions(c.model, now[c.name]) }));
    const first = walks.length && walks[0].c.name === focus ? [walks.shift()] : [];
    for (const group of [first, walks]) {
      while (group.length) {
        for (const walk of [...group]) {
          const next = walk.it.next();
          if (next.done) { group.splice(group.indexOf(walk), 1); continue; }
          const values = { ...now, [walk.c.name]: next.value };
          if (!frames.find(values, controls) && !frames.isRefused(values, controls)) return values;
        }
      }
    }
    return null;
  }

  // ask the kernel for the next frame ahead of the hand: one request at a time, while on screen
  // and no cell runs
  let later = null;
  function ask() {
    if (asked || !controls || !visible || document.hidden || !model.get("ahead") || pressed) return;
    if (cellsRunning(el)) {
      if (later === null) later = setTimeout(() => { later = null; ask(); }, 500);
      return;
    }
    if (frames.bytes > 0.9 * FRAME_BYTES) frames.trim(nearby, 0.75 * FRAME_BYTES);
    if (frames.bytes > 0.9 * FRAME_BYTES) return;   // the frames near the settings fill the budget
    const values = nextSettings();
    if (!values) return;
    const timer = setTimeout(() => { asked = null; }, REPLY_TIMEOUT_MS);
    asked = { values, timer };
    model.send({ type: "frame", values, generation: frames.generation, view: me });
  }

  function onReply(msg, buffers) {
    if (!msg || (msg.type !== "frame" && msg.type !== "no-frame")) return;
    if (asked && msg.view === me) { clearTimeout(asked.timer); asked = null; }
    if (msg.generation === frames.generation && controls) {
      if (msg.type === "no-frame") {
        frames.refused.push(msg.values);
      } else if (buffers && buffers.length && !frames.find(msg.values, controls)) {
        const frame = frameOf(buffers[0], msg.values, msg.generation);
        frame.ahead = true;
        keep(frame);
        display();
      }
    }
    setTimeout(ask, 0);
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

  // which control the hand is at: the controls' boxes are in the controls' order
  function pointAt(event) {
    const box = el.closest(".ck-explorer")?.querySelector(".ck-controls");
    if (!controls || !box) return;
    const child = Array.from(box.children).find(c => c.contains(event.target));
    const index = child ? Array.from(box.children).indexOf(child) : -1;
    if (index >= 0 && index < controls.length) focus = controls[index].name;
  }

  // while a hand holds a control (a drag), the kernel answers the control alone: a frame
  // ahead asked for then would make the drag's next frame wait
  let pressed = false;
  const press = event => { if (event.target.closest?.(".ck-controls")) pressed = true; };
  const release = () => { if (pressed) { pressed = false; ask(); } };

  let removed = false;
  const onControl = () => { display(); ask(); };
  const onAlt = () => { img.alt = model.get("alt"); };
  model.on("change:png", fromKernel);
  model.on("change:alt", onAlt);
  model.on("change:generation", newGeneration);
  model.on("msg:custom", onReply);
  fromKernel();
  controlModels(model).then(found => {
    if (removed) return;
    controls = found;
    for (const { model: m } of controls) m.on("change:value change:index", onControl);
    display();
    ask();
  }).catch(() => { controls = null; });   // without the controls, the kernel's frames only
  const explorer = el.closest(".ck-explorer");
  explorer?.addEventListener("pointerover", pointAt);
  explorer?.addEventListener("focusin", pointAt);
  explorer?.addEventListener("pointerdown", press);
  window.addEventListener("pointerup", release);
  window.addEventListener("pointercancel", release);
  const seen = new IntersectionObserver(entries => {
    visible = entries.some(e => e.isIntersecting);
    ask();
  });
  seen.observe(el);
  const resized = new ResizeObserver(schedule);
  resized.observe(el.closest(".jp-OutputArea-output") || el.parentElement || el);
  window.addEventListener("resize", schedule);
  document.addEventListener("visibilitychange", ask);
  schedule();
  return () => {   // the view is removed (its output cleared): it holds, shows and asks nothing more
    removed = true;
    visible = false;
    model.off("change:png", fromKernel);
    model.off("change:alt", onAlt);
    model.off("change:generation", newGeneration);
    model.off("msg:custom", onReply);
    for (const { model: m } of controls || []) m.off("change:value change:index", onControl);
    seen.disconnect();
    resized.disconnect();
    window.removeEventListener("resize", schedule);
    document.removeEventListener("visibilitychange", ask);
    explorer?.removeEventListener("pointerover", pointAt);
    explorer?.removeEventListener("focusin", pointAt);
    explorer?.removeEventListener("pointerdown", press);
    window.removeEventListener("pointerup", release);
    window.removeEventListener("pointercancel", release);
    if (asked) clearTimeout(asked.timer);
    if (later !== null) clearTimeout(later);
    frames.clear(null, null);
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
    """An ``<img>`` shown at its natural pixel size; reports the screen it is shown on; keeps
    frames ahead of the hand.

    Traits: ``png`` (the image, bytes) and ``values`` (the controls' settings it
    shows: a slider's value, a choice's index), ``css_width``/``css_height``
    (its size in CSS pixels, set by the kernel), ``screen`` (set by the
    browser: ``width``/``height`` of the room for the figure in CSS pixels and
    the device pixel ``ratio``), ``alt`` (the image's text alternative),
    ``controls`` (the explorer's control widgets by name), ``generation``
    (raised when the kernel's frames change resolution, so the browser drops
    the ones it holds) and ``ahead`` (whether to ask for frames ahead).

    While on screen and while no cell of its notebook runs, the view asks the
    kernel for the frames of the slider positions around the current settings,
    one request at a time (a custom message ``{"type": "frame", "values": ...,
    "generation": ..., "view": ...}``, answered by a ``"frame"`` message with
    the PNG as its buffer or by ``"no-frame"``): a few steps both ways, then
    step by step towards the farther end of each slider's range and back to the
    nearer one, the slider under the pointer or with the focus first. It shows a
    held frame as soon as the controls reach its settings, and keeps at most
    48 MB of frames, dropping first those least recently shown and away from the
    current settings.
    """

    _esm = _ESM
    _css = _CSS
    png = traitlets.Bytes(b"").tag(sync=True)
    values = traitlets.Dict({}).tag(sync=True)
    controls = traitlets.Dict({}).tag(sync=True, **widgets.widget_serialization)
    generation = traitlets.Int(0).tag(sync=True)
    ahead = traitlets.Bool(True).tag(sync=True)
    css_width = traitlets.Float(0.0).tag(sync=True)
    css_height = traitlets.Float(0.0).tag(sync=True)
    screen = traitlets.Dict({}).tag(sync=True)
    alt = traitlets.Unicode("").tag(sync=True)
