"""Interactive explorers used in the notebooks, one module per chapter.

Each explorer is a pure ``compute`` function (tested without a browser) plus
a thin `Explorer` wrapper built by a ``*_explorer()`` function.
"""

from ._base import Explorer, dropdown, int_slider, rescale, slider

__all__ = ["Explorer", "slider", "int_slider", "dropdown", "rescale"]
