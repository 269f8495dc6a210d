"""What an explorer shows in a notebook reopened after a save: its figure, not a widget error.

A saved notebook keeps a widget's view, not its state; in a trusted notebook ipywidgets' renderer
then shows "model not found", never the PNG of the same output (state saved by JupyterLab's user
setting would show controls with no kernel behind them). So an explorer shown in a kernel first
publishes an HTML output with its figure, text alternative and readout; its style sheet shows either
it or the live widget after it. The static builds (website, slides) drop it (`is_fallback`).
"""

from __future__ import annotations

import base64
import html

__all__ = ["FALLBACK", "fallback_html", "publish_fallback", "is_fallback"]

#: the output metadata key that marks an explorer's fallback output
FALLBACK = "coursekit_explorer_fallback"

#: output areas of JupyterLab and Notebook 7: the fallback, or the live explorer after it
_STYLE = ("<style>.jp-OutputArea-child:has(.ck-explorer-fallback):has(+ .jp-OutputArea-child .ck-explorer),"
          " .jp-OutputArea-child:has(.ck-explorer-fallback) + .jp-OutputArea-child:not(:has(.ck-explorer))"
          " { display: none; }</style>")


def fallback_html(title: str, png: bytes, alt: str, readout: str) -> str:
    """The fallback of an explorer titled `title`: the figure `png` (shown at its pixel size)
    described by `alt`, the `readout` (lines split at ``"\\n"``) and how to make it live."""
    src = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
    lines = "<br>".join(html.escape(line) for line in readout.split("\n")) if readout else ""
    return (f'<div class="ck-explorer-fallback">{_STYLE}<p><b>{html.escape(title)}</b></p>'
            + (f"<p>{lines}</p>" if lines else "")
            + f'<img src="{src}" alt="{html.escape(alt)}" style="max-width: 100%; height: auto">'
            + "<p><i>The figure saved with the notebook: run this cell to move the controls.</i></p></div>")


def publish_fallback(explorer, png: bytes) -> None:
    """Publish the fallback of `explorer`, its figure `png`, as an output of the running cell (in a kernel only)."""
    from IPython import get_ipython
    from IPython.display import publish_display_data
    if getattr(get_ipython(), "kernel", None) is not None:
        publish_display_data({"text/html": fallback_html(explorer.title, png, explorer.alt, explorer.text)},
                             metadata={FALLBACK: True})


def is_fallback(output) -> bool:
    """Whether the notebook output `output` (a dict) is an explorer's fallback."""
    return bool(output.get("metadata", {}).get(FALLBACK))
