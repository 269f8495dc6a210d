"""What an explorer shows in a notebook reopened after a save: its figure, not a widget error.

JupyterLab and Notebook 7 save a widget's view in the notebook, not its state; reopened with a
new kernel (or none), ipywidgets' renderer finds no model and shows "Error displaying widget:
model not found" (or "Loading widget..."), never another type of the same output. Saving the
widget state (ipywidgets' ``saveState`` setting) is not restored without a kernel in JupyterLab
4 (jupyterlab/jupyterlab#15361) and writes metadata into every notebook saved. So an explorer
shown in a kernel publishes, just before its widget, an HTML output: its figure for the settings
it was shown with, the figure's text alternative, the readout and a line saying that running
the cell makes it live. Its style sheet shows either that output or the widget: the fallback is
hidden while the output after it holds a live explorer, and that output while it holds none.
The static builds (website, slides) drop it (`is_fallback`): they show their own static explorer.
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


def publish_fallback(explorer) -> None:
    """Publish the fallback of `explorer` as an output of the running cell (in a kernel only)."""
    from IPython import get_ipython
    shell = get_ipython()
    if shell is None or getattr(shell, "kernel", None) is None:
        return
    from IPython.display import publish_display_data
    content = fallback_html(explorer.title, explorer.static_png(), explorer.alt, explorer.text)
    publish_display_data({"text/html": content}, metadata={FALLBACK: True})


def is_fallback(output) -> bool:
    """Whether the notebook output `output` (a dict) is an explorer's fallback."""
    return bool(output.get("metadata", {}).get(FALLBACK))
