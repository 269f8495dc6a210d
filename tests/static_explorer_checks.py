"""The explorers of a static page (the website, the slides) driven in Chromium: shared by
tests/test_site_browser.py and tests/test_slides.py (coursekit.tools.static_explorers builds them).

`check_page` opens nothing itself: it takes a Playwright page already showing a chapter and the
folder its frames are read from, and for every explorer on it

* waits until its frames are loaded, and checks that every input has its label;
* steps each range input through all its values with the keyboard (arrow keys), for each choice
  of each dropdown: every state a reader reaches shows a loaded frame whose text alternative
  names exactly the settings the inputs stand at (no reachable state without its frame);
* drags each range input with the mouse across its track: the figure and its alt text change,
  each value the hand passes is one swap of the frame (a count, not a time), the polite live
  region announces the figure once the slider rests, and the figure shown is, pixel for pixel,
  the one the explorer renders in this process for the settings the slider snapped to
  (`test_static_explorers.assert_shows`).

A page whose explorers run the same script over data made the same way as a page checked in full
(the student edition, byte for byte the instructor's; the slides, drawn for the screen rather than
the column) is checked with less (`check_page`'s `every_state`): one key step, every frame on the
disk, one drag.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
from PIL import Image

from coursekit.tools.chapters import explorer_factories

__all__ = ["check_page", "explorer_data"]

_STATE_JS = """root => {
  const img = root.querySelector('img.ck-static-figure');
  return {frame: Number(root.dataset.ckFrame), src: img.getAttribute('src'), alt: img.alt,
          loaded: img.complete && img.naturalWidth > 0, natural: [img.naturalWidth, img.naturalHeight],
          swaps: root.ckSwaps, live: root.querySelector('.ck-static-live').textContent,
          readout: root.querySelector('.ck-static-readout').innerText,
          state: [...root.querySelectorAll('[data-ck-control]')].map(i =>
            i.tagName === 'SELECT' ? i.selectedIndex : Number(i.value)),
          valuetexts: [...root.querySelectorAll('input[type=range]')].map(i => i.getAttribute('aria-valuetext'))};
}"""

#: records the state (as `_STATE_JS` reads it) after each input event, the page's own handler
#: having run first; `_TAKE_JS` hands out the records and clears them
_LOG_JS = """root => { if (root.ckLog) return; root.ckLog = [];
  const read = """ + _STATE_JS + """;
  root.querySelectorAll('[data-ck-control]').forEach(i => i.addEventListener('input', () => root.ckLog.push(read(root)))); }"""
_TAKE_JS = "root => root.ckLog.splice(0)"

_LABELS_JS = """root => [...root.querySelectorAll('[data-ck-control]')].map(i =>
  i.labels.length === 1 && i.labels[0].textContent.trim().length > 0)"""

_SET_JS = """(root, [j, index]) => {
  const input = root.querySelectorAll('[data-ck-control]')[j];
  if (input.tagName === 'SELECT') input.selectedIndex = index; else input.value = String(index);
  input.dispatchEvent(new Event('input', {bubbles: true}));
}"""

_COUNT_JS = """root => { root.ckInputs = 0;
  root.querySelectorAll('[data-ck-control]').forEach(i => i.addEventListener('input', () => {
    const key = [...root.querySelectorAll('[data-ck-control]')].map(x =>
      x.tagName === 'SELECT' ? x.selectedIndex : x.value).join(',');
    if (key !== root.ckLastKey) { root.ckInputs += 1; root.ckLastKey = key; }
  }));
  root.ckLastKey = [...root.querySelectorAll('[data-ck-control]')].map(x =>
      x.tagName === 'SELECT' ? x.selectedIndex : x.value).join(','); }"""


_EXPLORERS: dict = {}


def _explorers_by_title() -> dict:
    """{an explorer's title: (its factory, an explorer it made)} for every explorer of the course."""
    if not _EXPLORERS:
        for factory in explorer_factories().values():
            explorer = factory()
            _EXPLORERS[explorer.title] = (factory, explorer)
    return _EXPLORERS


def _settings_text(data: dict, state: list[int]) -> str:
    """The "Settings: ..." part of the alt text for `state`, formatted as `Explorer.alt_for` does."""
    parts = []
    for control, index in zip(data["controls"], state):
        value = control["values"][index]
        parts.append(f"{control['name']} = {value:g}" if isinstance(value, (int, float)) else
                     f"{control['name']} = {value}")
    return "Settings: " + ", ".join(parts) + "."


def _pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(path.read_bytes())).convert("RGB")).astype(int)


def _data(root) -> dict:
    """The explorer's data (`explorer_data` without the frames' images) as the page holds it."""
    script = json.loads(root.locator("script.ck-static-data").text_content())
    controls = [dict(name=None, values=values, texts=texts, kind=kind, default=default)
                for values, texts, kind, default in zip(script["values"], script["texts"], script["kinds"],
                                                        script["defaults"])]
    return dict(script=script, controls=controls)


def _names(explorer, data: dict) -> None:
    for control, name in zip(data["controls"], explorer.controls):
        control["name"] = name


def _step_everywhere(page, root, data: dict, shown: list) -> None:
    """Every value of every range input, with the keyboard, for each choice of each dropdown: each
    state is read in the page as it is reached (`_LOG_JS`), and checked here."""
    controls = data["controls"]
    selects = [j for j, c in enumerate(controls) if c["kind"] == "select"]
    choices = [[]] + [[(j, i)] for j in selects for i in range(len(controls[j]["values"]))]
    root.evaluate(_LOG_JS)
    for choice in choices:
        for j, c in enumerate(controls):
            root.evaluate(_SET_JS, [j, c["default"]]) if c["kind"] == "range" else None
        for j, i in choice:
            root.evaluate(_SET_JS, [j, i])
        for j, control in enumerate(controls):
            if control["kind"] != "range":
                continue
            root.locator("[data-ck-control]").nth(j).focus()
            page.keyboard.press("Home")
            root.evaluate(_TAKE_JS)
            states = [root.evaluate(_STATE_JS)]
            for _ in range(len(control["values"]) - 1):
                page.keyboard.press("ArrowRight")
            states += root.evaluate(_TAKE_JS)
            assert [s["state"][j] for s in states] == list(range(len(control["values"]))), \
                f"the arrow keys did not step through every value: {[s['state'] for s in states]}"
            for state in states:
                assert state["loaded"], f"a reachable state without a loaded frame: {state}"
                assert _settings_text(data, state["state"]) in state["alt"], (state["state"], state["alt"])
                assert state["valuetexts"][sum(c["kind"] == "range" for c in controls[:j])] == \
                    control["texts"][state["state"][j]]
                shown.append(tuple(state["state"]))


def _drag(page, root, j: int, count: int) -> dict:
    """Drag range input `j` from its default to the far end of its track in `count` moves."""
    box = root.locator("[data-ck-control]").nth(j).bounding_box()
    before = root.evaluate(_STATE_JS)
    fraction = before["state"][j] / max(1, count - 1)
    y, x0 = box["y"] + box["height"] / 2, box["x"] + 8 + fraction * (box["width"] - 16)
    far = box["x"] + box["width"] - 2 if fraction < 0.5 else box["x"] + 2
    root.evaluate(_COUNT_JS)
    page.mouse.move(x0, y)
    page.mouse.down()
    for k in range(1, 2 * count + 1):
        page.mouse.move(x0 + (far - x0) * k / (2 * count), y)
    page.mouse.up()
    return before


def check_page(page, folder: Path, *, column: bool, scroll=None, every_state: bool = True,
               render: bool | None = None) -> int:
    """Check every explorer of the chapter `page` shows (see the module's doc); its frames are
    files of `folder` (the page's own folder), drawn for the website's column when `column`.
    `scroll(root)` brings an explorer into view (default: scroll it into view). Without
    `every_state` (for a page whose explorers run the same script over data of the same kind as a
    page checked with it), the keyboard's walk through every state is left out: one key step of
    the first slider is checked instead, every frame file the data names is checked to be on the
    disk and readable, and only the first slider is dragged; its figure is compared with the frame
    file the data names and, with `render` (default: `every_state`; for frames not checked
    elsewhere), with the figure the explorer renders in this process. Returns how many explorers
    were checked."""
    from test_static_explorers import assert_shows    # the figure a fresh explorer shows after one move
    roots = page.locator(".ck-static-explorer")
    for n in range(roots.count()):
        root = roots.nth(n)
        (scroll or (lambda r: r.scroll_into_view_if_needed()))(root)
        page.wait_for_function("r => r.dataset.ckLoaded === 'true'", arg=root.element_handle(), timeout=60_000)
        assert all(root.evaluate(_LABELS_JS)), "an input without its label"
        data = _data(root)
        title = root.locator(".ck-static-title").inner_text().strip()
        factory, explorer = _explorers_by_title()[title]
        _names(explorer, data)
        ranges = [j for j, control in enumerate(data["controls"]) if control["kind"] == "range"]
        if every_state:
            shown: list = []
            _step_everywhere(page, root, data, shown)
            assert set(shown) <= {tuple(map(int, k.split(","))) for k in data["script"]["states"]}
        else:
            _frames_on_disk(folder, data)
            _key_step(page, root, data, ranges[0])
        for j in ranges if every_state else ranges[:1]:
            control = data["controls"][j]
            for k, c in enumerate(data["controls"]):
                root.evaluate(_SET_JS, [k, c["default"]])
            page.wait_for_timeout(50)
            before = _drag(page, root, j, len(control["values"]))
            after = root.evaluate(_STATE_JS)
            moved = abs(after["state"][j] - before["state"][j])
            assert moved >= len(control["values"]) // 3, (title, j, before["state"], after["state"])
            assert after["src"] != before["src"] and after["alt"] != before["alt"], title
            swaps, inputs = after["swaps"] - before["swaps"], root.evaluate("r => r.ckInputs")
            assert swaps == inputs >= moved, (title, j, swaps, inputs, moved)
            page.wait_for_function("r => r.querySelector('.ck-static-live').textContent === "
                                   "r.querySelector('img.ck-static-figure').alt", arg=root.element_handle(),
                                   timeout=5_000)
            settings = {c["name"]: c["values"][i] for c, i in zip(data["controls"], after["state"])}
            frame = _pixels(folder / after["src"])
            assert list(frame.shape[1::-1]) == after["natural"]
            if not every_state:
                named = data["script"]["frames"][data["script"]["states"][",".join(map(str, after["state"]))]]
                assert (after["src"], after["alt"]) == (named["src"], named["alt"]), (after, named)
                assert _settings_text(data, after["state"]) in after["alt"], (after["state"], after["alt"])
            if every_state if render is None else render:
                alt = assert_shows(factory, settings, frame, column=column)
                assert after["alt"] == alt, (after["alt"], alt)
    return roots.count()


def _frames_on_disk(folder: Path, data: dict) -> None:
    """Every state the data stores names a frame, and every frame is a readable image file of
    `folder` (what the keyboard's walk through every state would load)."""
    frames = data["script"]["frames"]
    assert sorted(set(data["script"]["states"].values())) == list(range(len(frames))), "a frame no state shows"
    for frame in frames:
        with Image.open(folder / frame["src"]) as image:
            assert image.size[0] > 0 and image.size[1] > 0, frame["src"]


def _key_step(page, root, data: dict, j: int) -> None:
    """One arrow key on range input `j` (focused) moves it one value and shows that state's frame,
    loaded, with its settings in the alt text."""
    control = data["controls"][j]
    root.locator("[data-ck-control]").nth(j).focus()
    before = root.evaluate(_STATE_JS)
    key, step = ("ArrowLeft", -1) if before["state"][j] == len(control["values"]) - 1 else ("ArrowRight", 1)
    page.keyboard.press(key)
    page.wait_for_function("r => { const i = r.querySelector('img.ck-static-figure'); "
                           "return i.complete && i.naturalWidth > 0; }", arg=root.element_handle(), timeout=10_000)
    after = root.evaluate(_STATE_JS)
    assert after["state"][j] == before["state"][j] + step and after["src"] != before["src"], (before, after)
    assert _settings_text(data, after["state"]) in after["alt"], (after["state"], after["alt"])


def explorer_data(page, folder: Path) -> list:
    """What each explorer of `page` shows: its data as the page holds it, each frame's file as bytes."""
    scripts = page.locator(".ck-static-explorer script.ck-static-data").all_text_contents()
    return [(script, [(folder / frame["src"]).read_bytes() for frame in json.loads(script)["frames"]])
            for script in scripts]
