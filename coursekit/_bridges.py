"""Bridges to python-control and SciPy: the same (A, B, C, D, dt) in another library.

Students who go on from the course reach for python-control (``control.StateSpace``)
or SciPy (``scipy.signal.StateSpace``). These functions copy the four matrices of (1.24)
and the time base across, so ``StateSpace.from_control(sys.to_control())`` and
``StateSpace.from_scipy(sys.to_scipy())`` give back the very same numbers (the matrices
are copied, never recomputed). They are reached through the methods
``StateSpace.from_control``, ``StateSpace.to_control``, ``StateSpace.from_scipy`` and
``StateSpace.to_scipy``.

Time bases. coursekit: ``dt=None`` continuous, ``dt > 0`` the sampling period.
python-control: ``dt=0`` continuous, ``dt > 0`` the sampling period, ``dt=True`` discrete
with an unspecified period, ``dt=None`` unspecified (either). SciPy: ``dt=None``
continuous, ``dt > 0`` or ``dt=True`` (unspecified period) discrete. Mapping:

- continuous (control ``0``, SciPy ``None``) <-> coursekit ``None``;
- a period ``dt > 0`` <-> the same ``dt``;
- an unspecified period (``True``) -> ``dt=1``: time counted in samples, as
  `difference_to_ss` does; going back gives ``dt=1``;
- python-control's unspecified time base (``None``, e.g. a static gain) -> continuous.

Signal names (state, input, output labels) have no place in coursekit's `StateSpace`
and are not carried over; the system's own name is (python-control's generic names
such as ``sys[3]`` are dropped). Transfer functions and nonlinear systems are refused
with a message that says how to get a state-space model first: a transfer function has
many realizations, and which one to take is the user's choice, not the bridge's.

The sign convention of the gains is *not* a matter for the bridge: coursekit's
``place`` returns K for u = K x (3.17), python-control's and SciPy's the gain for
u = -K x, i.e. minus coursekit's (chapter 3 shows both side by side).

python-control is optional: it is imported only inside `from_control` / `to_control`.
"""

from __future__ import annotations

import re

import numpy as np

# used through StateSpace's methods (and `as_system`); none is a top-level name of coursekit
__all__ = ["realization_hint", "from_control", "to_control", "from_scipy", "to_scipy"]

_GENERIC_CONTROL_NAME = re.compile(r"sys\[\d+\]")


def _import_control():
    """python-control, or an ImportError that says how to install it."""
    try:
        import control
    except ImportError as err:
        raise ImportError(
            "The python-control bridge needs the package python-control, which coursekit "
            "does not install: run `pip install control` in the environment of this kernel, "
            "then restart the kernel."
        ) from err
    return control


def _dt_to_coursekit(dt, library: str) -> float | None:
    """coursekit's dt for a time base of python-control or SciPy (see the module docstring)."""
    if dt is True:
        return 1.0  # discrete with an unspecified period: time counted in samples
    if dt is None or dt is False:
        return None  # scipy: continuous; control: unspecified, taken as continuous
    try:
        value = float(dt)
    except (TypeError, ValueError):
        raise ValueError(
            f"the {library} system has a time base dt={dt!r} that is neither continuous "
            "nor a sampling period; expected 0/None (continuous), a number > 0 or True."
        ) from None
    return None if value == 0 else value  # control: dt=0 is continuous


def _copy(matrix) -> np.ndarray:
    # np.array copies: the new system never shares memory with the one it came from
    return np.array(matrix, dtype=float, copy=True)


def _refuse(sys, library: str, hint: str) -> TypeError:
    return TypeError(
        f"sys must be a {library} state-space system: received {type(sys).__module__}."
        f"{type(sys).__name__}. {hint}"
    )


def _other_hint(sys, constructor: str) -> str:
    """What to do with an object that belongs to another library (or to none)."""
    module = type(sys).__module__.split(".")[0]
    if module == "coursekit":
        return "It already is a coursekit object: use it as it is."
    if module == "scipy":
        return "For scipy.signal systems use StateSpace.from_scipy."
    if module == "control":
        return "For python-control systems use StateSpace.from_control."
    return f"Build one with {constructor}, or pass the matrices to StateSpace(A, B, C, D, dt)."


def realization_hint(sys) -> str:
    """How to get a state-space model from a python-control or SciPy system that is not one."""
    if type(sys).__module__.split(".")[0] == "scipy":
        return ("A transfer function has many state-space realizations: choose one, "
                "e.g. `sys.to_ss()`, and pass that.")
    if type(sys).__name__ == "TransferFunction":
        return ("A transfer function has many state-space realizations: choose one, "
                "e.g. `control.ss(G)`, and pass that.")
    return ("Only linear state-space systems can be converted; linearize a nonlinear "
            "system first (`sys.linearize(xeq, ueq)` or coursekit's `linearize`).")


def from_control(sys, cls):
    """coursekit `StateSpace` with the matrices and time base of a python-control system.

    `cls` is coursekit's StateSpace class, passed in by the classmethod
    `StateSpace.from_control` so that this module does not import `systems`.

    Accepts a ``control.StateSpace`` (MIMO, with or without inputs). The matrices are
    copied exactly; the time base is mapped as the module docstring says (dt=0 ->
    continuous, dt=True -> dt=1, dt=None -> continuous). Raises TypeError for anything
    else, saying how to get a state-space model (``control.ss(G)`` for a transfer
    function), and ImportError naming ``pip install control`` when python-control is missing.
    """
    control = _import_control()
    if not isinstance(sys, control.StateSpace):
        hint = realization_hint(sys) if isinstance(sys, control.InputOutputSystem) else \
            _other_hint(sys, "control.ss(A, B, C, D)")
        raise _refuse(sys, "python-control", hint)
    if sys.nstates == 0:
        raise ValueError(
            "sys has no states (a static gain D): coursekit's StateSpace needs n >= 1; "
            "use the matrix sys.D directly."
        )
    name = "" if sys.name is None or _GENERIC_CONTROL_NAME.fullmatch(sys.name) else sys.name
    return cls(_copy(sys.A), _copy(sys.B), _copy(sys.C), _copy(sys.D),
                      dt=_dt_to_coursekit(sys.dt, "python-control"), name=name)


def to_control(ss):
    """python-control ``StateSpace`` with the matrices, time base and name of `ss`.

    Continuous time becomes python-control's ``dt=0``, a sampling period stays itself.
    The matrices are copied exactly. Raises ImportError naming ``pip install control``
    when python-control is missing, and ValueError for a system without inputs that has
    a single state or a single output, which python-control cannot represent (its empty
    1x0 B or D matrix becomes 0x0); systems without inputs and with n, p >= 2 convert.
    """
    control = _import_control()
    dt = 0 if ss.dt is None else ss.dt
    try:
        return control.StateSpace(_copy(ss.A), _copy(ss.B), _copy(ss.C), _copy(ss.D), dt,
                                  name=ss.name or None)
    except ValueError as err:
        if ss.m > 0:
            raise
        # python-control's _ssmatrix turns an empty 1x0 matrix into 0x0 and then rejects it
        raise ValueError(
            f"python-control {control.__version__} cannot hold this system without inputs: it "
            f"has {ss.n} state(s) and {ss.p} output(s), and python-control stores the empty "
            f"{ss.n}x0 B and {ss.p}x0 D only when they have at least 2 rows ({err}). Give the "
            "system one input that does nothing, StateSpace(A, np.zeros((n, 1)), C, dt=dt), "
            "and convert that."
        ) from err


def from_scipy(sys, cls):
    """coursekit `StateSpace` (`cls`, as for `from_control`) with the matrices and time base of a ``scipy.signal`` system.

    Accepts ``scipy.signal.StateSpace`` objects, continuous (``dt=None``) or discrete
    (``dt`` a period, or True -> dt=1). The matrices are copied exactly. A
    ``TransferFunction`` or ``ZerosPolesGain`` is refused (TypeError) with the hint
    ``sys.to_ss()``: choosing its realization is the user's call.
    """
    import scipy.signal as signal

    if not isinstance(sys, signal.StateSpace):
        hint = realization_hint(sys) if isinstance(sys, (signal.lti, signal.dlti)) else \
            _other_hint(sys, "scipy.signal.StateSpace(A, B, C, D)")
        raise _refuse(sys, "scipy.signal", hint)
    return cls(_copy(sys.A), _copy(sys.B), _copy(sys.C), _copy(sys.D),
                      dt=_dt_to_coursekit(sys.dt, "scipy.signal"))


def to_scipy(ss):
    """``scipy.signal.StateSpace`` with the matrices and time base of `ss` (copied exactly).

    Continuous time gives SciPy's continuous ``StateSpace`` (``dt=None``), a sampling
    period its discrete one with that ``dt``. SciPy has no system names: the name is dropped.
    """
    import scipy.signal as signal

    matrices = (_copy(ss.A), _copy(ss.B), _copy(ss.C), _copy(ss.D))
    if ss.dt is None:
        return signal.StateSpace(*matrices)
    return signal.StateSpace(*matrices, dt=ss.dt)
