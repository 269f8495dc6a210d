"""Explorers without a kernel (coursekit.tools.static_explorers): which settings a static page
stores, that each frame is the figure JupyterLab shows for its settings, and the HTML and files
the builds write. In a browser: tests/test_site_browser.py and tests/test_slides.py."""

import base64
import functools
import html
import io
import json
import re

import nbformat
import numpy as np
import pytest
from PIL import Image

from coursekit.explorers import Explorer, ch1, ch2, dropdown, int_slider, rescale, slider
from coursekit.tools import static_explorers as se
from coursekit.tools.site_figures import drawn_for_the_column


def _lag(fail_above: float | None = None, sliders: int = 1, note: bool = False, **kinds) -> Explorer:
    """A small explorer (docs/extending.md's first-order lag) with up to three sliders and the
    dropdowns `kinds` (name -> options); compute raises for a rate above `fail_above`; with `note`,
    a text right of the axes, as long as the time constant's digits, says how fast the lag is."""
    def compute(a=1.0, gain=1.0, delay=0.0, **choices):
        if fail_above is not None and a > fail_above:
            raise ValueError(f"a = {a:g} is too fast for this test")
        t = np.linspace(0.0, 5.0, 100)
        return dict(t=t, x=gain * (1.0 - np.exp(-a * np.clip(t - delay, 0, None))), tau=1.0 / a)

    def draw(fig):
        ax = fig.subplots()
        line, = ax.plot([], [], label="x(t)")
        ax.set(xlabel="time t [s]", ylabel="x", title="step response")
        return dict(ax=ax, line=line, note=ax.text(1.03, 0.5, "", transform=ax.transAxes) if note else None)

    def update(h, r):
        h["line"].set_data(r["t"], r["x"])
        if note:
            h["note"].set_text(f"tau = {r['tau']:.6g} s")
        h["ax"].set_xlim(0, r["t"][-1])
        rescale(h["ax"])

    controls = dict(a=slider(1.0, 0.2, 5.0, 0.1, "rate a [1/s]"),
                    gain=slider(1.0, 0.5, 3.0, 0.5, "gain"),
                    delay=int_slider(0, 0, 3, "delay [s]"))
    controls = dict(list(controls.items())[:sliders])
    controls.update({name: dropdown(options, options[0], name) for name, options in kinds.items()})
    return Explorer(title="First-order lag", controls=controls, compute=compute, draw=draw, update=update,
                    readout=lambda r: f"time constant tau = {r['tau']:.3g} s", figsize=(4, 3))


def _pixels(image: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(image)).convert("RGB")).astype(int)


# -- which settings are stored ----------------------------------------------------------------

@pytest.mark.parametrize("widget, count", [
    (slider(0.1, 0.01, 1.0, 0.01, "Ts [s]"), 21),
    (slider(-2.0, -6.0, -0.5, 0.25, "pole"), 8),
    (int_slider(2, 2, 4, "r"), 10),
    (slider(-0.30103, -4.00103, 2.99897, 0.1, "log10 Q"), 12),   # a grid off round numbers
])
def test_slider_values_hold_the_default_both_ends_and_only_values_the_slider_can_hold(widget, count):
    values = se.slider_values(widget, count)
    assert len(values) <= count and values == sorted(set(values))
    assert widget.value in values and values[0] == widget.min and values[-1] == widget.max
    steps = (np.array(values) - widget.min) / widget.step
    assert np.allclose(steps, np.round(steps), atol=1e-6)
    assert all(type(v) is type(widget.value) for v in values)
    natural = round((widget.max - widget.min) / widget.step) + 1
    assert len(values) == min(natural, count) or len(values) >= count - 2   # no values thrown away


def test_one_slider_at_a_time_with_every_dropdown_choice_when_the_grid_does_not_fit():
    explorer = _lag(sliders=3, system=["a", "b"])
    chosen = se.plan(explorer, 40)
    controls, states = chosen["controls"], chosen["states"]
    assert not chosen["full"] and len(states) <= 40 and len(set(states)) == len(states)
    defaults = [c["default"] for c in controls]
    for state in states:      # at most one slider away from its default
        assert sum(s != d for s, d, c in zip(state, defaults, controls) if c["kind"] == "range") <= 1
    for j, control in enumerate(controls[:3]):   # each slider's every stored value, for each choice
        for i in range(len(control["values"])):
            for choice in range(2):
                state = list(defaults)
                state[j], state[3] = i, choice
                assert tuple(state) in states
    assert [len(c["values"]) for c in controls] == [7, 6, 4, 2]


def test_the_full_grid_when_enough_values_of_each_slider_fit():
    chosen = se.plan(_lag(sliders=2), 100)
    assert chosen["full"]
    counts = [len(c["values"]) for c in chosen["controls"]]
    assert len(chosen["states"]) == np.prod(counts) <= 100 and min(counts) >= se.FULL_GRID_MIN - 1


@pytest.mark.parametrize("call, error, match", [
    (lambda: se.slider_values(slider(1.0, 0.0, 2.0, 0.1, "a"), 1), ValueError, "count must be a whole number >= 2"),
    (lambda: se.plan(_lag(), 0), ValueError, "max_frames must be a whole number >= 1"),
    (lambda: se.explorer_html({"frames": [{}], "controls": [], "states": []}, [], ident="x"), ValueError,
     "sources must give one address per frame"),
])
def test_bad_arguments_are_named(call, error, match):
    with pytest.raises(error, match=match):
        call()


# -- each frame is the figure of its settings -------------------------------------------------

@functools.lru_cache(maxsize=64)     # each a few MB: the site's two editions ask for the same
def _one_move_cached(factory, settings: tuple, column: bool) -> tuple[np.ndarray, str]:
    image, alt = _one_move(factory, dict(settings), column=column)
    return image.astype(np.uint8), alt


def _one_move(factory, settings: dict, *, column: bool) -> tuple[np.ndarray, str]:
    """The figure a fresh explorer shows in JupyterLab after one move to `settings` (a single
    control changed), as the website draws it (`column`) or at its natural size, and its alt."""
    fresh = factory()
    places = [(ax, ax.get_position(original=True)) for ax in fresh.fig.axes]   # where the defaults put them
    changed = {name: value for name, value in settings.items() if fresh.params[name] != value}
    assert len(changed) <= 1, changed
    with (drawn_for_the_column(fresh.fig, fresh.natural_dpi) if column else _natural(fresh)):
        for name, value in changed.items():
            fresh.controls[name].value = value
        for ax, place in places:             # laid out from there, as the build does for each frame
            ax.set_position(place)
            ax.set_in_layout(True)
        fresh.frames.reset()                 # a full draw: not blitted over the defaults' layout
        se.render_laid_out(fresh)
        return np.asarray(fresh.frames.canvas.buffer_rgba())[..., :3].astype(int), fresh.alt


def assert_shows(factory, settings: dict, shown: np.ndarray, *, column: bool) -> str:
    """Assert that `shown` (pixels) is the figure of `settings`: equal, within 2 levels per pixel,
    to a fresh explorer's after one move to them (every explorer, the robot planner's path of one
    scale too: its limits depend on the settings alone). Returns the fresh explorer's alt text."""
    reference, alt = _one_move_cached(factory, tuple(sorted(settings.items())), column)
    reference = reference.astype(int)
    assert shown.shape == reference.shape, settings
    assert np.abs(shown - reference).max() <= 2, settings      # a blit's antialiasing: 1 level
    return alt


class _natural:
    def __init__(self, explorer):
        self.explorer = explorer

    def __enter__(self):
        self.explorer.fig.set_dpi(self.explorer.natural_dpi)

    def __exit__(self, *exc):
        return False


@pytest.mark.parametrize("factory, column", [(ch2.planner_explorer, True), (ch1.euler_explorer, False),
                                             (ch2.robot_planner_explorer, True)],
                         ids=["planner-site", "euler-slides", "robot-planner-site"])
def test_each_frame_is_the_figure_of_one_move_from_the_defaults(factory, column):
    """Rendered together, in the order the module draws them (blitting where it can), each frame
    is what a fresh explorer shows after one move to its settings, laid out from where the
    defaults put its axes."""
    explorer = factory()
    chosen = se.plan(explorer, 24)
    defaults = [c["default"] for c in chosen["controls"]]
    states = [s for s in chosen["states"] if sum(a != b for a, b in zip(s, defaults)) <= 1]
    settings = [se._settings(chosen["controls"], s) for s in states]
    frames = se.render_frames(explorer, settings, column=column)
    assert explorer.frames.full_draws + explorer.frames.blits > len(frames)
    for n in range(0, len(frames), 3):
        alt = assert_shows(factory, settings[n], _pixels(frames[n]["image"]), column=column)
        frame = frames[n]
        assert frame["alt"] == alt and frame["readout"].replace("\n", "; ") in alt
    assert explorer.params == {c["name"]: c["values"][c["default"]] for c in chosen["controls"]}


@pytest.mark.parametrize("note", [False, True], ids=["curve-only", "text-beside-the-axes"])
def test_frames_drawn_together_are_those_drawn_alone_and_blitted_where_the_layout_stays(note):
    """Rates of the same limits: their frames share a layout, and all but the first are blitted in
    it, unless a text beside the axes changes with them (constrained layout measures it: each frame
    is laid out again). Either way each frame is the frame rendered alone (here byte for byte; a
    blit's antialiasing may differ by a level elsewhere, as `assert_shows` allows)."""
    rates = [1.5, 2.0, 2.5, 3.0, 4.0, 5.0]
    explorer = _lag(note=note)
    together = se.render_frames(explorer, [dict(a=a) for a in rates], column=False)
    alone = [se.render_frames(_lag(note=note), [dict(a=a)], column=False)[0] for a in rates]
    for a, drawn, reference in zip(rates, together, alone):
        shown, expected = _pixels(drawn["image"]), _pixels(reference["image"])
        assert shown.shape == expected.shape and np.abs(shown - expected).max() <= 2, a
    assert len({f["image"] for f in together}) == len(rates)
    assert explorer.frames.blits == (0 if note else len(rates) - 1), explorer.frames.blits


def test_a_setting_compute_fails_for_shows_the_default_figure_and_says_why():
    explorer = _lag(fail_above=4.0)
    fine, failing = se.render_frames(explorer, [dict(a=1.0), dict(a=4.5)], column=False)
    assert np.array_equal(_pixels(fine["image"]), _pixels(failing["image"]))
    assert failing["readout"].startswith("No figure for these settings: ValueError: a = 4.5 is too fast")
    assert "Settings: a = 4.5." in failing["alt"]
    assert explorer.error is None and explorer.text == "time constant tau = 1 s"


# -- the data, the HTML and the files -------------------------------------------------------

def test_explorer_data_stays_within_the_frame_budget(monkeypatch):
    plenty = se.explorer_data(_lag(sliders=2), column=False, max_frames=30)
    sizes = [len(base64.b64decode(f["image"])) for f in plenty["frames"]]
    monkeypatch.setattr(se, "FRAME_BUDGET", 8 * max(sizes))
    tight = se.explorer_data(_lag(sliders=2), column=False, max_frames=30)
    assert len(plenty["frames"]) > 8 >= len(tight["frames"]) >= 3
    assert sum(len(base64.b64decode(f["image"])) for f in tight["frames"]) <= se.FRAME_BUDGET
    json.dumps(tight)      # what the kernel sends: JSON


def test_publish_writes_the_frames_and_puts_labelled_inputs_in_place_of_the_explorer(tmp_path):
    data = se.explorer_data(_lag(sliders=2, system=["first </script> order", "second"]), column=False,
                            max_frames=16)
    output = nbformat.v4.new_output("display_data", data={se.MIME: data, "image/png": "iVBOR",
                                                         "text/plain": "explorer"})
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("lag_explorer()", outputs=[output])])
    written = se.publish(nb, tmp_path / "assets", "assets", stem="05_lag")
    assert list(output.data) == ["text/html"] and len(written) == len(data["frames"])
    page = output.data["text/html"]
    files = sorted((tmp_path / "assets" / "05_lag-1").iterdir())
    assert len(files) == len(data["frames"]) and all(Image.open(f).format == "WEBP" for f in files)
    assert sum(f["bytes"] for f in written) == sum(f.stat().st_size for f in files)
    # every input has its label, the range inputs step through the stored values only
    ids = re.findall(r'<(?:input|select) [^>]*id="([^"]+)"', page)
    assert len(ids) == 3 and all(f'<label for="{i}">' in page for i in ids)
    ranges = re.findall(r'<input type="range" [^>]*max="(\d+)" step="1" value="(\d+)" aria-valuetext="([^"]+)"', page)
    assert [(int(m) + 1, int(v)) for m, v, _ in ranges] == [(len(c["values"]), c["default"])
                                                           for c in data["controls"][:2]]
    assert [t for *_, t in ranges] == ["1", "1"]
    # the data the script reads: one frame per stored state, each a file written
    payload = re.search(r'<script type="application/json" class="ck-static-data">(.*?)</script>', page, re.S)
    script = json.loads(payload.group(1))
    assert sorted(script["states"].values()) == list(range(len(data["frames"])))
    assert {f["src"] for f in script["frames"]} == {f"assets/05_lag-1/{p.name}" for p in files}
    assert "first &lt;/script&gt; order" in page and "first <\\/script> order" in payload.group(1)
    assert html.unescape(re.search(r'<img [^>]*alt="([^"]+)"', page).group(1)).startswith(
        "First-order lag. Settings: a = 1, gain = 1, system = first </script> order.")
    assert "one slider at a time" in page or "every combination" in page


def test_a_build_over_its_budget_says_so():
    with pytest.raises(RuntimeError, match="take 30.1 MB, more than the 30 MB allowed"):
        se.check_site_budget([{"bytes": 30_100_000}], what="the site")
    se.check_site_budget([{"bytes": 29_000_000}], what="the site")


def test_the_script_and_its_style_sheet_ship_with_the_package(tmp_path):
    se.copy_assets(tmp_path)
    script = (tmp_path / "explorers.js").read_text(encoding="utf-8")
    assert "fetch(" not in script and "http" not in script and "import " not in script
    assert 'aria-live' not in script and "live.textContent" in script      # the page's region, filled at rest
    assert (tmp_path / "explorers.css").stat().st_size > 0
