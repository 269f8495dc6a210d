"""How JupyterLab shows the notebooks, in headless Chromium: lecture mode, reopened explorers.

* ``ck.lecture_mode()`` run in a cell enlarges the notebook's own text: the computed font size
  of a markdown paragraph, a code cell, a text output and a widget label grows by half, and
  ``ck.lecture_mode(False)`` run in a later cell brings each back to its size before;
* a notebook of explorers run, saved, closed and reopened with a new kernel (JupyterLab and
  Notebook 7) shows each explorer's figure and text alternative, not a widget error; running
  the cell again makes the explorer live (coursekit/explorers/_fallback.py);
* a comm opened just before its kernel connection goes away (as when a test closes a notebook
  while the widget manager opens its control comm) makes JupyterLab report its cancelled
  subshell request as an uncaught page error: the harness sets that one aside
  (`lab_harness.teardown_page_error`) and still reports any other uncaught error.

That each chapter opened untouched stays unmodified is checked where tests/test_browser.py opens
it to run it.

Runs like tests/test_browser.py (marker ``browser``; skipped when Playwright or Chromium is missing).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import nbformat
import pytest

import lab_harness as lab_h

pytestmark = pytest.mark.browser

LECTURE = "lecture_text.ipynb"
LECTURE_CELLS = [
    nbformat.v4.new_markdown_cell("## Lecture mode\n\nA paragraph the back row should read: the closed "
                                  "loop $A + B K$ has the poles we ask for (3.21)."),
    "import coursekit as ck\nimport ipywidgets as widgets\nprint('an output line')\n"
    "widgets.IntSlider(3, description='gain')",
    "ck.lecture_mode()",
    "ck.lecture_mode(False)",
]

# the computed font size (px) of each kind of text in the active notebook
_SIZES_JS = f"""() => {{
    const size = selector => parseFloat(getComputedStyle(
        document.querySelector('{lab_h.ACTIVE} ' + selector)).fontSize);
    return {{markdown: size('.jp-RenderedMarkdown p'), code: size('.jp-CodeCell .cm-content'),
             output: size('.jp-OutputArea-output pre'), widget: size('.widget-label')}};
}}"""

_RUN_CELL_JS = """i => { const panel = window.jupyterapp.shell.currentWidget;
    panel.content.activeCellIndex = i; return window.jupyterapp.commands.execute('notebook:run-cell'); }"""


TEARDOWN = "teardown.ipynb"
REOPENED = "reopened_explorers.ipynb"
REOPENED_CELLS = ["%matplotlib inline\nfrom coursekit.explorers.ch1 import euler_explorer, msd_explorer",
                  "euler_explorer()", "msd_explorer()"]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """JupyterLab serving the lecture-mode, reopened-explorers and teardown notebooks."""
    reason = lab_h.missing_reason()
    if reason:
        pytest.skip(reason)
    base = tmp_path_factory.mktemp("lab")
    (base / "root").mkdir()
    lab_h.write_notebook(base / "root" / LECTURE, LECTURE_CELLS)
    lab_h.write_notebook(base / "root" / REOPENED, REOPENED_CELLS)
    lab_h.write_notebook(base / "root" / TEARDOWN, ["6 * 7"])
    with lab_h.running_lab(base / "root", base) as url, lab_h.launched_chromium() as browser:
        page = lab_h.new_lab_page(browser, url)
        page.ck_url, page.ck_root = url, base / "root"
        yield page
        page.close()
        lab_h.shut_down_kernels(url)


def _run_cell(page, index: int, ready: str) -> None:
    """Run cell `index` of the active notebook; wait until it has run, the kernel is idle and
    `ready` matches in the notebook."""
    page.evaluate(_RUN_CELL_JS, index)
    page.wait_for_function("i => { const panel = window.jupyterapp.shell.currentWidget;"
                           " return panel.content.widgets[i].model.executionCount !== null"
                           " && panel.sessionContext.session?.kernel?.status === 'idle'; }",
                           arg=index, timeout=60_000)
    page.wait_for_selector(f"{lab_h.ACTIVE} {ready}", state="attached", timeout=60_000)


def test_lecture_mode_enlarges_the_notebooks_text_and_off_restores_it(page):
    lab_h.open_notebook(page, LECTURE)
    _run_cell(page, 1, ".widget-label")
    before = page.evaluate(_SIZES_JS)
    _run_cell(page, 2, 'style[data-coursekit="lecture-mode-on"]')
    on = page.evaluate(_SIZES_JS)
    _run_cell(page, 3, 'style[data-coursekit="lecture-mode-off"]')
    off = page.evaluate(_SIZES_JS)
    errors = lab_h.error_outputs(page)
    lab_h.close_all(page)
    assert not errors, errors
    assert all(on[kind] >= 1.4 * before[kind] for kind in before), (before, on)
    assert off == before, (before, off)


def _close_active_tab(page) -> str | None:
    """Close the active tab with its close icon, as a reader does; return the title of the
    dialog that appears (after discarding through it), or None."""
    page.locator(".lm-DockPanel-tabBar .lm-TabBar-tab.lm-mod-current .lm-TabBar-tabCloseIcon").click()
    dialog = page.locator(".jp-Dialog")
    try:
        dialog.wait_for(state="visible", timeout=3000)
    except Exception:  # playwright's TimeoutError: no dialog, the tab closed
        return None
    title = dialog.locator(".jp-Dialog-header").inner_text()
    dialog.locator("button", has_text="Discard").click()
    return title


# every output the active notebook shows (not hidden): whether it is an explorer's fallback or a
# live explorer, its figure's text alternative and whether the figure loaded, and its text
_SHOWN_OUTPUTS_JS = """() => Array.from(document.querySelectorAll(
        '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-OutputArea-child'))
    .filter(o => o.getClientRects().length > 0)
    .map(o => { const img = o.querySelector('img');
        return {fallback: !!o.querySelector('.ck-explorer-fallback'), live: !!o.querySelector('.ck-explorer'),
                alt: img?.alt || '', loaded: !!img && img.complete && img.naturalWidth > 0,
                text: o.innerText.trim().slice(0, 300)}; })"""


def _shown_outputs(page, expected: int, kind: str, timeout: float = 60.0) -> list[dict]:
    """The outputs shown once `expected` of them are of `kind` ('fallback' or 'live') with their
    figure loaded (or after `timeout` seconds, whatever is shown then)."""
    deadline = time.monotonic() + timeout
    while True:
        shown = page.evaluate(_SHOWN_OUTPUTS_JS)
        if sum(o[kind] and o["loaded"] for o in shown) >= expected or time.monotonic() > deadline:
            return shown
        page.wait_for_timeout(500)


def _reopened_shows_each_figure(page, shot: Path) -> None:
    """Each explorer of the reopened notebook shows its saved figure with its text alternative,
    and nothing shows a widget error; a screenshot of the notebook goes to `shot`."""
    shown = _shown_outputs(page, 2, "fallback")
    page.wait_for_timeout(3000)           # the widget manager has restored what it can by now
    shown = page.evaluate(_SHOWN_OUTPUTS_JS)
    page.screenshot(path=str(shot), full_page=True)
    print(f"screenshot of the reopened notebook: {shot}")
    assert [o["fallback"] for o in shown] == [True, True], shown
    assert all(o["loaded"] and "Settings:" in o["alt"] and len(o["alt"]) > 40 for o in shown), shown
    assert not any(re.search(r"Error displaying widget|Loading widget", o["text"]) for o in shown), shown


def test_explorers_of_a_saved_notebook_show_their_figure_when_reopened_and_run_live_again(page, tmp_path):
    """Run all, save, close, stop the kernel, reopen (JupyterLab, then Notebook 7): each explorer
    shows its figure and text alternative, not "Error displaying widget: model not found";
    running its cell again makes it live. Saving wrote outputs only, no widget state."""
    errors = len(page.ck_page_errors)                # those of this test, not of the tests before
    lab_h.open_notebook(page, REOPENED)
    lab_h.run_all(page)
    lab_h.wait_until_done(page, 240)
    live = _shown_outputs(page, 2, "live")
    assert [(o["live"], o["fallback"]) for o in live] == [(True, False)] * 2, live    # no figure twice
    lab_h.close_all(page)
    lab_h.shut_down_kernels(page.ck_url)
    saved = nbformat.read(page.ck_root / REOPENED, as_version=4)

    lab_h.open_notebook(page, REOPENED)              # a new kernel: the widgets' models are gone
    _reopened_shows_each_figure(page, tmp_path / "reopened-lab.png")
    assert "widgets" not in saved.metadata
    assert [len(cell.outputs) for cell in saved.cells] == [0, 2, 2]      # the fallback, the widget
    assert not page.ck_page_errors[errors:], page.ck_page_errors[errors:]
    _run_cell(page, 0, ".jp-CodeCell")
    _run_cell(page, 1, ".ck-explorer img")
    shown = _shown_outputs(page, 1, "live")
    assert [(o["live"], o["fallback"]) for o in shown] == [(True, False), (False, True)], shown
    handle = page.locator(f"{lab_h.ACTIVE} .ck-explorer .noUi-handle").first
    before = page.locator(f"{lab_h.ACTIVE} .ck-explorer img").first.get_attribute("src")
    handle.focus()
    handle.press("ArrowRight")
    page.wait_for_function(f"src => document.querySelector('{lab_h.ACTIVE} .ck-explorer img').src !== src",
                           arg=before, timeout=60_000)
    page.screenshot(path=str(tmp_path / "run-again-lab.png"))
    _close_active_tab(page)
    lab_h.shut_down_kernels(page.ck_url)

    pytest.importorskip("notebook", minversion="7", reason="Notebook 7 is not installed")
    tab = page.context.browser.new_page(viewport=lab_h.VIEWPORT)
    try:
        tab.goto(f"{page.ck_url}/notebooks/{REOPENED}?token={lab_h.TOKEN}")
        tab.wait_for_function("() => document.querySelector('.jp-Notebook-ExecutionIndicator')?.dataset.status"
                              " === 'idle'", timeout=90_000)
        _reopened_shows_each_figure(tab, tmp_path / "reopened-notebook7.png")
    finally:
        tab.close()
        lab_h.shut_down_kernels(page.ck_url)


# On a second connection to the active notebook's kernel (the notebook's own stays as it was),
# with JupyterLab's default of one subshell per comm target: open a comm, and close the
# connection before the kernel has answered the subshell request the comm sent. Then throw an
# error of the page's own.
_CUT_OFF_SUBSHELL_JS = """async () => {
    const own = window.jupyterapp.shell.currentWidget.sessionContext.session.kernel;
    const kernel = own.clone({handleComms: true, commsOverSubshells: 'perCommTarget'});
    await kernel.info;
    kernel.createComm('coursekit.teardown');
    await new Promise(resolve => setTimeout(resolve, 0));
    kernel.dispose();
    setTimeout(() => { throw new Error('coursekit: an uncaught error of the page'); }, 50);
    return kernel.supportsSubshells;
}"""


def test_a_subshell_request_cut_off_by_teardown_is_set_aside_and_other_page_errors_are_kept(page):
    errors, teardown = len(page.ck_page_errors), len(page.ck_teardown_errors)
    lab_h.open_notebook(page, TEARDOWN)
    if not page.evaluate(_CUT_OFF_SUBSHELL_JS):
        lab_h.close_all(page)
        pytest.skip("this kernel has no subshells, so JupyterLab sends no subshell request")
    deadline = time.monotonic() + 10
    while len(page.ck_page_errors) == errors and time.monotonic() < deadline:
        page.wait_for_timeout(100)
    lab_h.close_all(page)
    lab_h.shut_down_kernels(page.ck_url)
    assert page.ck_teardown_errors[teardown:] == [
        "Error: Canceled future for create_subshell_request message before replies were done"]
    assert page.ck_page_errors[errors:] == ["coursekit: an uncaught error of the page"]
