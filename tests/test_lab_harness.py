"""The browser harness's reading of the kernel's stderr (`lab_harness.stderr_lines`), without a
browser: the kernel cuts its stream into messages wherever it flushes, and the widget manager's
refused control comm must be left out however its lines arrive. Of the page's uncaught errors,
only JupyterLab's cancelled subshell request is set aside (`lab_harness.teardown_page_error`).
In Chromium: axe-core, left to check one token of highlighted code per look and ground, still
finds every faint one."""

from __future__ import annotations

import pytest

import lab_harness as lab_h

_REFUSED = "No such comm target registered: jupyter.widget.control\n"


def test_a_line_split_over_several_messages_is_one_line():
    assert lab_h.stderr_lines(["stderr from the kernel", "\n"], set()) == ["stderr from the kernel"]
    assert lab_h.stderr_lines(["stderr ", "from the ", "kernel\nsecond"], set()) == [
        "stderr from the kernel", "second"]


def test_the_refused_control_comm_is_left_out_in_either_order_and_however_split():
    comms = {"abc123"}
    for chunks in (["No such comm: abc123\n", _REFUSED], [_REFUSED, "No such comm: abc123\n"],
                   ["No such comm target registered: ", "jupyter.widget.control\nNo such comm: ab",
                    "c123\n"]):
        assert lab_h.stderr_lines(chunks, comms) == [], chunks


def test_other_lines_around_the_refusal_are_kept():
    chunks = [_REFUSED, "Traceback (most recent call last):\n", "No such comm: abc123\n",
              "No such comm: other\n"]
    assert lab_h.stderr_lines(chunks, {"abc123"}) == [
        "Traceback (most recent call last):", "No such comm: other"]
    assert lab_h.stderr_lines(["No such comm: abc123\n"], set()) == ["No such comm: abc123"]


def test_only_jupyterlabs_cancelled_subshell_request_counts_as_teardown():
    cancelled = "Canceled future for create_subshell_request message before replies were done"
    assert lab_h.teardown_page_error(cancelled)
    assert lab_h.teardown_page_error(f"Error: {cancelled}\n")
    for other in ("Error: Canceled future for execute_request message before replies were done",
                  f"TypeError: {cancelled}", f"{cancelled}; then the widget failed",
                  "Error: widget model not found", ""):
        assert not lab_h.teardown_page_error(other), other


# axe-core on highlighted code (a browser is needed) ------------------------------------------

#: Pygments' markup: 300 lines of a good token, then a faint one; the good token once more on a
#: dark highlighted line (the same look on another ground); a second block narrower than its line,
#: whose first ``k`` token is cut off by the block's scroll box
_CODE_PAGE = """<!doctype html><html lang="en"><head><title>code</title><style>
.highlight pre { background: #fff; color: #000; margin: 0 }
.highlight .n { color: #222 } .highlight .c { color: #bbb } .highlight .k { color: #008 }
.highlight .hll { background: #333; display: block }
#narrow pre { width: 12em; overflow: auto }
</style></head><body><main>
<div class="highlight"><pre>{lines}<span class="c">faint comment</span>
<span class="hll"><span class="n">dark_ground</span></span></pre></div>
<div class="highlight" id="narrow"><pre tabindex="0"><span class="n">a_very_long_name_that_runs_past_the_box</span> \
<span class="k">cut</span>
<span class="k">seen</span> <span class="k">again</span></pre></div>
</main></body></html>""".replace("{lines}", '<span class="n">name</span>\n' * 300)


@pytest.fixture(scope="module")
def code_page():
    reason = lab_h.missing_reason()
    if reason:
        pytest.skip(reason)
    with lab_h.launched_chromium() as browser:
        page = browser.new_page()
        page.set_content(_CODE_PAGE)
        yield page


@pytest.mark.browser
def test_repeated_code_tokens_are_left_to_the_one_axe_checks_for_their_look(code_page):
    marked = code_page.evaluate(lab_h._MARK_REPEATED_CODE_JS, "main")
    kept = code_page.evaluate("Array.from(document.querySelectorAll("
                              "'.highlight span:not(:has(*)):not([data-ck-axe-repeat])'), s => s.textContent)")
    # one "name" of each ground; the cut-off "cut" does not stand for its look, "seen" does
    assert kept == ["name", "faint comment", "dark_ground", "cut", "seen"], kept
    assert marked == 299 + 1 + 1          # the other names, the long name, "again"
    code_page.evaluate("for (const s of document.querySelectorAll('[data-ck-axe-repeat]')) "
                       "s.removeAttribute('data-ck-axe-repeat')")


@pytest.mark.browser
def test_axe_still_finds_faint_code_and_code_on_a_ground_of_its_own(code_page):
    found = lab_h.axe_violations(code_page, "main", lab_h.axe_source())
    assert len(found) == 1 and found[0].startswith("color-contrast:") and "(2 elements" in found[0], found
    assert code_page.evaluate("document.querySelectorAll('[data-ck-axe-repeat]').length") == 0
