"""coursekit: the Python companion to the state-space control course.

Every public name of the submodules listed below is available directly as
``coursekit.<name>``. Heavy libraries (SciPy submodules, sympy, matplotlib,
ipywidgets) are imported inside the functions that use them, so that
``import coursekit`` stays fast.

Conventions (see the README): state feedback ``u = K x`` with closed loop
``A + B K``; observer error dynamics ``A - L C``; polynomials as ascending
coefficient arrays ``[a_0, ..., a_{n-1}]``; time series time-major.
"""

from importlib import import_module as _import_module

__version__ = "0.1.0"

# One module per job; each line lists the modules of one chapter of the notes.
_MODULES = (
    # chapter 1: representations
    "systems", "simulation", "realization", "interconnect", "plotting",
    # chapter 2: controllability and open-loop control
    "controllability", "trajectory", "flatness", "symbolic",
    # chapter 3: stability and state feedback
    "placement", "stability", "equilibria", "linearization", "controllers",
    # chapter 4: observability and observers
    "observability", "observers", "kalman", "kalman_bucy", "ekf", "kalman_discrete", "noise",
    # course tools: figure style and layout
    "style", "describe",
    # course tools: environment check (exercises stay the subpackage coursekit.exercises)
    "environment_check", "diagnostics",
)

__all__ = ["models"]
for _name in _MODULES:
    _module = _import_module(f".{_name}", __name__)
    for _public in _module.__all__:
        globals()[_public] = getattr(_module, _public)
    __all__ += list(_module.__all__)
del _name, _module, _public


def __getattr__(name):
    # `coursekit.models` is loaded on first use
    if name == "models":
        return _import_module(".models", __name__)
    raise AttributeError(f"module 'coursekit' has no attribute {name!r}")
