"""A real-browser test: JupyterLab + headless Chromium driven by Playwright.

For each chapter notebook (and a small demo notebook that tests the harness
itself): open it in JupyterLab, Run > Run All Cells, wait until the kernel is
done, assert that no cell shows a traceback, then move the first slider of an
explorer with the keyboard and assert that the explorer's figure changes.

Needs Playwright for Python (``pip install playwright``, part of the dev extra)
and the system Chromium (Debian package ``chromium``; no browser download).
Skipped with the reason when either is missing. Run only these tests with
``python -m pytest -m browser``; leave them out with ``-m "not browser"``.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

NOTEBOOKS = Path(__file__).parents[1] / "notebooks"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]
TOKEN = "coursekit-browser-test"
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
    "Explorer(title='Demo', controls={'a': slider(1.0, 0.1, 3.0, 0.1, 'a')},\n"
    "         compute=compute, draw=draw, update=update)",
]


def _chromium() -> str | None:
    for candidate in ("/usr/bin/chromium", shutil.which("chromium"), shutil.which("chromium-browser")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    return None


def _skip_reason() -> str | None:
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright for Python is not installed (python -m pip install playwright)"
    if _chromium() is None:
        return "Chromium is not installed (Debian/Ubuntu: apt-get install -y chromium)"
    return None


def _chapter_notebooks() -> list[str]:
    return sorted(p.name for p in NOTEBOOKS.glob("0*.ipynb"))


def _write_demo(path: Path) -> None:
    import nbformat
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(src) for src in DEMO_SOURCE]
    nbformat.write(nb, path)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _write_settings(settings: Path) -> None:
    """Render every cell (no windowing) and keep news/update pop-ups away."""
    overrides = {
        "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
        "@jupyterlab/apputils-extension/notification.jupyterlab-settings":
            {"fetchNews": "false", "checkForUpdates": False},
    }
    for rel, content in overrides.items():
        path = settings / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(content))


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on a free loopback port serving copies of the notebooks."""
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    base = tmp_path_factory.mktemp("lab")
    root, settings = base / "root", base / "settings"
    root.mkdir()
    for name in _chapter_notebooks():
        shutil.copy(NOTEBOOKS / name, root / name)
    _write_demo(root / "demo_explorer.ipynb")
    _write_settings(settings)
    port = _free_port()
    cmd = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ServerApp.open_browser=False",
           "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}", "--ServerApp.port_retries=0",
           f"--ServerApp.root_dir={root}", f"--IdentityProvider.token={TOKEN}",
           f"--LabApp.user_settings_dir={settings}", f"--LabApp.workspaces_dir={base / 'workspaces'}",
           "--LabApp.expose_app_in_browser=True"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-root")
    env = dict(os.environ, JUPYTER_CONFIG_DIR=str(base / "config"), JUPYTER_RUNTIME_DIR=str(base / "runtime"),
               MPLBACKEND="module://matplotlib_inline.backend_inline")
    log = open(base / "server.log", "w")
    proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=root)
    url = f"http://127.0.0.1:{port}"
    try:
        _wait_for_server(url, proc, base / "server.log")
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()


def _wait_for_server(url: str, proc: subprocess.Popen, log: Path, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"JupyterLab exited with code {proc.returncode}:\n{log.read_text()[-3000:]}")
        try:
            with urllib.request.urlopen(f"{url}/api/status?token={TOKEN}", timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            time.sleep(0.5)
    pytest.fail(f"JupyterLab did not answer within {timeout:.0f} s:\n{log.read_text()[-3000:]}")


@pytest.fixture(scope="module")
def browser(lab):
    from playwright.sync_api import sync_playwright
    with sync_playwright() as pw:
        chromium = pw.chromium.launch(executable_path=_chromium(), args=CHROMIUM_ARGS, headless=True)
        try:
            yield chromium
        finally:
            chromium.close()


# JavaScript run in the page ------------------------------------------------------------

_PROMPTS_JS = """() => Array.from(document.querySelectorAll(
    '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-CodeCell .jp-InputPrompt')).map(p => p.textContent.trim())"""

_ERRORS_JS = """() => Array.from(document.querySelectorAll(
    '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-OutputArea-output'))
    .filter(o => /Traceback|Error displaying widget/.test(o.textContent))
    .map(o => o.textContent.slice(0, 1500))"""

_KERNEL_IDLE_JS = """() => document.querySelector(
    '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-Notebook-ExecutionIndicator')?.dataset.status === 'idle'"""

# from the notebook model, so cells whose input is collapsed (the exercise solutions) count too
_EXECUTION_COUNTS_JS = """() => window.jupyterapp.shell.currentWidget.content.widgets
    .filter(c => c.model.type === 'code').map(c => c.model.executionCount)"""

_EXPLORER_IMAGES_JS = """() => Array.from(document.querySelectorAll(
    '.jp-NotebookPanel:not(.lm-mod-hidden) .widget-vbox img')).map(i => i.src)"""


def _run_all(page) -> None:
    """Run > Run All Cells; retried when the kernel did not pick it up (clicked too early)."""
    for _ in range(3):
        page.locator(".lm-MenuBar-itemLabel", has_text="Run").first.click()
        page.locator(".lm-Menu-item:visible", has_text="Run All Cells").first.click()
        try:
            page.wait_for_function(f"() => ({_PROMPTS_JS})().some(p => p.includes('*') || /\\d/.test(p))",
                                   timeout=20_000)
            return
        except Exception:  # playwright's TimeoutError: nothing was queued yet
            page.keyboard.press("Escape")
    pytest.fail("Run > Run All Cells did not start the kernel")


def _executed(prompt: str) -> bool:
    """True for an input prompt such as '[12]:' (the cell ran), False for '[ ]:' or '[*]:'."""
    return re.fullmatch(r"\[\d+\]:?", prompt) is not None


def _wait_until_done(page, timeout: float) -> list[str]:
    """Wait until the kernel has run every queued cell and is idle; return the input prompts."""
    deadline = time.monotonic() + timeout
    started = False
    while time.monotonic() < deadline:
        prompts = page.evaluate(_PROMPTS_JS)
        busy = any("*" in p for p in prompts)
        started = started or busy or (bool(prompts) and any(map(_executed, prompts)))
        if started and not busy and page.evaluate(_KERNEL_IDLE_JS):
            return prompts
        page.wait_for_timeout(250)
    pytest.fail(f"cells still running after {timeout:.0f} s: prompts {page.evaluate(_PROMPTS_JS)}")


def _wait_for_new_image(page, handle_index: int, before: str, timeout: float) -> str:
    """Wait until the explorer's image differs from `before` and then stays the same for 1 s."""
    deadline = time.monotonic() + timeout
    last, stable_since = before, None
    while time.monotonic() < deadline:
        src = page.evaluate(_EXPLORER_IMAGES_JS)[handle_index]
        if src != last:
            last, stable_since = src, time.monotonic()
        elif last != before and time.monotonic() - stable_since >= 1.0:
            return last
        page.wait_for_timeout(200)
    pytest.fail("the explorer's figure did not change after moving its slider "
                f"(waited {timeout:.0f} s)")


def _move_first_slider(page) -> None:
    """Focus the first slider handle of the first explorer and press the right arrow."""
    explorer = page.locator(".jp-NotebookPanel:not(.lm-mod-hidden) .widget-vbox:has(img)").first
    handle = explorer.locator(".noUi-handle, .ui-slider-handle").first
    handle.scroll_into_view_if_needed()
    handle.focus()
    for _ in range(3):
        handle.press("ArrowRight")
        page.wait_for_timeout(100)
    # continuous_update=False sends the value when the handle is released / loses focus
    page.keyboard.press("Tab")


def _open_notebook(page, name: str) -> None:
    """Open `name` in the already loaded JupyterLab (no page reload) and wait for its kernel."""
    page.evaluate("name => window.jupyterapp.commands.execute('docmanager:open', "
                  "{path: name, factory: 'Notebook'})", name)
    page.wait_for_function("name => Array.from(window.jupyterapp.shell.widgets('main'))"
                           ".some(w => w.context?.path === name && w.isVisible)",
                           arg=name, timeout=60_000)
    page.evaluate("name => { const w = Array.from(window.jupyterapp.shell.widgets('main'))"
                  ".find(w => w.context?.path === name); window.jupyterapp.shell.activateById(w.id); }",
                  name)
    page.wait_for_selector(".jp-NotebookPanel:not(.lm-mod-hidden) .jp-Cell", timeout=60_000)
    # the kernel is ready when the notebook's session reports an idle kernel
    page.wait_for_function("name => Array.from(window.jupyterapp.shell.widgets('main'))"
                           ".some(w => w.context?.path === name"
                           " && w.sessionContext?.session?.kernel?.status === 'idle')",
                           arg=name, timeout=90_000)


def _close_all(page) -> None:
    """Save (into the temporary root) and close every tab, so no 'unsaved changes' dialog appears."""
    page.evaluate("""async () => {
        for (const widget of Array.from(window.jupyterapp.shell.widgets('main'))) {
            if (widget.context) { await widget.context.save(); }
            widget.dispose();
        }
    }""")
    page.wait_for_function("() => !document.querySelector('.jp-NotebookPanel')", timeout=30_000)


@pytest.fixture(scope="module")
def page(lab, browser):
    """One JupyterLab page for all notebooks: loading the application once saves seconds per test."""
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.goto(f"{lab}/lab?reset&token={TOKEN}")
    page.wait_for_function("() => window.jupyterapp?.commands?.hasCommand('docmanager:open')",
                           timeout=90_000)
    yield page
    page.close()


@pytest.mark.parametrize("name", ["demo_explorer.ipynb", *_chapter_notebooks()])
def test_notebook_runs_in_jupyterlab_and_its_explorer_answers(name, lab, page, capsys, tmp_path):
    try:
        _check_notebook(page, name, capsys)
    except BaseException:
        shot = tmp_path / f"{name}.png"
        page.screenshot(path=str(shot), full_page=True)
        print(f"screenshot of the failing page: {shot}")
        raise
    finally:
        _close_all(page)
        _shut_down_kernels(lab)


def _check_notebook(page, name: str, capsys) -> None:
    """Open, run all, look for errors, move a slider; print the timings."""
    t0 = time.monotonic()
    _open_notebook(page, name)
    t_open = time.monotonic() - t0
    _run_all(page)
    prompts = _wait_until_done(page, RUN_TIMEOUT_S)
    t_run = time.monotonic() - t0 - t_open
    errors = page.evaluate(_ERRORS_JS)
    assert not errors, f"{name}: a cell shows an error:\n" + "\n----\n".join(errors)
    assert len(prompts) == _count_code_cells(name), (
        f"{name}: {len(prompts)} code cells rendered, the notebook has {_count_code_cells(name)}")
    counts = page.evaluate(_EXECUTION_COUNTS_JS)
    not_run = [i for i, count in enumerate(counts) if count is None]
    assert not not_run, f"{name}: code cells {not_run} did not run (execution counts {counts})"
    images = page.evaluate(_EXPLORER_IMAGES_JS)
    assert images, f"{name}: no explorer figure (a widget with an image) was rendered"
    t1 = time.monotonic()
    _move_first_slider(page)
    _wait_for_new_image(page, 0, images[0], SLIDER_TIMEOUT_S)
    t_slider = time.monotonic() - t1
    with capsys.disabled():
        print(f"\n[browser] {name}: open {t_open:.1f} s, run all {t_run:.1f} s "
              f"({len(prompts)} code cells), slider -> new figure {t_slider:.1f} s")


def _count_code_cells(name: str) -> int:
    if name == "demo_explorer.ipynb":
        return len(DEMO_SOURCE)
    cells = json.loads((NOTEBOOKS / name).read_text(encoding="utf-8"))["cells"]
    return sum(cell["cell_type"] == "code" for cell in cells)


def _shut_down_kernels(lab: str) -> None:
    """Stop every kernel of the server so the next notebook has the machine to itself."""
    with urllib.request.urlopen(f"{lab}/api/kernels?token={TOKEN}", timeout=10) as response:
        kernels = json.load(response)
    for kernel in kernels:
        request = urllib.request.Request(f"{lab}/api/kernels/{kernel['id']}?token={TOKEN}", method="DELETE")
        urllib.request.urlopen(request, timeout=30).close()
