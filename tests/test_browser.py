"""A real-browser test: JupyterLab + headless Chromium driven by Playwright.

For each chapter notebook: open it in JupyterLab and assert that, untouched, it
is not marked modified once its kernel is connected, Run > Run All Cells, wait
until the kernel is done, assert that no cell shows a traceback, then move the
first slider of an explorer with the keyboard and assert that the explorer's
figure changes.

Then what a student feels when dragging a slider, on a small demo explorer
(which also tests the harness itself) and on a real one (the mass-spring-damper
of chapter 1): during a slow drag the figure follows (it changes at least
twice before the mouse is released); after the release the figure shown is
the one the explorer computes for the value the slider shows (pixel for pixel,
against the explorer's figure computed and drawn whole again in the kernel for
its final parameters); with a chapter open, the kernel does no work while
nobody touches a control; and nothing anywhere reports an error (no traceback
or stderr in a cell, no error or stderr message from the kernel, widget
callbacks included, no uncaught error in the page). Nothing here asserts a
time; ``python benchmarks/run.py --browser`` measures them. In Notebook 7
(served by the same server), arrow keys, Home and End on a focused slider step
it and leave the notebook's cell selection alone.

Needs Playwright for Python (``pip install playwright``, part of the dev extra)
and the system Chromium (Debian package ``chromium``; no browser download).
Skipped with the reason when either is missing. Run only these tests with
``python -m pytest -m browser``; leave them out with ``-m "not browser"``.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import shutil
import time
from pathlib import Path

import nbformat
import numpy as np
import pytest

import lab_harness as lab_h
from coursekit.explorers import ch2
from coursekit.tools.notebooks import chapter_notebooks

pytestmark = pytest.mark.browser

NOTEBOOKS = Path(__file__).parents[1] / "notebooks"
RUN_TIMEOUT_S = 240          # one notebook, run all cells
SLIDER_TIMEOUT_S = 30        # recompute after a slider move

DEMO_SOURCE = [
    "%matplotlib inline\nimport numpy as np\nimport coursekit as ck\nfrom coursekit.explorers import Explorer, slider",
    "ck.check_environment()",
    "def compute(a):\n    t = np.linspace(0, 5, 400)\n    return t, np.exp(-a * t) * np.cos(3 * t)\n\n"
    "def draw(fig):\n    ax = fig.subplots()\n    line, = ax.plot([], [])\n"
    "    ax.set(title='harness demo', xlabel='t [s]', ylabel='y [m]')\n    return ax, line\n\n"
    "def update(handles, result):\n    ax, line = handles\n    line.set_data(*result)\n"
    "    ax.relim(); ax.autoscale_view()\n\n"
    "def make_demo():\n"
    "    return Explorer(title='Demo', controls={'a': slider(1.0, 0.1, 3.0, 0.1, 'a')},\n"
    "                    compute=compute, draw=draw, update=update)\n\n"
    "demo = make_demo()\ndemo",
]

# notebook -> (cells, variable holding the explorer shown)
DRAG_NOTEBOOKS = {
    "demo_explorer.ipynb": (DEMO_SOURCE, "demo"),
    "msd_explorer.ipynb": (["%matplotlib inline\nfrom coursekit.explorers.ch1 import msd_explorer",
                            "explorer = msd_explorer()\nexplorer"], "explorer"),
}
PLANNER_NOTEBOOK = "planner_explorer.ipynb"
PLANNER_CELLS = ["%matplotlib inline\nfrom coursekit.explorers.ch2 import planner_explorer",
                 "explorer = planner_explorer()\nexplorer"]
# run in the planner's kernel: the limits shown, and a fresh explorer's after one move to its T
_PLANNER_LIMITS_CODE = """\
import json as _json
_fresh = planner_explorer()
_fresh.controls["T"].value = explorer.controls["T"].value
_limits = lambda e: [[list(map(float, ax.get_xlim())), list(map(float, ax.get_ylim()))] for ax in e.fig.axes]
print(_json.dumps({"T": explorer.params["T"], "end": float(explorer.result["t"][-1]),
                   "shown": _limits(explorer), "fresh": _limits(_fresh)}))
"""

_EXPLORER_IMAGES_JS = f"""() => Array.from(document.querySelectorAll(
    '{lab_h.EXPLORER.replace(", ", " img, ")} img')).map(i => i.src)"""

# the bytes of the figure the explorer shows now (blob: and data: URLs alike), base64
_SHOWN_PNG_JS = f"""async () => {{
    const img = document.querySelector('{lab_h.EXPLORER.replace(", ", " img, ")} img');
    const bytes = new Uint8Array(await (await fetch(img.src)).arrayBuffer());
    let text = '';
    for (const b of bytes) {{ text += String.fromCharCode(b); }}
    return btoa(text);
}}"""

# run in the notebook's kernel: the shown explorer's parameters, and its figure computed and
# drawn whole again for them (the axes stay where they are, as for any frame with the same data)
_REFERENCE_CODE = """\
import base64 as _base64
import json as _json
_shown = {shown}
_shown._update(_shown.handles, _shown._compute(**_shown.params))
_shown.frames.reset()
_png = _base64.b64encode(_shown.frames.frame()).decode("ascii")
print(_json.dumps({{"params": _shown.params, "png": _png}}, default=str))
"""

# run in the notebook's kernel: the CPU seconds the kernel process has used so far
_CPU_CODE = "import resource as _r; _u = _r.getrusage(_r.RUSAGE_SELF); print(_u.ru_utime + _u.ru_stime)"
IDLE_S = 8                   # how long the kernel is watched while nobody touches a control


# once JupyterLab has written the kernel's metadata into the model of the notebook `path` (it
# does so on connecting; an equal value changes nothing): whether the notebook is modified, as
# its tab shows it, and the metadata of the model and of the kernel
_CONNECTED_STATE_JS = """async path => {
    const widget = Array.from(window.jupyterapp.shell.widgets('main')).find(w => w.context?.path === path);
    const kernel = widget.sessionContext.session.kernel;
    const [info, spec] = [await kernel.info, await kernel.spec];
    const canonical = value => JSON.stringify(value, (key, v) => v && typeof v === 'object' && !Array.isArray(v)
        ? Object.fromEntries(Object.entries(v).sort()) : v);
    const model = widget.context.model;
    for (let wait = 0; wait < 100; wait++) {
        if (canonical(model.getMetadata('language_info')) === canonical(info.language_info)
                && model.getMetadata('kernelspec')?.display_name === spec.display_name) { break; }
        await new Promise(resolve => setTimeout(resolve, 100));
    }
    const tab = Array.from(document.querySelectorAll('.lm-DockPanel-tabBar .lm-TabBar-tab'))
        .find(t => t.dataset.id === widget.id);
    return {dirty: tab.classList.contains('jp-mod-dirty'), modelDirty: model.dirty,
            kernelspec: model.getMetadata('kernelspec'), language_info: model.getMetadata('language_info'),
            version: info.language_info.version};
}"""


def _changed(stored: dict, shown: dict) -> list[str]:
    """The metadata fields JupyterLab changed: 'kernelspec.display_name', 'language_info.version', ..."""
    return sorted(f"{key}.{field}" for key in ("kernelspec", "language_info")
                  for field in set(stored.get(key, {})) | set(shown.get(key) or {})
                  if stored.get(key, {}).get(field) != (shown.get(key) or {}).get(field))


def _chapter_notebooks() -> list[str]:
    return [p.name for p in chapter_notebooks(NOTEBOOKS)]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on a free loopback port serving copies of the notebooks."""
    reason = lab_h.missing_reason()
    if reason:
        pytest.skip(reason)
    base = tmp_path_factory.mktemp("lab")
    root = base / "root"
    root.mkdir()
    for name in _chapter_notebooks():
        shutil.copy(NOTEBOOKS / name, root / name)
    for name, (cells, _) in DRAG_NOTEBOOKS.items():
        lab_h.write_notebook(root / name, cells)
    lab_h.write_notebook(root / PLOTS_BESIDE_EXPLORER, [*DRAG_NOTEBOOKS["msd_explorer.ipynb"][0], _PLOT_CELL_CODE])
    lab_h.write_notebook(root / KEYS_NOTEBOOK, KEYS_CELLS)
    lab_h.write_notebook(root / PROBE_NOTEBOOK, DEMO_SOURCE)
    lab_h.write_notebook(root / PLANNER_NOTEBOOK, PLANNER_CELLS)
    with lab_h.running_lab(root, base) as url:
        yield url


@pytest.fixture(scope="module")
def page(lab):
    """One JupyterLab page for all notebooks: loading the application once saves seconds per test."""
    with lab_h.launched_chromium() as browser:
        page = lab_h.new_lab_page(browser, lab)
        yield page
        page.close()


@pytest.fixture
def opened(lab, page, tmp_path):
    """Opens a notebook with `opened(name)`; on a failure of the test leaves a screenshot of
    the page (its path is printed); at the end closes every tab and stops the kernels."""
    @contextlib.contextmanager
    def open_and_watch(name):
        try:
            lab_h.open_notebook(page, name)
            yield
        except BaseException:
            shot = tmp_path / f"{name}.png"
            page.screenshot(path=str(shot), full_page=True)
            print(f"screenshot of the failing page: {shot}")
            raise
    yield open_and_watch
    lab_h.close_all(page)
    lab_h.shut_down_kernels(lab)


def _run_without_errors(page, name: str) -> list[str]:
    """Run all cells, assert none shows an error; return the input prompts."""
    lab_h.run_all(page)
    prompts = lab_h.wait_until_done(page, RUN_TIMEOUT_S)
    errors = lab_h.error_outputs(page)
    assert not errors, f"{name}: an error was reported:\n" + "\n----\n".join(errors)
    return prompts


@pytest.mark.parametrize("name", _chapter_notebooks())
def test_notebook_runs_in_jupyterlab_and_its_explorer_answers(name, page, opened, capsys):
    t0 = time.monotonic()
    with opened(name):
        t_open = time.monotonic() - t0
        _assert_opened_unmodified(page, name)
        prompts = _run_without_errors(page, name)
        t_run = time.monotonic() - t0 - t_open
        assert len(prompts) == _count_code_cells(name), (
            f"{name}: {len(prompts)} code cells rendered, the notebook has {_count_code_cells(name)}")
        # from the notebook model, so cells whose input is collapsed count too
        counts = page.evaluate("() => window.jupyterapp.shell.currentWidget.content.widgets"
                               ".filter(c => c.model.type === 'code').map(c => c.model.executionCount)")
        not_run = [i for i, count in enumerate(counts) if count is None]
        assert not not_run, f"{name}: code cells {not_run} did not run (execution counts {counts})"
        images = page.evaluate(_EXPLORER_IMAGES_JS)
        assert images, f"{name}: no explorer figure (a widget with an image) was rendered"
        _check_accessibility(page, name)
        idle_cpu = _kernel_cpu_while_idle(page)
        assert idle_cpu < 0.5, (f"{name}: the kernel used {idle_cpu:.2f} CPU-seconds in {IDLE_S} s while "
                                "nobody touched a control (it should do no work)")
        t1 = time.monotonic()
        alt_before = _first_explorer(page, "img", "alt")
        _move_first_slider(page)
        _wait_for_new_image(page, images[0], SLIDER_TIMEOUT_S)
        t_slider = time.monotonic() - t1
        # the text alternative follows the slider, and the live region announces it once settled
        alt = _first_explorer(page, "img", "alt")
        value = _readout_value(page)
        assert alt != alt_before and f"= {value:g}" in alt, (alt_before, alt, value)
        page.wait_for_timeout(1500)
        assert _first_explorer(page, ".ck-live", "textContent") == alt
        errors = lab_h.error_outputs(page)
        assert not errors, f"{name}: an error was reported after moving a slider:\n" + "\n----\n".join(errors)
        with capsys.disabled():
            print(f"\n[browser] {name}: open {t_open:.1f} s, run all {t_run:.1f} s "
                  f"({len(prompts)} code cells), kernel CPU while idle {idle_cpu:.2f} s in {IDLE_S} s, "
                  f"slider -> new figure {t_slider:.1f} s")


def _assert_opened_unmodified(page, name: str) -> None:
    """The chapter, opened untouched, is not modified once its kernel is connected: no unsaved mark
    on its tab, so closing it would not ask to save. JupyterLab writes the kernel's metadata into
    the notebook on connecting, so this holds when the notebooks store the metadata of this kernel
    (coursekit/tools/kernel_metadata.py). With a kernel of another Python version it cannot hold
    (the version is part of that metadata, jupyter/notebook#2123): then the version must be all
    JupyterLab changed."""
    stored = json.loads((NOTEBOOKS / name).read_text(encoding="utf-8"))["metadata"]
    state = page.evaluate(_CONNECTED_STATE_JS, name)
    changed = _changed(stored, state)
    stored_version = stored.get("language_info", {}).get("version")
    if stored_version is not None and state["version"] != stored_version:
        assert changed == ["language_info.version"], (
            f"{name}: opening it changed {changed}; with a kernel of another Python only the version may differ")
        return
    assert not changed, f"{name}: JupyterLab changed the stored metadata {changed} on opening it"
    assert not state["dirty"] and not state["modelDirty"], f"{name}: marked modified though untouched"


def _first_explorer(page, selector: str, prop: str) -> str:
    """A property of the first element `selector` matches in the first explorer."""
    return page.locator(f"{lab_h.ACTIVE} .ck-explorer").first.locator(selector).first.evaluate(
        f"e => e.{prop}")


def _check_accessibility(page, name: str) -> None:
    """axe-core finds no WCAG 2.1 AA violation inside the explorers; each figure has a text
    alternative that names its settings, and each slider and dropdown an accessible name."""
    violations = lab_h.axe_violations(page, f"{lab_h.ACTIVE} .ck-explorer", lab_h.axe_source())
    assert not violations, f"{name}: accessibility violations in the explorers:\n" + "\n".join(violations)
    alts = page.evaluate(f"() => Array.from(document.querySelectorAll('{lab_h.ACTIVE} .ck-explorer img'))"
                         ".map(i => i.alt)")
    assert alts and all("Settings:" in alt for alt in alts), alts


def _kernel_cpu_while_idle(page) -> float:
    """CPU seconds the kernel spends during IDLE_S seconds in which nobody touches anything
    (after the figures have settled), less the cost of asking it."""
    lab_h.install_probe(page)
    lab_h.wait_until_quiet(page, quiet_ms=1000, timeout=SLIDER_TIMEOUT_S)
    before = float(lab_h.execute_in_kernel(page, _CPU_CODE))
    asking = float(lab_h.execute_in_kernel(page, _CPU_CODE)) - before
    page.wait_for_timeout(IDLE_S * 1000)
    return float(lab_h.execute_in_kernel(page, _CPU_CODE)) - before - 2 * asking


@pytest.mark.parametrize("name", list(DRAG_NOTEBOOKS))
def test_explorer_follows_a_drag_and_ends_on_the_figure_of_the_final_value(name, page, opened):
    _, shown = DRAG_NOTEBOOKS[name]
    with opened(name):
        _check_drag(page, name, shown)


def _check_drag(page, name: str, shown: str) -> None:
    """Drag the first slider; check the figure followed, ended right, and no error."""
    _run_without_errors(page, name)
    assert page.evaluate(_EXPLORER_IMAGES_JS), f"{name}: no explorer figure was rendered"
    start_value = _readout_value(page)
    lab_h.install_probe(page)
    lab_h.drag(page, lab_h.first_slider(page), seconds=3.0, trips=1.5)
    state = lab_h.wait_until_quiet(page, quiet_ms=1000, timeout=SLIDER_TIMEOUT_S)

    down = min(i["t"] for i in state["inputs"] if i["type"] == "mousedown")
    up = max(i["t"] for i in state["inputs"] if i["type"] == "mouseup")
    values = {r["text"] for r in state["readouts"] if down <= r["t"] <= up}
    during = [p for p in state["paints"] if down < p["t"] <= up]
    assert len(values) >= 5, f"{name}: the drag moved the slider through only {sorted(values)}"
    assert len(during) >= 2, (
        f"{name}: while the slider went through {len(values)} values, the figure changed "
        f"{len(during)} time(s) before the mouse was released (at least 2 expected: the figure "
        "should follow the slider, not wait for the release)")

    final_value = _readout_value(page)
    reference = json.loads(lab_h.execute_in_kernel(page, _REFERENCE_CODE.format(shown=shown)))
    kernel_value = list(reference["params"].values())[0]
    assert final_value != start_value, f"{name}: the drag ended where it started ({final_value})"
    assert final_value == pytest.approx(kernel_value, rel=1e-3, abs=1e-9), (
        f"{name}: the slider shows {final_value}, the kernel has {kernel_value}")
    shown_png = base64.b64decode(page.evaluate(_SHOWN_PNG_JS))
    expected_png = base64.b64decode(reference["png"])
    shown_px, expected_px = _pixels(shown_png), _pixels(expected_png)
    assert shown_px.shape == expected_px.shape, (
        f"{name}: the figure shown after the drag is {shown_px.shape[1::-1]} pixels, the one for "
        f"the final parameters {reference['params']} is {expected_px.shape[1::-1]}")
    differ = np.count_nonzero(np.any(shown_px != expected_px, axis=-1))
    assert differ == 0, (
        f"{name}: the figure shown after the drag is not the one for the final parameters "
        f"{reference['params']} ({differ} pixels differ)")
    errors = lab_h.error_outputs(page)
    assert not errors, f"{name}: an error was reported during the drag:\n" + "\n----\n".join(errors)


def test_the_planner_s_time_axis_ends_with_its_data_after_a_long_drag_and_key_steps(page, opened):
    """Issue 32: after a drag of T to 8.6 s the time axis ran to ~23 s with data to 17.6 s, and
    key steps kept it there. After a drag to the far end and after each key step, the figure's
    limits are those of a fresh explorer for the same T, its time axis [0, time_shown(T)]."""
    with opened(PLANNER_NOTEBOOK):
        _run_without_errors(page, PLANNER_NOTEBOOK)
        slider = lab_h.first_slider(page)
        lab_h.install_probe(page)
        lab_h.drag(page, slider, seconds=2.0, trips=0.5)          # out to the far end, released there
        for key in (None, "ArrowLeft", "ArrowLeft"):
            if key:
                slider.locator(".noUi-handle").first.focus()
                page.keyboard.press(key)
            lab_h.wait_until_quiet(page, quiet_ms=1500, timeout=SLIDER_TIMEOUT_S)
            seen = json.loads(lab_h.execute_in_kernel(page, _PLANNER_LIMITS_CODE))
            assert seen["T"] > 6.0, seen["T"]                      # a long drag
            assert seen["end"] == pytest.approx(ch2.time_shown(seen["T"]))
            assert seen["shown"][1][0] == pytest.approx([0.0, seen["end"]]), (key, seen)
            assert seen["shown"] == seen["fresh"], (key, seen)


# a notebook no test runs: a run one is saved when its tab closes (`lab_harness.close_all`), and
# reopened, its widget outputs show "model not found" as soon as the widget manager gives up on
# them, which no kernel error is
PROBE_NOTEBOOK = "control_probe.ipynb"

# what JupyterLab's widget manager sends a kernel that has not imported ipywidgets when it
# looks for existing widgets: a comm to the control target, then a request over that comm
_CONTROL_PROBE_JS = """async () => {
    const kernel = window.jupyterapp.shell.currentWidget.sessionContext.session.kernel;
    const comm = kernel.createComm('jupyter.widget.control');
    const opened = comm.open({}).done;
    const sent = comm.send({method: 'request_states'}).done;
    await Promise.all([opened, sent]);
}"""


def test_kernel_errors_are_reported_but_not_the_widget_managers_control_probe(page, opened):
    with opened(PROBE_NOTEBOOK):
        page.evaluate(_CONTROL_PROBE_JS)
        printed = lab_h.execute_in_kernel(page, "import sys; print('stderr from the kernel', file=sys.stderr)")
        page.wait_for_timeout(500)
        errors = lab_h.error_outputs(page)
    assert printed.strip() == "stderr from the kernel"
    assert errors == ["stderr from the kernel"], errors


def _readout_value(page) -> float:
    """The value the first slider's readout shows (its minus sign may be U+2212)."""
    text = lab_h.first_slider(page).locator(".widget-readout").inner_text()
    return float(text.strip().replace("\u2212", "-"))


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))


def _move_first_slider(page) -> None:
    """Focus the first slider handle of the first explorer and press the right arrow."""
    handle = lab_h.first_slider(page).locator(".noUi-handle").first
    handle.focus()
    for _ in range(3):
        handle.press("ArrowRight")
        page.wait_for_timeout(100)
    # a slider with continuous_update=False sends the value when the handle loses focus
    page.keyboard.press("Tab")


def _wait_for_new_image(page, before: str, timeout: float) -> str:
    """Wait until the explorer's image differs from `before` and then stays the same for 1 s."""
    deadline = time.monotonic() + timeout
    last, stable_since = before, None
    while time.monotonic() < deadline:
        src = page.evaluate(_EXPLORER_IMAGES_JS)[0]
        if src != last:
            last, stable_since = src, time.monotonic()
        elif last != before and time.monotonic() - stable_since >= 1.0:
            return last
        page.wait_for_timeout(200)
    pytest.fail("the explorer's figure did not change after moving its slider "
                f"(waited {timeout:.0f} s)")


def _count_code_cells(name: str) -> int:
    if name == "demo_explorer.ipynb":
        return len(DEMO_SOURCE)
    cells = json.loads((NOTEBOOKS / name).read_text(encoding="utf-8"))["cells"]
    return sum(cell["cell_type"] == "code" for cell in cells)


# run in the notebook's kernel: note every drawing of a matplotlib figure (an explorer's frame,
# a full Agg draw, a PNG written) with the thread it runs on, and every time two of them run at
# once on different threads (matplotlib's figures and its font cache are not thread-safe)
_DRAW_WATCH_CODE = """\
import functools as _functools
import threading as _threading
from matplotlib.backends.backend_agg import FigureCanvasAgg as _Agg
from coursekit.explorers import _frames as _ck_frames_module
_ck_watch = {"active": [], "overlaps": [], "threads": set()}
_ck_watch_lock = _threading.Lock()
def _ck_watched(original):
    @_functools.wraps(original)
    def watched(*args, **kwargs):
        me = _threading.current_thread().name
        with _ck_watch_lock:
            others = sorted({name for name in _ck_watch["active"] if name != me})
            if others:
                _ck_watch["overlaps"].append(f"{original.__qualname__} on {me} while {others} drew")
            _ck_watch["active"].append(me)
            _ck_watch["threads"].add(me)
        try:
            return original(*args, **kwargs)
        finally:
            with _ck_watch_lock:
                _ck_watch["active"].remove(me)
    return watched
_Agg.draw = _ck_watched(_Agg.draw)
_Agg.print_png = _ck_watched(_Agg.print_png)
_ck_frames_module.FrameRenderer.frame = _ck_watched(_ck_frames_module.FrameRenderer.frame)
"""

# a cell a student runs while the explorer is on screen: it draws figures of its own
PLOTS_BESIDE_EXPLORER = "plots_beside_explorer.ipynb"
_PLOT_CELL_CODE = """\
import io as _io
import matplotlib.pyplot as _plt
for _i in range(15):
    _fig, _ax = _plt.subplots()
    _ax.plot(range(50), [(_i * _k) % 7 for _k in range(50)])
    _ax.set(title=f"figure {_i}", xlabel="k", ylabel="value")
    _fig.savefig(_io.BytesIO(), format="png")
    _plt.close(_fig)
print("plotted")
"""


def test_explorer_drawing_never_overlaps_other_kernel_work(page, opened):
    """A dropdown changed while a cell draws figures of its own: matplotlib is not thread-safe
    (figures, and the font cache that every figure shares), so those drawings must never
    overlap, whichever thread or kernel subshell each widget message is handled on (the
    explorer handles every message on the kernel's main thread); and once settled, the figure
    shown is the kernel's figure for the settings shown."""
    name, (_, shown) = PLOTS_BESIDE_EXPLORER, DRAG_NOTEBOOKS["msd_explorer.ipynb"]
    with opened(name):
        _run_without_errors(page, name)
        lab_h.execute_in_kernel(page, _DRAW_WATCH_CODE)
        choice = page.locator(f"{lab_h.ACTIVE} .ck-explorer .widget-dropdown select").first
        for option in ["initial", "step", "initial", "step", "initial"]:
            choice.select_option(option)
            page.wait_for_timeout(400)
        # the plotting cell again, right after the last change of the dropdown
        page.evaluate("() => { const panel = window.jupyterapp.shell.currentWidget;"
                      " panel.content.activeCellIndex = panel.content.widgets.length - 1;"
                      " return window.jupyterapp.commands.execute('notebook:run-cell'); }")
        prompts = lab_h.wait_until_done(page, RUN_TIMEOUT_S)
        assert prompts[-1] == f"[{len(prompts) + 1}]:", prompts     # the third cell ran again
        lab_h.install_probe(page)
        lab_h.wait_until_quiet(page, quiet_ms=1500, timeout=SLIDER_TIMEOUT_S)
        watch = json.loads(lab_h.execute_in_kernel(
            page, "import json; print(json.dumps({k: sorted(v) if isinstance(v, set) else v"
                  " for k, v in _ck_watch.items()}))"))
        assert not watch["overlaps"], (
            f"{name}: figures were drawn at the same time on different threads "
            f"{watch['threads']} ({len(watch['overlaps'])} times), e.g. {watch['overlaps'][:3]}")
        reference = json.loads(lab_h.execute_in_kernel(page, _REFERENCE_CODE.format(shown=shown)))
        assert reference["params"]["experiment"] == "initial"
        shown_px = _pixels(base64.b64decode(page.evaluate(_SHOWN_PNG_JS)))
        expected_px = _pixels(base64.b64decode(reference["png"]))
        assert shown_px.shape == expected_px.shape
        differ = np.count_nonzero(np.any(shown_px != expected_px, axis=-1))
        assert differ == 0, f"{name}: the figure shown is not the one for {reference['params']} ({differ} pixels differ)"
        errors = lab_h.error_outputs(page)
        assert not errors, "\n----\n".join(errors)


# --- keys on an explorer's controls, in Notebook 7 ---------------------------------------------

KEYS_NOTEBOOK = "keys_explorer.ipynb"
# a section heading above the explorer (ArrowLeft collapses it in command mode) and a cell below
# it (ArrowDown selects it)
KEYS_CELLS = [nbformat.v4.new_markdown_cell("# A section"), "\n".join(DEMO_SOURCE),
              nbformat.v4.new_markdown_cell("# The next section"), "1 + 1"]

_CELLS_JS = """() => {
    const cells = Array.from(document.querySelectorAll('.jp-Notebook .jp-Cell'));
    return {active: cells.findIndex(c => c.classList.contains('jp-mod-active')),
            shown: cells.filter(c => c.offsetParent !== null).length,
            focused: document.activeElement?.getAttribute('role') || ''};
}"""


#: whether a cell of the notebook was queued or run (its prompt shows * or a number)
_RAN_JS = ("() => [...document.querySelectorAll('.jp-Notebook .jp-InputPrompt')]"
           ".some(p => /\\[[*\\d]/.test(p.textContent))")


def test_keys_on_a_focused_slider_step_it_and_never_reach_notebook_7_s_shortcuts(lab, page):
    """Arrow keys, Home and End on a focused explorer slider move the slider in Notebook 7, where
    in command mode they are shortcuts (the next cell, collapse or expand the section)."""
    pytest.importorskip("notebook", minversion="7", reason="Notebook 7 is not installed")
    tab = page.context.browser.new_page(viewport=lab_h.VIEWPORT)
    try:
        tab.goto(f"{lab}/notebooks/{KEYS_NOTEBOOK}?token={lab_h.TOKEN}")
        tab.wait_for_selector(".jp-Notebook .jp-Cell", timeout=90_000)
        tab.wait_for_function("() => document.querySelector('.jp-Notebook-ExecutionIndicator')?.dataset.status"
                              " === 'idle'", timeout=90_000)
        # a dialog Notebook 7 may show while it connects the kernel goes by itself
        tab.wait_for_function("() => !document.querySelector('.jp-Dialog')", timeout=60_000)
        handle = tab.locator(".ck-explorer .noUi-handle").first
        for _ in range(6):                     # Run > Run All Cells; again when clicked too early
            tab.locator(".lm-MenuBar-itemLabel", has_text="Run").first.click()
            tab.locator(".lm-Menu-item:visible", has_text="Run All Cells").first.click()
            try:                               # a cell queued or run: the click took
                tab.wait_for_function(_RAN_JS, timeout=10_000)
                break
            except Exception:  # playwright's TimeoutError: nothing ran
                tab.keyboard.press("Escape")
        handle.wait_for(timeout=90_000)
        readout = tab.locator(".ck-explorer .widget-slider .widget-readout").first
        tab.wait_for_timeout(1000)
        handle.focus()
        before = tab.evaluate(_CELLS_JS)
        assert before["focused"] == "slider", before
        seen = []
        for key, value in [("ArrowRight", 1.1), ("ArrowUp", 1.2), ("ArrowLeft", 1.1), ("ArrowDown", 1.0),
                           ("End", 3.0), ("Home", 0.1)]:
            handle.press(key)
            tab.wait_for_timeout(300)
            seen.append((key, float(readout.inner_text().strip().replace("\u2212", "-")), tab.evaluate(_CELLS_JS)))
            assert seen[-1][1:] == (pytest.approx(value), before), seen
    finally:
        tab.close()
        lab_h.shut_down_kernels(lab)
