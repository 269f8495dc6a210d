"""What the open-loop plans of `trajectory` (2.73) and `flatness` (2.88)-(2.89) share."""

from __future__ import annotations

from math import isfinite

import numpy as np

from ._validation import as_scalar, time_grid

__all__ = ["PLAN_RTOL", "input_time", "plan_grid"]


def input_time(t, horizon: float) -> float:
    """One time for a plan's ``input(t, x)``, clipped to [0, T]; checked unless a finite float.

    An ODE solver passes a finite float at every step, so that case skips the checks.
    """
    tt = t if isinstance(t, float) and isfinite(t) else as_scalar(t, "t")
    return min(max(tt, 0.0), horizon)


def plan_grid(horizon: float, samples) -> np.ndarray:
    """The plot grid of a plan: `samples` (>= 2) times on [0, T]."""
    return time_grid(horizon, samples, t_end_name="T", max_span=None)


# A plan counts as landing when its own x(0), x(T) and the simulated x(T) are within 1e-6 of
# the task's size max(|x0|, |xT|). Rounding moves them by ~1e-15 of the largest state on the
# way, so this holds while the plan stays within ~1e8 times the task's size (the notes'
# examples: < 10; random 8-state systems with T = 1: ~1e6); 12 random states pass 1e10.
PLAN_RTOL = 1e-6
