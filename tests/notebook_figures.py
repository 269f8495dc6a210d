"""Every figure a chapter notebook shows, checked inside the kernel that runs the notebook.

`PRELUDE`, run as a notebook's first cell, gives every figure and every explorer it displays one
more output: the report of `figure_checks.figure_report(fig)` as JSON, under `REPORT`
(`coursekit.tools.site_figures.add_output`, the mechanism the website uses for its figures'
descriptions). tests/executed_chapters.py executes the chapters once with it; `figure_reports(nb)`
reads an executed notebook whose first cell was the prelude: one entry per displayed image, its
cell, and its report (None when it carried none); `text_outputs(nb)` the text the same run printed
or showed.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["REPORT", "PRELUDE", "figure_reports", "text_outputs"]

#: the media type of the reports
REPORT = "application/x-coursekit-figure-report+json"

#: the first cell of a notebook whose figures are to be checked
PRELUDE = f"""\
import json as _json
import sys as _sys
_sys.path.insert(0, {str(Path(__file__).parent)!r})
import coursekit.tools.site_figures as _site_figures
from figure_checks import figure_report as _figure_report
_site_figures.add_output(get_ipython(), {REPORT!r}, lambda fig: _json.dumps(_figure_report(fig)), explorers=True)
"""


def figure_reports(nb) -> list[dict]:
    """[{"cell": index in the notebook without its prelude, "report": dict or None}] for each image
    the executed notebook `nb` shows."""
    assert PRELUDE in nb.cells[0].source, "the notebook did not run the figure checks' prelude first"
    out = []
    for index, cell in enumerate(nb.cells[1:]):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if "image/png" in data:
                report = data.get(REPORT)
                out.append({"cell": index, "report": json.loads(report) if isinstance(report, str) else report})
    return out


def text_outputs(nb) -> list[tuple[int, str]]:
    """[(cell index in the notebook without its prelude, text)] for each text the executed notebook
    `nb` printed or showed as text (not a figure's)."""
    assert PRELUDE in nb.cells[0].source, "the notebook did not run the figure checks' prelude first"
    out = []
    for index, cell in enumerate(nb.cells[1:]):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            text = output.get("text") or ("" if "image/png" in data else data.get("text/plain", ""))
            if text:
                out.append((index, "".join(text)))
    return out
