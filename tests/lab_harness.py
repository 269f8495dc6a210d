"""JupyterLab on loopback driven by headless Chromium: the parts the browser test and the
browser benchmark (``benchmarks/run.py --browser``) share.

* `running_lab` starts a JupyterLab server on a free 127.0.0.1 port serving a folder, and
  stops it (by its process) at the end;
* `open_notebook`, `run_all`, `wait_until_done`, `close_all`, `shut_down_kernels` drive the
  application the way a user would (menus, tabs), with a timeout on every wait;
* `install_probe` puts a recorder into the page that notes, in the page's own clock
  (``performance.now()``), every key press and mouse press/release, every value shown by a
  slider readout, and every new figure painted: an ``<img>`` that appears or gets a new
  ``src``, timed at the first animation frame after its ``load`` event, which is when the
  browser paints it;
* `drag` moves a slider handle like a hand: mouse down, a move every 16 ms, mouse up.

Every failure raises `HarnessError` with what was waited for; the test turns it into a test
failure, the benchmark into a message.
"""

from __future__ import annotations

import contextlib
import functools
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

__all__ = ["CHROMIUM_ARGS", "TOKEN", "VIEWPORT", "HarnessError", "chromium_path", "missing_reason",
           "write_notebook", "running_lab", "launched_chromium", "new_lab_page", "open_notebook",
           "run_all", "wait_until_done", "close_all", "shut_down_kernels", "install_probe",
           "probe_state", "execute_in_kernel", "EXPLORER", "first_slider", "drag", "wait_until_quiet",
           "error_outputs", "stderr_lines", "teardown_page_error", "axe_source", "axe_violations"]

CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]
TOKEN = "coursekit-browser-harness"
VIEWPORT = {"width": 1600, "height": 1000}
ACTIVE = ".jp-NotebookPanel:not(.lm-mod-hidden)"
# the explorer's box: the class the explorer sets, or (older explorers) a widget box holding a figure
EXPLORER = f"{ACTIVE} .ck-explorer, {ACTIVE} .widget-vbox:not(:has(.widget-vbox)):has(img)"


class HarnessError(RuntimeError):
    """Something the harness waited for did not happen (the message says what)."""


@functools.lru_cache(maxsize=1)
def chromium_path() -> str | None:
    """The Chromium to drive: the system's (Debian's package ``chromium``), else the one Playwright
    downloads (``python -m playwright install chromium``), else None. Call it first outside a
    running Playwright (`missing_reason` does): it asks Playwright where its own browser is."""
    for candidate in ("/usr/bin/chromium", shutil.which("chromium"), shutil.which("chromium-browser")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        return None
    with sync_playwright() as pw:
        own = pw.chromium.executable_path
    return own if own and os.access(own, os.X_OK) else None


def missing_reason() -> str | None:
    """Why the browser cannot be driven here (with the fix), or None when it can."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright for Python is not installed (python -m pip install -e \".[dev]\" installs it)"
    if chromium_path() is None:
        return ("Chromium is not installed: apt-get install chromium (Debian, Ubuntu), or "
                "python -m playwright install chromium where downloads are allowed")
    return None


@functools.lru_cache(maxsize=1)
def _kernel_metadata() -> dict:
    from coursekit.tools.kernel_metadata import kernel_metadata
    return kernel_metadata()


def write_notebook(path: Path, cells: list) -> None:
    """A notebook of `cells` (a string is a code cell of that source; an nbformat cell is taken
    as it is) for the python3 kernel, with the kernel metadata JupyterLab writes for this
    environment's kernel, so that opening it changes nothing."""
    import nbformat
    from coursekit.tools.kernel_metadata import with_kernel_metadata
    nb = with_kernel_metadata(nbformat.v4.new_notebook(), _kernel_metadata())
    nb.cells = [nbformat.v4.new_code_cell(cell) if isinstance(cell, str) else cell for cell in cells]
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


@contextlib.contextmanager
def running_lab(root: Path, base: Path):
    """Serve `root` with JupyterLab on a free loopback port; yields its URL. `base` (an empty
    temporary folder) takes the settings, runtime files and the server log."""
    _write_settings(base / "settings")
    port = _free_port()
    cmd = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ServerApp.open_browser=False",
           "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}", "--ServerApp.port_retries=0",
           f"--ServerApp.root_dir={root}", f"--IdentityProvider.token={TOKEN}",
           f"--LabApp.user_settings_dir={base / 'settings'}", f"--LabApp.workspaces_dir={base / 'workspaces'}",
           "--LabApp.expose_app_in_browser=True"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd.append("--allow-root")
    env = dict(os.environ, JUPYTER_CONFIG_DIR=str(base / "config"), JUPYTER_RUNTIME_DIR=str(base / "runtime"),
               MPLBACKEND="module://matplotlib_inline.backend_inline")
    log_path = base / "server.log"
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=root)
        url = f"http://127.0.0.1:{port}"
        try:
            _wait_for_server(url, proc, log_path)
            yield url
        finally:
            proc.terminate()
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=20)


def _wait_for_server(url: str, proc: subprocess.Popen, log: Path, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise HarnessError(f"JupyterLab exited with code {proc.returncode}:\n{log.read_text()[-3000:]}")
        try:
            with urllib.request.urlopen(f"{url}/api/status?token={TOKEN}", timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            time.sleep(0.5)
    raise HarnessError(f"JupyterLab did not answer within {timeout:.0f} s:\n{log.read_text()[-3000:]}")


@contextlib.contextmanager
def launched_chromium():
    """Headless Chromium (`chromium_path`: the system one when there is one) under Playwright."""
    from playwright.sync_api import sync_playwright
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium_path(), args=CHROMIUM_ARGS, headless=True)
        try:
            yield browser
        finally:
            browser.close()


# JupyterLab (4.4 and later) gives the comms of each comm target a kernel subshell of their own:
# opening a comm sends a create_subshell_request, and one of the promises that wait for its reply
# has no error handler. When the kernel connection goes away before the reply (a test closes the
# notebook or stops its kernel just as the widget manager opens its control comm), JupyterLab
# cancels the request and the page reports the rejection as an uncaught error. It comes from the
# test's teardown, never from the course; `test_browser_notebook_view.py` provokes it.
_TEARDOWN_PAGE_ERROR = re.compile(
    r"(Error: )?Canceled future for create_subshell_request message before replies were done")


def teardown_page_error(message: str) -> bool:
    """Whether the uncaught page error `message` is JupyterLab's cancelled subshell request
    (see `_TEARDOWN_PAGE_ERROR`) rather than an error to report."""
    return _TEARDOWN_PAGE_ERROR.fullmatch(message.strip()) is not None


def _record_page_error(page, message: str) -> None:
    (page.ck_teardown_errors if teardown_page_error(message) else page.ck_page_errors).append(message)


def new_lab_page(browser, url: str, *, viewport: dict = VIEWPORT):
    """A page with JupyterLab loaded and ready to open documents; uncaught page errors are
    collected in ``page.ck_page_errors``, except JupyterLab's cancelled subshell requests
    (`teardown_page_error`), which go to ``page.ck_teardown_errors``."""
    page = browser.new_page(viewport=viewport)
    page.ck_page_errors, page.ck_teardown_errors = [], []
    page.on("pageerror", lambda error: _record_page_error(page, str(error)))
    page.goto(f"{url}/lab?reset&token={TOKEN}")
    page.wait_for_function("() => window.jupyterapp?.commands?.hasCommand('docmanager:open')",
                           timeout=90_000)
    return page


# JavaScript run in the page ------------------------------------------------------------

_PROMPTS_JS = f"""() => Array.from(document.querySelectorAll(
    '{ACTIVE} .jp-CodeCell .jp-InputPrompt')).map(p => p.textContent.trim())"""

_KERNEL_IDLE_JS = f"""() => document.querySelector(
    '{ACTIVE} .jp-Notebook-ExecutionIndicator')?.dataset.status === 'idle'"""

_ERRORS_JS = f"""() => Array.from(document.querySelectorAll('{ACTIVE} .jp-OutputArea-output'))
    .filter(o => /Traceback|Error displaying widget/.test(o.textContent)
                 || o.dataset.mimeType === 'application/vnd.jupyter.stderr')
    .map(o => o.textContent.slice(0, 1500))"""

# Opens a notebook and records every error and stderr message of its kernel from the start,
# also those of widget callbacks, which JupyterLab shows in no cell. One exchange is harmless and
# left out (see `error_outputs`): JupyterLab's widget manager asks a newly started kernel for its
# widgets over a 'jupyter.widget.control' comm; a kernel that has not imported ipywidgets yet
# logs that it has no such comm target, closes the comm, and logs "No such comm: <id>" for each
# message the manager sends over it before it learns of the close (the lines may come in either
# order, so they are told apart by the comm's id). The manager then asks another
# way; the ipywidgets maintainers call these lines harmless (ipywidgets issue 3525). Whether they
# come depends on how soon the manager asks, so they cannot be relied on either way.
_OPEN_AND_WATCH_JS = """async name => {
    const widget = await window.jupyterapp.commands.execute(
        'docmanager:open', {path: name, factory: 'Notebook'});
    const watch = {stderr: [], errors: [], controlComms: []};
    window.__ckKernelWatch = watch;
    const context = widget.sessionContext;
    context.iopubMessage.connect((_, msg) => {
        const c = msg.content;
        if (msg.header.msg_type === 'error') {
            watch.errors.push(`${c.ename}: ${c.evalue}`);
        } else if (msg.header.msg_type === 'stream' && c.name === 'stderr') {
            watch.stderr.push(c.text);
        }
    });
    const watchSent = kernel => kernel?.anyMessage.connect((_, {msg, direction}) => {
        if (direction === 'send' && msg.header.msg_type === 'comm_open'
                && msg.content.target_name === 'jupyter.widget.control') {
            watch.controlComms.push(msg.content.comm_id);
        }
    });
    watchSent(context.session?.kernel);
    context.kernelChanged.connect((_, change) => watchSent(change.newValue));
}"""

_HARMLESS_STDERR = re.compile(r"No such comm target registered: jupyter\.widget\.control|No such comm: (\S+)")


def open_notebook(page, name: str) -> None:
    """Open `name` in the already loaded JupyterLab (no page reload), start recording its
    kernel's error output (see `error_outputs`) and wait until the kernel is idle."""
    page.evaluate(_OPEN_AND_WATCH_JS, name)
    page.wait_for_function("name => Array.from(window.jupyterapp.shell.widgets('main'))"
                           ".some(w => w.context?.path === name && w.isVisible)",
                           arg=name, timeout=60_000)
    page.evaluate("name => { const w = Array.from(window.jupyterapp.shell.widgets('main'))"
                  ".find(w => w.context?.path === name); window.jupyterapp.shell.activateById(w.id); }",
                  name)
    page.wait_for_selector(f"{ACTIVE} .jp-Cell", timeout=60_000)
    page.wait_for_function("name => Array.from(window.jupyterapp.shell.widgets('main'))"
                           ".some(w => w.context?.path === name"
                           " && w.sessionContext?.session?.kernel?.status === 'idle')",
                           arg=name, timeout=90_000)


def error_outputs(page) -> list[str]:
    """Tracebacks and stderr in the active notebook's outputs, error messages and stderr lines of
    its kernel (widget callbacks included; not the widget manager's refused control comm, see
    `_OPEN_AND_WATCH_JS`), and uncaught errors in the page."""
    watch = page.evaluate("() => window.__ckKernelWatch") or {"stderr": [], "errors": [], "controlComms": []}
    return (page.evaluate(_ERRORS_JS) + watch["errors"]
            + stderr_lines(watch["stderr"], set(watch["controlComms"]))
            + list(page.ck_page_errors))


def stderr_lines(chunks: list[str], control_comms: set[str]) -> list[str]:
    """The non-blank lines of the kernel's stderr stream, given as the `chunks` its messages
    carried, without the kernel's refusals of the widget control comms `control_comms`.

    The kernel cuts its stream into messages wherever it flushes, so one line may come in
    several messages (a printed text and its newline, for example): lines are taken from the
    whole stream, not from each message."""
    lines = (line.strip() for line in "".join(chunks).splitlines())
    return [line for line in lines if line and not _harmless(line, control_comms)]


def _harmless(line: str, control_comms: set[str]) -> bool:
    """True when `line` is the kernel refusing one of the widget control comms `control_comms`."""
    match = _HARMLESS_STDERR.fullmatch(line)
    return match is not None and (match[1] is None or match[1] in control_comms)


def run_all(page) -> None:
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
    raise HarnessError("Run > Run All Cells did not start the kernel")


def _executed(prompt: str) -> bool:
    """True for an input prompt such as '[12]:' (the cell ran), False for '[ ]:' or '[*]:'."""
    return re.fullmatch(r"\[\d+\]:?", prompt) is not None


def wait_until_done(page, timeout: float) -> list[str]:
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
    raise HarnessError(f"cells still running after {timeout:.0f} s: prompts {page.evaluate(_PROMPTS_JS)}")


def close_all(page) -> None:
    """Save (into the served folder) and close every tab, so no 'unsaved changes' dialog appears."""
    page.evaluate("""async () => {
        for (const widget of Array.from(window.jupyterapp.shell.widgets('main'))) {
            if (widget.context) { await widget.context.save(); }
            widget.dispose();
        }
    }""")
    page.wait_for_function("() => !document.querySelector('.jp-NotebookPanel')", timeout=30_000)


def shut_down_kernels(url: str) -> None:
    """Stop every kernel of the server so the next notebook has the machine to itself."""
    with urllib.request.urlopen(f"{url}/api/kernels?token={TOKEN}", timeout=10) as response:
        kernels = json.load(response)
    for kernel in kernels:
        request = urllib.request.Request(f"{url}/api/kernels/{kernel['id']}?token={TOKEN}", method="DELETE")
        urllib.request.urlopen(request, timeout=30).close()


_EXECUTE_JS = """async code => {
    const kernel = window.jupyterapp.shell.currentWidget.sessionContext.session.kernel;
    const future = kernel.requestExecute({code, silent: false, store_history: false});
    const out = [];
    future.onIOPub = msg => {
        const c = msg.content;
        if (msg.header.msg_type === 'stream') { out.push(c.text); }
        if (msg.header.msg_type === 'error') { out.push(`${c.ename}: ${c.evalue}`); }
    };
    await future.done;
    return out.join('');
}"""


def execute_in_kernel(page, code: str, timeout: float = 60.0) -> str:
    """Run `code` in the active notebook's kernel (no cell is added); return what it printed."""
    page.set_default_timeout(timeout * 1e3)
    try:
        return page.evaluate(_EXECUTE_JS, code)
    finally:
        page.set_default_timeout(30_000)


# The probe: input events, slider readouts and figure paints, on the page's clock -----------

_PROBE_JS = """() => {
    const root = document.querySelector('.jp-NotebookPanel:not(.lm-mod-hidden) .jp-Notebook');
    const probe = {paints: [], inputs: [], readouts: [], seen: new WeakMap()};
    const paint = (img, src) => {
        if (img.getAttribute('src') !== src || !img.isConnected) { return; }
        requestAnimationFrame(() => probe.paints.push({t: performance.now(), src}));
    };
    const watch = img => {
        const src = img.getAttribute('src');
        if (!src || probe.seen.get(img) === src) { return; }
        probe.seen.set(img, src);
        img.addEventListener('load', () => paint(img, src), {once: true});
    };
    const imgs = node => node.nodeType !== 1 ? [] :
        (node.tagName === 'IMG' ? [node] : Array.from(node.querySelectorAll('img')));
    root.querySelectorAll('img').forEach(img => probe.seen.set(img, img.getAttribute('src')));
    new MutationObserver(records => {
        for (const r of records) {
            if (r.type === 'attributes') { watch(r.target); }
            r.addedNodes.forEach(n => imgs(n).forEach(watch));
            const readout = (r.target.nodeType === 1 ? r.target : r.target.parentElement)
                ?.closest?.('.widget-readout');
            if (readout) { probe.readouts.push({t: performance.now(), text: readout.textContent}); }
        }
    }).observe(root, {subtree: true, childList: true, attributes: true, attributeFilter: ['src'],
                      characterData: true});
    for (const type of ['keydown', 'mousedown', 'mouseup']) {
        document.addEventListener(type, e => probe.inputs.push({type, t: e.timeStamp}), true);
    }
    window.__ckProbe = probe;
}"""


def install_probe(page) -> None:
    """Start recording inputs, readouts and figure paints in the active notebook (see module doc)."""
    page.evaluate(_PROBE_JS)


def probe_state(page) -> dict:
    """Everything recorded so far: lists ``paints`` ({t, src}), ``inputs`` ({type, t}) and
    ``readouts`` ({t, text}), plus ``now``, all in milliseconds of the page's clock."""
    return page.evaluate("() => ({paints: window.__ckProbe.paints, inputs: window.__ckProbe.inputs,"
                         " readouts: window.__ckProbe.readouts, now: performance.now()})")


def first_slider(page, scope: str = EXPLORER):
    """The first slider of the first explorer (or of whatever `scope` selects), scrolled into view."""
    slider = page.locator(scope).first.locator(".widget-slider").first
    slider.scroll_into_view_if_needed()
    return slider


def drag(page, slider, seconds: float = 3.0, *, trips: float = 1.5, reach: float = 0.9) -> None:
    """Press the mouse on the slider's handle, move it in a 16 ms rhythm towards the far end of
    the track (`reach` of the way) and back, `trips` times within `seconds` (a half trip ends
    at the far end, away from the start value), then release."""
    handle = slider.locator(".noUi-handle").first.bounding_box()
    track = slider.locator(".noUi-target").first.bounding_box()
    if handle is None or track is None:
        raise HarnessError("the slider has no visible handle or track to drag")
    x0, y = handle["x"] + handle["width"] / 2, handle["y"] + handle["height"] / 2
    left, right = track["x"] + 2, track["x"] + track["width"] - 2
    far = left if x0 - left > right - x0 else right
    page.mouse.move(x0, y)
    page.mouse.down()
    start = time.perf_counter()
    step = 0
    while (elapsed := time.perf_counter() - start) < seconds:
        phase = (elapsed * trips / seconds) % 1.0           # 0 -> 1 per trip
        there = 2 * phase if phase < 0.5 else 2 - 2 * phase  # 0 -> 1 -> 0
        page.mouse.move(x0 + reach * there * (far - x0), y)
        step += 1
        time.sleep(max(0.0, start + 0.016 * step - time.perf_counter()))
    page.mouse.up()


def wait_until_quiet(page, quiet_ms: float = 1000.0, timeout: float = 60.0) -> dict:
    """Wait until no figure has been painted for `quiet_ms`; return `probe_state` then."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = probe_state(page)
        last = max([p["t"] for p in state["paints"]] + [i["t"] for i in state["inputs"]], default=0.0)
        if state["now"] - last >= quiet_ms:
            return state
        page.wait_for_timeout(100)
    raise HarnessError(f"the figure kept changing for {timeout:.0f} s")


def axe_source() -> str:
    """The text of axe-core's ``axe.min.js``: the file ``$AXE_CORE_JS`` names when it is set (to try
    another axe-core), else the one the Python package ``axe-playwright-python`` ships (the ``dev``
    extra installs it). Raises `HarnessError` saying how to get it when neither is there."""
    override = os.environ.get("AXE_CORE_JS", "")
    if override:
        if not Path(override).is_file():
            raise HarnessError(f"AXE_CORE_JS is set to {override!r}, which is not a file: point it at "
                               "axe-core's axe.min.js, or unset it to use the one of axe-playwright-python")
        return Path(override).read_text(encoding="utf-8")
    try:
        from axe_playwright_python.sync_playwright import Axe
    except ImportError:
        raise HarnessError("axe-core is missing: it comes with the Python package axe-playwright-python "
                           "(python -m pip install -e \".[dev]\" installs it)") from None
    return Axe().axe_script


#: Marks, inside the elements a selector matches, the highlighted code's token spans (Pygments'
#: ``.highlight span``, on the website and the slides) that are drawn like one already kept: the
#: same colour, size and weight, on the same grounds up to the page (each ancestor's background
#: and opacity), so of the same contrast. A span is kept when it is the first of its look seen
#: whole in its code block (a span cut off by the block's scroll box is kept too, and does not
#: count). A chapter page has about 7,000 token spans, and axe's colour-contrast rule spent
#: 6 of its 9 s on them. Returns how many were marked.
_MARK_REPEATED_CODE_JS = """selector => {
  const look = s => [s.color, s.fontSize, s.fontWeight, s.backgroundColor, s.backgroundImage, s.opacity].join(' ');
  const grounds = new Map(), seen = new Set();
  const ground = element => {
    if (!element) return '';
    if (!grounds.has(element))
      grounds.set(element, look(getComputedStyle(element)) + '|' + ground(element.parentElement));
    return grounds.get(element);
  };
  let marked = 0;
  for (const root of document.querySelectorAll(selector))
    for (const span of root.querySelectorAll('.highlight span')) {
      if (span.childElementCount) continue;
      const box = (span.closest('pre') || span.parentElement).getBoundingClientRect();
      const r = span.getBoundingClientRect();
      const whole = r.width > 0 && r.height > 0 && r.left >= box.left && r.right <= box.right
        && r.top >= box.top && r.bottom <= box.bottom;
      const key = look(getComputedStyle(span)) + '|' + ground(span.parentElement);
      if (seen.has(key)) { span.setAttribute('data-ck-axe-repeat', ''); marked++; }
      else if (whole) seen.add(key);
    }
  return marked;
}"""


def axe_violations(page, selector: str, source: str, *, preload: bool = True) -> list[str]:
    """axe-core's WCAG 2.1 A/AA violations inside the elements `selector` matches, one line each.
    Every rule runs on every element but the token spans of highlighted code drawn like one that
    axe checks (`_MARK_REPEATED_CODE_JS`: the same contrast; a token span is only text, which the
    other rules do not look at); ``resultTypes`` only spares axe listing each element that passed
    (30 to 50 % of its time on a page of 600 sections). Without `preload` axe does not fetch the
    page's style sheets (for its CSS orientation rule): on a page opened from the disk Chromium
    refuses those fetches anyway, and each refusal would be a failed request and a console error
    of the page, which may arrive after axe has returned."""
    page.add_script_tag(content=source)
    page.evaluate(_MARK_REPEATED_CODE_JS, selector)
    found = page.evaluate("""async ([selector, preload]) => {
        axe.configure({rules: [{id: 'color-contrast', selector: '*:not([data-ck-axe-repeat])'}]});
        const result = await axe.run(Array.from(document.querySelectorAll(selector)),
            {runOnly: {type: 'tag', values: ['wcag2a', 'wcag2aa', 'wcag21a', 'wcag21aa']},
             resultTypes: ['violations'], preload});
        for (const span of document.querySelectorAll('[data-ck-axe-repeat]'))
            span.removeAttribute('data-ck-axe-repeat');
        return result.violations.map(v => `${v.id}: ${v.help} (${v.nodes.length} elements, e.g. `
            + `${v.nodes[0].html.slice(0, 160)})`);
    }""", [selector, preload])
    return list(found)
