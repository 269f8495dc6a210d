"""The browser side of an explorer: its figure at the screen's own pixel size, and its styling.

`FigureView` is a small anywidget whose script and style sheet are the package-data files
`VIEW_JS` and `VIEW_CSS`. It shows the kernel's PNG at its pixel size over the device pixel
ratio and reports the ratio and the room the figure has when shown and when it changes, so an
untouched explorer costs the kernel nothing. The image carries the text alternative, announced
by a polite live region once a control rests; keys on the controls never reach the notebook.
"""

from __future__ import annotations

from pathlib import Path

import anywidget
import traitlets

__all__ = ["FigureView", "VIEW_JS", "VIEW_CSS"]

#: the widget's script (an ES module) and its style sheet
VIEW_JS, VIEW_CSS = (Path(__file__).with_name(name) for name in ("view.js", "view.css"))


class FigureView(anywidget.AnyWidget):
    """An ``<img>`` at its natural pixel size: ``png``, ``css_width``/``css_height`` and ``alt``
    set by the kernel; ``screen`` (``width``/``height`` of the room in CSS pixels, the pixel
    ``ratio``) set by the browser."""

    _esm = VIEW_JS
    _css = VIEW_CSS
    png = traitlets.Bytes(b"").tag(sync=True)
    css_width = traitlets.Float(0.0).tag(sync=True)
    css_height = traitlets.Float(0.0).tag(sync=True)
    screen = traitlets.Dict({}).tag(sync=True)
    alt = traitlets.Unicode("").tag(sync=True)
