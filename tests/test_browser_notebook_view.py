"""How JupyterLab shows the notebooks, in headless Chromium: lecture mode and opening untouched.

* ``ck.lecture_mode()`` run in a cell enlarges the notebook's own text: the computed font size
  of a markdown paragraph, a code cell, a text output and a widget label grows by half, and
  ``ck.lecture_mode(False)`` run in a later cell brings each back to its size before;
* each chapter notebook opened untouched stays unmodified once its kernel is connected (no
  unsaved mark on its tab) and closes without the "Save your work" dialog. JupyterLab writes
  the kernel's metadata into the notebook on connecting, so this holds when the notebooks store
  the metadata of this kernel (coursekit/tools/kernel_metadata.py). With a kernel of another
  Python version it cannot hold (the version is part of that metadata, jupyter/notebook#2123):
  the test then checks that the version is all JupyterLab changed, and is skipped saying so.

Runs like tests/test_browser.py (marker ``browser``; skipped when Playwright or Chromium is missing).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import nbformat
import pytest

import lab_harness as lab_h
from coursekit.tools.notebooks import chapter_notebooks

pytestmark = pytest.mark.browser

NOTEBOOKS = Path(__file__).parents[1] / "notebooks"
UNTOUCHED = "untouched"          # the folder of the served copies that no test runs or saves
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


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """JupyterLab serving the lecture-mode notebook and untouched copies of the chapters."""
    reason = lab_h.missing_reason()
    if reason:
        pytest.skip(reason)
    base = tmp_path_factory.mktemp("lab")
    (base / "root" / UNTOUCHED).mkdir(parents=True)
    for path in chapter_notebooks(NOTEBOOKS):
        shutil.copy(path, base / "root" / UNTOUCHED / path.name)
    lab_h.write_notebook(base / "root" / LECTURE, LECTURE_CELLS)
    with lab_h.running_lab(base / "root", base) as url, lab_h.launched_chromium() as browser:
        page = lab_h.new_lab_page(browser, url)
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


def _changed(stored: dict, shown: dict) -> list[str]:
    """The metadata fields JupyterLab changed: 'kernelspec.display_name', 'language_info.version', ..."""
    return sorted(f"{key}.{field}" for key in ("kernelspec", "language_info")
                  for field in set(stored.get(key, {})) | set(shown.get(key) or {})
                  if stored.get(key, {}).get(field) != (shown.get(key) or {}).get(field))


@pytest.mark.parametrize("name", [p.name for p in chapter_notebooks(NOTEBOOKS)])
def test_untouched_chapter_opens_unmodified_and_closes_without_asking(name, page):
    path = f"{UNTOUCHED}/{name}"
    stored = json.loads((NOTEBOOKS / name).read_text(encoding="utf-8"))["metadata"]
    lab_h.open_notebook(page, path)
    state = page.evaluate(_CONNECTED_STATE_JS, path)
    changed = _changed(stored, state)
    dialog = _close_active_tab(page)
    page.wait_for_function("path => !Array.from(window.jupyterapp.shell.widgets('main'))"
                           ".some(w => w.context?.path === path)", arg=path, timeout=30_000)
    stored_version = stored.get("language_info", {}).get("version")
    if stored_version is not None and state["version"] != stored_version:
        assert changed == ["language_info.version"], (
            f"{name}: opening it changed {changed}; with a kernel of another Python only the version may differ")
        pytest.skip(f"the notebooks are stored for Python {stored_version}, the kernel "
                    f"is Python {state['version']}: JupyterLab marks them modified on opening (it writes "
                    "the kernel's version into them, jupyter/notebook#2123)")
    assert not changed, f"{name}: JupyterLab changed the stored metadata {changed} on opening it"
    assert not state["dirty"] and not state["modelDirty"], f"{name}: marked modified though untouched"
    assert dialog is None, f"{name}: closing it untouched asked {dialog!r}"
