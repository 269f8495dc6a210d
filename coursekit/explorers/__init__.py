"""Interactive explorers used in the notebooks, one module per chapter (``ch1``, ``ch2``, ...).

Each explorer is a pure ``compute`` function plus a thin `Explorer` built by a ``*_explorer()``
function. The kit for writing one (docs/extending.md): `Explorer`, its controls `slider`,
`int_slider` and `dropdown`, and `rescale`, which fits an axes' limits (module ``limits``).
"""

from ._base import Explorer, dropdown, int_slider, slider
from .limits import rescale

__all__ = ["Explorer", "slider", "int_slider", "dropdown", "rescale"]
