"""An explorer's fallback output: what a notebook reopened after a save shows in place of the
widget, whose model is gone (coursekit/explorers/_fallback.py). In the browser, JupyterLab and
Notebook 7: tests/test_browser_notebook_view.py."""

import base64
import html
import re

import IPython
import IPython.display
import nbformat
import pytest

from coursekit.explorers import ch1
from coursekit.explorers._fallback import FALLBACK, is_fallback
from coursekit.tools import static_explorers as se


@pytest.fixture
def published(monkeypatch):
    """The display data an explorer publishes besides its own bundle, as if shown in a kernel."""
    sent = []
    monkeypatch.setattr(IPython, "get_ipython", lambda: type("Shell", (), {"kernel": object()})())
    monkeypatch.setattr(IPython.display, "publish_display_data",
                        lambda data, metadata=None: sent.append((data, metadata)))
    return sent


def test_an_explorer_shown_in_a_kernel_publishes_its_figure_and_text_before_its_widget(published):
    explorer = ch1.msd_explorer()
    bundle = explorer._repr_mimebundle_()
    assert len(published) == 1, published
    data, metadata = published[0]
    assert list(data) == ["text/html"] and metadata == {FALLBACK: True}
    page = data["text/html"]
    src, alt = re.search(r'<img src="data:image/png;base64,([^"]+)" alt="([^"]+)"', page).groups()
    assert base64.b64decode(src) == explorer.static_png() == base64.b64decode(bundle["image/png"])
    assert html.unescape(alt) == explorer.alt and "Settings: m = " in alt
    assert all(html.escape(line) in page for line in explorer.text.split("\n"))
    assert html.escape(explorer.title) in page and "run this cell" in page
    # shown only while the output after it holds no live explorer, which it hides then
    assert ":has(+ .jp-OutputArea-child .ck-explorer)" in page
    assert "+ .jp-OutputArea-child:not(:has(.ck-explorer))" in page


def test_outside_a_kernel_an_explorer_publishes_nothing_besides_its_bundle(monkeypatch):
    sent = []
    monkeypatch.setattr(IPython.display, "publish_display_data", lambda *a, **k: sent.append(a))
    ch1.msd_explorer()._repr_mimebundle_()
    assert sent == []


def test_the_static_builds_drop_the_fallback_and_keep_their_own_explorer(tmp_path, published):
    explorer = ch1.euler_explorer()
    explorer._repr_mimebundle_()
    fallback = nbformat.v4.new_output("display_data", data=published[0][0], metadata=published[0][1])
    data = se.explorer_data(explorer, column=False, max_frames=4)
    shown = nbformat.v4.new_output("display_data", data={se.MIME: data, "image/png": "iVBOR", "text/plain": "x"})
    printed = nbformat.v4.new_output("stream", text="printed\n")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_markdown_cell("text"),
                                         nbformat.v4.new_code_cell("euler_explorer()",
                                                                   outputs=[printed, fallback, shown])])
    assert is_fallback(fallback) and not is_fallback(shown) and not is_fallback(printed)
    se.publish(nb, tmp_path / "assets", "assets", stem="01_euler")
    outputs = nb.cells[1].outputs
    assert outputs == [printed, shown] and "ck-static-explorer" in shown.data["text/html"]
