"""The browser benchmark: what a student feels when moving an explorer's slider.

JupyterLab on a loopback port, headless Chromium at 1600x1000 (the harness of the browser
test, ``tests/lab_harness.py``). Each explorer runs alone in a small generated notebook
(its import and one call of its factory); the floor is a trivial ``interact`` whose function
plots one line and calls ``plt.show()`` (``%matplotlib inline``, ipywidgets' default
``continuous_update=True``), the fastest a slider-driven figure gets in the same JupyterLab. Measured in the page, on the page's clock:

* step: focus the first slider's handle, press an arrow key, time from the key event to the
  paint of the last new figure (the first animation frame after the ``<img>``'s ``load``),
  once the figure has been quiet for 0.4 s. The key steps towards the far end of the range
  so the values are new ones until the end is reached;
* drag: mouse down on that handle, a move every 16 ms, to 90 % of the way to the far end of
  the track and back, 2.5 trips in 3 s; new figures painted between mouse down and mouse up
  per second, next to the slider values the hand passed per second. Twice: first right after
  the Run All, before anything else touched the explorer (the "first drag"), and again after
  the steps;
* lag after release: from mouse up to the paint of the last figure, once the figure has not
  changed for 1 s (0 when nothing changed after the release); it includes the frame that fits
  the limits 0.3 s after the slider rests, when that frame differs;
* CPU during that drag: seconds of CPU per second of the drag used by Chromium's processes and
  by the kernel (of the machine's cores; the server and Playwright's driver use the rest).

The floor runs before the first explorer and after every third measurement, so drift in the
machine's speed affects both; its row pools those runs. Every target is relative to it (issue
34): a step at most 1.0 times the floor's, a first drag at least 1.0 times its figures per
second (1.3 times for a light explorer).

Busy machine (``busy=True``): the same with `BUSY_PROCESSES` CPU-bound processes (a Python loop
each) running beside the browser and the kernel from before the floor's first run to the end, as
when a class shares one server: each explorer's drags must paint at least as often as the
floor's in the same run. The table says the machine's load average at the end.
"""

from __future__ import annotations

import contextlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import lab_harness as lab_h  # noqa: E402  (lives with the browser test)

__all__ = ["FLOOR_SOURCE", "LIGHT_MS", "BUSY_PROCESSES", "cpu_bound", "require_browser", "run_browser"]

FLOOR_SOURCE = [
    "%matplotlib inline\nimport numpy as np\nimport matplotlib.pyplot as plt\n"
    "from ipywidgets import interact, FloatSlider\nt = np.linspace(0, 10, 500)",
    "def plot(a):\n    plt.plot(t, np.sin(a * t))\n    plt.show()\n\n"
    "interact(plot, a=FloatSlider(value=1.0, min=0.1, max=5.0, step=0.1));",
]
FLOOR_SCOPE = ".jp-NotebookPanel:not(.lm-mod-hidden) .jp-CodeCell:has(.widget-slider) .jp-Cell-outputArea"
LIGHT_MS = 25.0      # kernel compute + redraw at most this: "light", first drag >= 1.3 times the floor
BUSY_PROCESSES = 2   # CPU-bound processes beside the browser and the kernel in the busy case
DRAG_S = 3.0
RUN_TIMEOUT_S = 120
STEP_QUIET_MS = 400


def _paint_count(page) -> int:
    return page.evaluate("() => window.__ckProbe.paints.length")


def measure_steps(page, slider, count: int) -> list[float]:
    """Milliseconds from each of `count` arrow-key presses to its last new figure painted."""
    handle = slider.locator(".noUi-handle").first
    handle.focus()
    aria = lambda: handle.evaluate("h => ['now', 'min', 'max'].map(k => h.getAttribute('aria-value' + k))")
    now, low, high = map(float, aria())
    key = "ArrowRight" if now - low <= high - now else "ArrowLeft"
    latencies = []
    for _ in range(count):
        now, low, high = aria()     # rounded alike, so equal at the end of the range
        key = "ArrowLeft" if now == high else "ArrowRight" if now == low else key
        before = _paint_count(page)
        page.keyboard.press(key)
        try:
            page.wait_for_function(f"() => window.__ckProbe.paints.length > {before}", timeout=30_000)
        except Exception as error:   # playwright's TimeoutError
            raise lab_h.HarnessError(f"no new figure within 30 s of pressing {key}") from error
        state = lab_h.wait_until_quiet(page, quiet_ms=STEP_QUIET_MS, timeout=60)
        pressed = max(i["t"] for i in state["inputs"] if i["type"] == "keydown")
        latencies.append(state["paints"][-1]["t"] - pressed)
    return latencies


def _cpu_seconds() -> dict:
    """CPU seconds used so far by the processes this benchmark started: Chromium's, and the
    kernel's (the rest: the server, Playwright's driver)."""
    import psutil
    used = {"chromium": 0.0, "kernel": 0.0}
    for process in psutil.Process().children(recursive=True):
        try:
            with process.oneshot():
                kind = ("chromium" if "chrom" in process.name() else
                        "kernel" if "ipykernel" in " ".join(process.cmdline()) else None)
                times = process.cpu_times()
        except psutil.Error:          # ended meanwhile
            continue
        if kind:
            used[kind] += times.user + times.system
    return used


def measure_drag(page, slider) -> dict:
    """Figures painted per second during a 3 s drag, slider values per second, lag after release,
    and the CPU Chromium and the kernel used per second of the drag."""
    before, start = _cpu_seconds(), time.perf_counter()
    lab_h.drag(page, slider, seconds=DRAG_S, trips=2.5)
    used, wall = _cpu_seconds(), time.perf_counter() - start
    state = lab_h.wait_until_quiet(page, quiet_ms=1000, timeout=90)
    down = max(i["t"] for i in state["inputs"] if i["type"] == "mousedown")
    up = max(i["t"] for i in state["inputs"] if i["type"] == "mouseup")
    seconds = (up - down) / 1e3
    texts = [r["text"] for r in state["readouts"] if down <= r["t"] <= up]
    changes = sum(a != b for a, b in zip(texts, texts[1:])) + bool(texts)
    paints = [p["t"] for p in state["paints"] if p["t"] > down]
    return {"updates": sum(t <= up for t in paints) / seconds, "values": changes / seconds,
            "lag": max(0.0, paints[-1] - up) if paints else float("nan"),
            **{f"cpu_{kind}": (used[kind] - before[kind]) / wall for kind in used}}


def measure_notebook(page, url: str, name: str, scope: str, steps: int, shots: Path | None) -> dict:
    """Open, run, measure a drag, steps and a drag on the first slider of `scope`; close and stop
    the kernel."""
    try:
        lab_h.open_notebook(page, name)
        lab_h.run_all(page)
        lab_h.wait_until_done(page, RUN_TIMEOUT_S)
        errors = lab_h.error_outputs(page)
        if errors:
            raise lab_h.HarnessError(f"{name} reported an error:\n" + "\n".join(errors))
        page.locator(f"{scope} img").first.wait_for(timeout=30_000)
        slider = lab_h.first_slider(page, scope)
        lab_h.install_probe(page)
        first = measure_drag(page, slider)
        result = {"steps": measure_steps(page, slider, steps), "first": first["updates"]}
        result.update(measure_drag(page, slider))
        if shots is not None:
            page.screenshot(path=str(shots / f"{Path(name).stem}.png"))
        return result
    finally:
        lab_h.close_all(page)
        lab_h.shut_down_kernels(url)


def _schedule(explorers: list[str]) -> list[str]:
    """The floor first and after every third explorer (and last)."""
    order = ["floor"]
    for i, label in enumerate(explorers, 1):
        order.append(label)
        if i % 3 == 0 or i == len(explorers):
            order.append("floor")
    return order


def _notebook(label: str) -> str:
    return f"{label}.ipynb"


def _write_notebooks(root: Path, explorers: list[str]) -> None:
    lab_h.write_notebook(root / "floor.ipynb", FLOOR_SOURCE)
    for label in explorers:
        module, factory = label.split(".")
        lab_h.write_notebook(root / _notebook(label), [
            f"%matplotlib inline\nfrom coursekit.explorers.{module} import {factory}", f"{factory}()"])


@contextlib.contextmanager
def cpu_bound(count: int = BUSY_PROCESSES):
    """`count` processes that each keep a core busy while the block runs (ended after it)."""
    processes = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]
    try:
        yield
    finally:
        for process in processes:
            process.kill()
            process.wait()


def require_browser() -> None:
    """Stop with the fix when Playwright or Chromium is missing."""
    reason = lab_h.missing_reason()
    if reason:
        raise SystemExit(f"browser benchmark: {reason}")


def run_browser(explorers: list[str], kernel_ms: dict, *, steps: int = 15,
                shots: Path | None = None, log=print, busy: bool = False) -> list[str]:
    """Measure every explorer (labels ``chN.factory``) and the floor; the markdown table rows.
    `kernel_ms` holds each explorer's compute + redraw time (ms), which makes it light or not;
    `busy`: beside `BUSY_PROCESSES` CPU-bound processes (see the module's doc)."""
    require_browser()
    from playwright.sync_api import TimeoutError as PlaywrightTimeout
    results: dict[str, list[dict]] = {}
    with tempfile.TemporaryDirectory(prefix="coursekit-browser-bench-") as tmp, \
            (cpu_bound() if busy else contextlib.nullcontext()):
        base = Path(tmp)
        (base / "root").mkdir()
        _write_notebooks(base / "root", explorers)
        with lab_h.running_lab(base / "root", base) as url, lab_h.launched_chromium() as browser:
            page = lab_h.new_lab_page(browser, url)
            for label in _schedule(explorers):
                start = time.monotonic()
                scope = FLOOR_SCOPE if label == "floor" else lab_h.EXPLORER
                try:
                    result = measure_notebook(page, url, _notebook(label), scope, steps, shots)
                except (lab_h.HarnessError, PlaywrightTimeout) as error:
                    raise SystemExit(f"browser benchmark, {label}: {error}") from error
                results.setdefault(label, []).append(result)
                log(f"  {label}: {time.monotonic() - start:.0f} s")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return _table(explorers, kernel_ms, results, busy=busy, load=load)


def _table(explorers: list[str], kernel_ms: dict, results: dict, *, busy: bool, load: float) -> list[str]:
    """The rows: the floor's (its runs pooled), then each explorer's, with its ratios to the floor
    and whether it meets the targets (see the module's doc)."""
    runs = results["floor"]
    floor_steps = [t for run in runs for t in run["steps"]]
    floor = {"step": statistics.median(floor_steps), "first": statistics.median(r["first"] for r in runs),
             "updates": statistics.median(r["updates"] for r in runs)}
    drag_target = ("drag / floor, first and after the steps (target >= 1.0: beside "
                   f"{BUSY_PROCESSES} CPU-bound processes)" if busy else
                   "first drag / floor (target >= 1.0, light >= 1.3)")
    rows = [f"Machine load average (1 min) at the end: {load:.1f} on {os.cpu_count()} cores"
            + (f", {BUSY_PROCESSES} of it the CPU-bound processes." if busy else "."), "",
            "| explorer | kernel compute + redraw | step median | step max | step / floor (target <= 1.0) "
            "| updates/s, first drag | updates/s, drag after the steps | " + drag_target + " | meets the targets "
            "| slider values/s during that drag | lag after release | CPU during that drag: Chromium, kernel (cores) |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    rows.append(f"| floor: `interact`, one line, continuous_update=True ({len(runs)} runs) | - "
                f"| {floor['step']:.0f} ms | {max(floor_steps):.0f} ms | 1.00 | {floor['first']:.1f} "
                f"| {floor['updates']:.1f} | 1.00 | - | {statistics.median(r['values'] for r in runs):.0f} "
                f"| {statistics.median(r['lag'] for r in runs):.0f} ms "
                f"| {statistics.median(r['cpu_chromium'] for r in runs):.2f}, "
                f"{statistics.median(r['cpu_kernel'] for r in runs):.2f} |")
    for label in explorers:
        run, ms = results[label][0], kernel_ms[label]
        light = ms <= LIGHT_MS
        step = statistics.median(run["steps"]) / floor["step"]
        first, after = run["first"] / floor["first"], run["updates"] / floor["updates"]
        if busy:
            ratio, met = f"{first:.2f}, {after:.2f}", step <= 1.0 and min(first, after) >= 1.0
        else:
            ratio, met = f"{first:.2f}", step <= 1.0 and first >= (1.3 if light else 1.0)
        rows.append(f"| {label}{' (light)' if light else ''} | {ms:.0f} ms | {statistics.median(run['steps']):.0f} ms "
                    f"| {max(run['steps']):.0f} ms | {step:.2f} | {run['first']:.1f} | {run['updates']:.1f} "
                    f"| {ratio} | {'yes' if met else '**no**'} | {run['values']:.0f} | {run['lag']:.0f} ms "
                    f"| {run['cpu_chromium']:.2f}, {run['cpu_kernel']:.2f} |")
    return rows
