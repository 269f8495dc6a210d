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
