"""The browser harness's reading of the kernel's stderr (`lab_harness.stderr_lines`), without a
browser: the kernel cuts its stream into messages wherever it flushes, and the widget manager's
refused control comm must be left out however its lines arrive."""

from __future__ import annotations

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
