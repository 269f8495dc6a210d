"""Stability of linear time-invariant systems (section 3.2) and pole plots.

* `is_stable(A, dt=None)`: the main result of section 3.2.2 -- x' = A x is
  stable exactly when every eigenvalue of A has a negative real part; for
  x(t+1) = A x(t) every eigenvalue must lie strictly inside the unit circle;
* `plot_poles(...)`: the eigenvalues in the complex plane with the stable
  region shaded (left half plane, or unit disc in discrete time).

Eigenvalues of A are the poles of the system: they are the roots of
det(sI - A), the denominator of (3.13).
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._validation import as_dt, as_square, foreign_library
from .systems import StateSpace

__all__ = ["is_stable", "plot_poles", "format_poles"]


def _matrix_and_dt(A, dt):
    """Accept a StateSpace (its own dt unless dt is given) or a square matrix."""
    if isinstance(A, StateSpace) or foreign_library(A):
        sys = as_system(A, "A", kind="linear")
        return sys.A, sys.dt if dt is None else as_dt(dt)
    return as_square(A, "A"), as_dt(dt)


def is_stable(A, dt=None) -> bool:
    """True when x' = A x (or x(t+1) = A x(t) if `dt` is set) is asymptotically stable.

    Implements the main result of section 3.2.2: every eigenvalue lambda of
    A, i.e. every root of det(lambda I - A) = 0, must have Re(lambda) < 0.
    In discrete time (`dt` = sampling period) the condition is |lambda| < 1.
    `A` may also be a `StateSpace`, whose `dt` is then used.

    The test is strict: a pole exactly on the boundary (e.g. the double
    integrator, or a pure oscillator) is *not* stable.
    """
    A, dt = _matrix_and_dt(A, dt)
    lam = np.linalg.eigvals(A)
    if dt is None:
        return bool(np.all(lam.real < 0))
    return bool(np.all(np.abs(lam) < 1))


def _as_pole_sets(poles) -> dict:
    """A dict label -> complex array, from an array or a dict of arrays."""
    if isinstance(poles, dict):
        items = poles.items()
    else:
        items = [("poles", poles)]
    out = {}
    for label, values in items:
        where = "poles" if label == "poles" and not isinstance(poles, dict) else f"poles[{label!r}]"
        if values is None or isinstance(values, (str, bytes)):
            raise ValueError(f"{where} must be a list of numbers: received {values!r}; "
                             "e.g. np.linalg.eigvals(A + B @ K).")
        try:
            arr = np.atleast_1d(np.asarray(values, dtype=complex)).ravel()
        except (TypeError, ValueError):
            raise ValueError(
                f"{where} must be a list of numbers: received {type(values).__name__}."
            ) from None
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{where} contains NaN or infinite entries: {arr.tolist()!r}.")
        if arr.size == 0:
            raise ValueError(f"{where} is empty: pass at least one pole.")
        out[str(label)] = arr
    if not out:
        raise ValueError("poles is empty: pass an array of poles or a dict label -> poles.")
    return out


def plot_poles(poles, *, dt=None, ax=None, title: str | None = None):
    """Plot poles in the complex plane with the stable region shaded.

    Parameters
    ----------
    poles : array or dict
        The poles (e.g. ``np.linalg.eigvals(A + B @ K)``), or a dict
        ``{"open loop": p1, "closed loop": p2}`` to compare several sets.
    dt : float, optional
        None (continuous time): the left half plane is shaded. A sampling
        period: the unit disc is shaded.
    ax : matplotlib Axes, optional
        Draw into this axes; by default a new figure is made with
        `coursekit.style.new_figure`.
    title : str, optional

    Returns ``(fig, ax)``.
    """
    sets = _as_pole_sets(poles)
    dt = as_dt(dt)
    from ._arguments import figure_for
    from .style import PALETTE, curve_style
    fig, ax = figure_for(ax)
    green = PALETTE["bluish green"]
    everything = np.concatenate(list(sets.values()))
    reach = 1.25 * max(1.0, float(np.abs(everything.real).max(initial=0)),
                       float(np.abs(everything.imag).max(initial=0)))
    if dt is None:
        ax.axvspan(-reach, 0, color=green, alpha=0.12, label="stable region (Re < 0)")
    else:
        angle = np.linspace(0, 2 * np.pi, 200)
        ax.fill(np.cos(angle), np.sin(angle), color=green, alpha=0.12, label="stable region (|z| < 1)")
        ax.plot(np.cos(angle), np.sin(angle), color=green, lw=1)
        ax.set_aspect("equal", adjustable="datalim")   # the axes fills its cell, as the layout sets it
    markers = "xo^sd*"
    for i, (label, values) in enumerate(sets.items()):
        ax.plot(values.real, values.imag, markers[i % len(markers)], ms=10, mew=2,
                color=curve_style(i)["color"], fillstyle="none", label=label)
    ax.axhline(0, color="0.5", lw=0.8)
    ax.axvline(0, color="0.5", lw=0.8)
    if dt is None:
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)
    else:
        # equal scales (the unit circle stays round): fixed limits would be overridden
        ax.margins(0)
        ax.update_datalim([(-reach, -reach), (reach, reach)])
        ax.autoscale_view()
    ax.set_xlabel("real part [1/s]" if dt is None else "real part")
    ax.set_ylabel("imaginary part [rad/s]" if dt is None else "imaginary part")
    ax.set_title(title or ("Poles (continuous time)" if dt is None else "Poles (discrete time)"), wrap=True)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig, ax


#: an imaginary part below this fraction of a pole's size is rounding noise (a repeated real pole,
#: such as the double observer pole -s, -s, comes out of eig as -s ± 1e-8 s j)
IMAG_NOISE = 1e-6
_TIMES = {2: "double", 3: "triple"}


def format_poles(poles, digits: int = 3) -> str:
    """Poles (any complex numbers) as short text, e.g. for an explorer's readout:
    ``"-1, -0.5 ± 2j"``, sorted by real part; a conjugate pair is written once, and poles that
    read the same once rounded are written once with their multiplicity (``"-17 (double)"``),
    an imaginary part smaller than `IMAG_NOISE` of the pole's size being rounding noise."""
    try:
        values = np.atleast_1d(np.asarray(poles, dtype=complex)).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"poles must be a list of numbers: received {poles!r}.") from None
    if isinstance(poles, str) or not values.size or not np.all(np.isfinite(values)):
        raise ValueError(f"poles must be a non-empty list of finite numbers: received {poles!r}.")
    values = np.where(np.abs(values.imag) <= IMAG_NOISE * np.abs(values), values.real, values)
    pending, out = sorted(values, key=lambda p: (p.real, -p.imag)), []
    while pending:
        p = pending.pop(0)
        re, im = f"{p.real:.{digits}g}", f"{abs(p.imag):.{digits}g}j"
        pair = next((q for q in pending if p.imag > 0 and np.isclose(q, np.conj(p))), None)
        if pair is not None:
            pending.remove(pair)
        out.append(re if p.imag == 0 else f"{re} ± {im}" if pair is not None
                   else f"{re} {'+' if p.imag > 0 else '-'} {im}")
    return ", ".join(_with_multiplicity(out))


def _with_multiplicity(texts: list[str]) -> list[str]:
    """Equal neighbouring texts once, with how many: ["-17", "-17"] -> ["-17 (double)"]."""
    out: list[str] = []
    for text in texts:
        count = texts.count(text)
        if text not in (o.split(" (")[0] for o in out):
            out.append(text if count == 1 else f"{text} ({_TIMES.get(count, f'x {count}')})")
    return out
