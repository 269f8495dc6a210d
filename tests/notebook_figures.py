"""Every figure a chapter notebook shows, checked inside the kernel that runs the notebook.

`figure_reports(path)` executes the notebook (nbclient, this interpreter's ipykernel) after a
first cell that gives every figure and every explorer it displays one more output: the report
of `report(fig)` as JSON (`coursekit.tools.site_figures.add_output`, the mechanism the website
uses for its figures' descriptions). Returns one entry per displayed image: its cell, whether
it carried a report, and the report. `text_outputs(path)` gives the text the same run printed or
showed (one execution per notebook and test session serves both).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import nbformat

from kernels import this_python_kernel

__all__ = ["REPORT", "figure_reports", "text_outputs"]

#: the media type of the reports
REPORT = "application/x-coursekit-figure-report+json"

_PRELUDE = """\
import json as _json
import sys as _sys
_sys.path.insert(0, {tests!r})
import coursekit.tools.site_figures as _site_figures
from figure_checks import figure_report as _figure_report
_site_figures.add_output(get_ipython(), {mime!r}, lambda fig: _json.dumps(_figure_report(fig)), explorers=True)
"""


@functools.lru_cache(maxsize=None)
def _executed(path: Path):
    """The notebook at `path` executed after the report prelude, without the prelude's cell."""
    from nbclient import NotebookClient
    nb = nbformat.read(path, as_version=4)
    prelude = _PRELUDE.format(tests=str(Path(__file__).parent), mime=REPORT)
    nb.cells.insert(0, nbformat.v4.new_code_cell(prelude))
    NotebookClient(nb, km=this_python_kernel(), timeout=300,
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    return nb.cells[1:]


def figure_reports(path: Path) -> list[dict]:
    """[{"cell": index in the notebook, "report": dict or None}] for each image the notebook shows."""
    out = []
    for index, cell in enumerate(_executed(Path(path))):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if "image/png" in data:
                report = data.get(REPORT)
                out.append({"cell": index, "report": json.loads(report) if isinstance(report, str) else report})
    return out


def text_outputs(path: Path) -> list[tuple[int, str]]:
    """[(cell index, text)] for each text the notebook printed or showed as text (not a figure's)."""
    out = []
    for index, cell in enumerate(_executed(Path(path))):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            text = output.get("text") or ("" if "image/png" in data else data.get("text/plain", ""))
            if text:
                out.append((index, "".join(text)))
    return out
