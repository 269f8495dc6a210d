// coursekit's explorers on a static page (the website, the slides): the frames rendered at build
// time by the explorer's own code (coursekit.tools.static_explorers), shown as the inputs move.
// No framework, no request but the frames. Each input steps through the stored values only; on a
// page that stores one slider at a time, moving a slider brings the others back to their defaults.
(() => {
  "use strict";
  const SETTLE_MS = 800;   // the inputs this long at rest: the live region announces the figure

  function start(root) {
    if (root.dataset.ckReady) return;
    root.dataset.ckReady = "true";
    const data = JSON.parse(root.querySelector("script.ck-static-data").textContent);
    const inputs = [...root.querySelectorAll("[data-ck-control]")];
    let img = root.querySelector("img.ck-static-figure");
    const readout = root.querySelector(".ck-static-readout");
    const live = root.querySelector(".ck-static-live");
    let settle = null, preloaded = null, shown = -1;
    root.ckSwaps = 0;

    const index = input => input.tagName === "SELECT" ? input.selectedIndex : Number(input.value);
    const key = state => state.join(",");

    // every frame fetched and decoded once, before a hand needs it: a swap puts the decoded image
    // in place of the one shown (setting the src of the shown one would decode it again)
    function preload() {
      if (preloaded) return preloaded;
      preloaded = Promise.all(data.frames.map(frame => {
        const image = img.cloneNode(false);
        image.src = frame.src;
        image.alt = frame.alt;
        return image.decode().then(() => { frame.image = image; }, () => undefined);
      })).then(() => { root.dataset.ckLoaded = "true"; });
      return preloaded;
    }

    function setInputs(state) {
      inputs.forEach((input, j) => {
        if (input.tagName === "SELECT") input.selectedIndex = state[j];
        else input.value = String(state[j]);
        const text = data.texts[j][state[j]];
        if (input.tagName !== "SELECT") input.setAttribute("aria-valuetext", text);
        const value = input.parentElement.querySelector(".ck-static-value");
        if (value) value.textContent = text;
      });
    }

    function show(n) {
      const frame = data.frames[n];
      if (n !== shown) {
        if (frame.image && frame.image !== img) {
          img.replaceWith(frame.image);
          img = frame.image;
        } else if (!frame.image) {
          img.src = frame.src;
          img.alt = frame.alt;
        }
        readout.replaceChildren(...frame.readout.split("\n").flatMap((line, i) =>
          i ? [document.createElement("br"), line] : [line]));
        shown = n;
        root.ckSwaps += 1;
        root.dataset.ckFrame = String(n);
      }
      clearTimeout(settle);
      settle = setTimeout(() => { live.textContent = frame.alt; }, SETTLE_MS);
    }

    // the state the inputs stand at, or (one slider at a time) the moved one with the other
    // sliders at their defaults: always a stored state
    function moved(changed) {
      preload();
      let state = inputs.map(index);
      if (!(key(state) in data.states)) {
        state = state.map((v, j) => j === changed || data.kinds[j] === "select" ? v : data.defaults[j]);
      }
      if (!(key(state) in data.states)) {
        state = data.defaults.map((v, j) => j === changed ? state[j] : v);
      }
      setInputs(state);
      show(data.states[key(state)]);
    }

    inputs.forEach((input, j) => input.addEventListener("input", () => moved(j)));
    root.addEventListener("pointerenter", preload, { once: true });
    root.addEventListener("focusin", preload, { once: true });
    if ("IntersectionObserver" in window) {
      const near = new IntersectionObserver(entries => {
        if (entries.some(e => e.isIntersecting)) { preload(); near.disconnect(); }
      }, { rootMargin: "100% 0px" });
      near.observe(root);
    } else {
      preload();
    }
    shown = data.states[key(inputs.map(index))];
    root.dataset.ckFrame = String(shown);
  }

  function startAll() { document.querySelectorAll(".ck-static-explorer").forEach(start); }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", startAll);
  else startAll();
})();
