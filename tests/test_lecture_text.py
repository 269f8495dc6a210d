"""Lecture mode enlarges the notebook's own text through a style output (coursekit/notebook_style.py).

The output is checked as a kernel sends it (executed by nbclient, which keeps display ids as
JupyterLab does); the browser test (tests/test_browser.py) measures the text in JupyterLab.
"""

import re

import pytest

import coursekit as ck
from coursekit.notebook_style import LECTURE_TEXT_SIZES, lecture_text_html, show_lecture_text
from coursekit.tools.kernel_metadata import kernelspec_metadata


@pytest.fixture(autouse=True)
def _lecture_mode_off():
    yield
    ck.lecture_mode(False)


def _rules(html: str) -> dict:
    """{selector: declarations} of the one <style> element `html` is."""
    match = re.fullmatch(r"<style [^>]+>\n(.*)</style>", html, re.S)
    assert match, html
    return {sel.strip(): body.strip() for sel, body in re.findall(r"([^{}]+)\{([^}]*)\}", match[1])}


def test_on_sets_jupyterlab_size_variables_on_the_live_notebook_holding_it():
    rules = _rules(lecture_text_html(True))
    enlarge = [body for sel, body in rules.items() if sel.startswith(".jp-NotebookPanel-notebook:has(")]
    assert len(enlarge) == 1
    declared = dict(re.findall(r"(--[\w-]+):\s*([^;]+);", enlarge[0]))
    assert declared == LECTURE_TEXT_SIZES
    for name in ("--jp-content-font-size1", "--jp-code-font-size", "--jp-ui-font-size1", "--jp-widgets-font-size"):
        assert float(declared[name].removesuffix("px")) >= 1.4 * 13, name
    # the rule looks for this very style element (its attribute), so other notebooks keep their sizes
    mark = re.match(r"<style ([^>]+)>", lecture_text_html(True))[1]
    assert f"style[{mark}]" in next(s for s in rules if s.startswith(".jp-NotebookPanel-notebook"))


def test_off_sets_no_size_and_either_state_hides_its_own_output_row():
    assert "--jp-" not in lecture_text_html(False)
    for on in (True, False):
        hide = [sel for sel, body in _rules(lecture_text_html(on)).items() if body == "display: none;"]
        assert len(hide) == 1 and hide[0].startswith(".jp-OutputArea-child:has(style[")
    assert lecture_text_html(True).split(">")[0] != lecture_text_html(False).split(">")[0]


def test_outside_a_notebook_nothing_is_displayed(capsys):
    assert show_lecture_text(True) is False
    ck.lecture_mode()
    ck.lecture_mode(False)
    assert capsys.readouterr() == ("", "")


def _executed(*sources):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in sources])
    nb.metadata["kernelspec"] = kernelspec_metadata()
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    return [cell.outputs for cell in nb.cells]


def test_in_a_kernel_on_displays_the_style_and_off_replaces_it_through_its_display_id():
    on, between, off = _executed("import coursekit as ck\nck.lecture_mode()", "print(ck.is_lecture_mode())",
                                 "ck.lecture_mode(False)")
    # switched off in a later cell: the output of the first cell now holds the "off" style
    assert [o.output_type for o in on] == ["display_data"]
    assert dict(on[0].data) == {"text/html": lecture_text_html(False)}     # no text/plain to print
    assert between[0].text == "True\n"
    assert off == []                                  # the later cell shows nothing of its own


def test_in_a_kernel_on_alone_leaves_the_enlarging_style():
    (on,) = _executed("import coursekit as ck\nck.lecture_mode()")
    assert [dict(o.data) for o in on] == [{"text/html": lecture_text_html(True)}]
