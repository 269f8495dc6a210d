"""Combining two linear state-space systems into one (section 1.5).

`cascade` connects the output of one system to the input of the other
(1.34)-(1.39); `feedback` also feeds the second system's output back to the
first one's input (1.40). The state of the combination is ``[x1; x2]``.
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._validation import as_scalar
from .systems import StateSpace

__all__ = ["cascade", "feedback"]


def _linear_pair(sys1, sys2, *, purpose: str) -> tuple[StateSpace, StateSpace, float | None]:
    """(sys1, sys2, dt): both as StateSpace (`as_system`), checked to share one time base."""
    sys1, sys2 = (as_system(sys, name, kind="linear", hint=f"{purpose} combines linear systems; "
                            "combinations of nonlinear systems are written by hand as one NonlinearSystem.")
                  for name, sys in (("sys1", sys1), ("sys2", sys2)))
    if sys1.dt != sys2.dt:
        raise ValueError(
            f"sys1 and sys2 must both be continuous or both discrete with the same dt: "
            f"received dt={sys1.dt} and dt={sys2.dt}."
        )
    return sys1, sys2, sys1.dt


def _check_sizes(sys_from: StateSpace, sys_to: StateSpace, from_name: str, to_name: str) -> None:
    """The outputs of sys_from feed the inputs of sys_to: their numbers must agree."""
    if sys_from.p != sys_to.m:
        raise ValueError(
            f"{to_name} has the wrong number of inputs: received a system with m={sys_to.m}, "
            f"expected m={sys_from.p} (one per output of {from_name}, which has p={sys_from.p}). "
            f"Choose the C matrix of {from_name} so that it outputs what {to_name} takes in."
        )


def cascade(sys1, sys2) -> StateSpace:
    """Series connection u -> sys1 -> sys2 -> y, with state [x1; x2].

    The output ``y1 = C1 x1 + D1 u`` of `sys1` is the input of `sys2`, so

    ``x1' = A1 x1 + B1 u``,
    ``x2' = A2 x2 + B2 C1 x1 + B2 D1 u``,
    ``y   = D2 C1 x1 + C2 x2 + D2 D1 u``.

    With ``C1 = I`` and ``D1 = 0`` (the input of sys2 is the state x1, (1.35))
    this is (1.38). The other order of (1.39) is ``cascade(sys2, sys1)``,
    whose state is then ``[x2; x1]``.
    """
    sys1, sys2, dt = _linear_pair(sys1, sys2, purpose="cascade")
    _check_sizes(sys1, sys2, "sys1", "sys2")
    A1, B1, C1, D1 = sys1.A, sys1.B, sys1.C, sys1.D
    A2, B2, C2, D2 = sys2.A, sys2.B, sys2.C, sys2.D
    # (1.38) generalised: [x1'; x2'] = [[A1, 0], [B2 C1, A2]] [x1; x2] + [B1; B2 D1] u
    A = np.block([[A1, np.zeros((sys1.n, sys2.n))], [B2 @ C1, A2]])
    B = np.vstack([B1, B2 @ D1])
    # y = y2 = C2 x2 + D2 (C1 x1 + D1 u)
    C = np.hstack([D2 @ C1, C2])
    D = D2 @ D1
    return StateSpace(A, B, C, D, dt=dt, name=_joined(sys1, sys2, "->"))


def feedback(sys1, sys2, sign: float = +1) -> StateSpace:
    """Feedback connection (1.40): sys2 measures y1 and feeds back into sys1.

    The connections are ``u1 = r + sign * y2`` and ``u2 = y1``; the combined
    system has input r, output y1 and state [x1; x2]. ``sign=+1`` is the
    notes' convention (compare u = K x, 3.17); ``sign=-1`` is the classical
    negative feedback.

    When both systems have a feedthrough (D1, D2 not zero) the loop is
    algebraic: ``y1 = C1 x1 + D1 (r + sign (C2 x2 + D2 y1))`` is solved for y1,
    which needs ``I - sign D1 D2`` to be invertible (a ValueError says so
    otherwise). With ``C1 = I, C2 = I, D1 = D2 = 0`` the matrix of the result
    is ``[[A1, B1], [B2, A2]]``, i.e. (1.40).
    """
    sys1, sys2, dt = _linear_pair(sys1, sys2, purpose="feedback")
    sign = as_scalar(sign, "sign")
    if sign not in (1.0, -1.0):
        raise ValueError(f"sign must be +1 or -1: received {sign!r}.")
    _check_sizes(sys1, sys2, "sys1", "sys2")
    _check_sizes(sys2, sys1, "sys2", "sys1")
    A1, B1, C1, D1 = sys1.A, sys1.B, sys1.C, sys1.D
    A2, B2, C2, D2 = sys2.A, sys2.B, sys2.C, sys2.D
    loop = np.eye(sys1.p) - sign * D1 @ D2
    if np.linalg.cond(loop) > 1e12:
        raise ValueError(
            "sys1 and sys2 form an algebraic loop that has no solution: I - sign * D1 @ D2 is "
            f"singular (D1 D2 = {np.array2string(D1 @ D2, precision=4)}, sign={sign:+g}). "
            "Give one of the systems D = 0, or change the sign."
        )
    M = np.linalg.inv(loop)
    # y1 = Cy x + Dy r, from (I - sign D1 D2) y1 = C1 x1 + sign D1 C2 x2 + D1 r
    Cy = M @ np.hstack([C1, sign * D1 @ C2])
    Dy = M @ D1
    # u1 = r + sign (C2 x2 + D2 y1) = Cu x + Du r
    Cu = sign * (np.hstack([np.zeros((sys2.p, sys1.n)), C2]) + D2 @ Cy)
    Du = np.eye(sys1.m) + sign * D2 @ Dy
    # (1.40) generalised: x1' = A1 x1 + B1 u1, x2' = A2 x2 + B2 y1
    A = np.block([[A1, np.zeros((sys1.n, sys2.n))], [np.zeros((sys2.n, sys1.n)), A2]])
    A = A + np.vstack([B1 @ Cu, B2 @ Cy])
    B = np.vstack([B1 @ Du, B2 @ Dy])
    return StateSpace(A, B, Cy, Dy, dt=dt, name=_joined(sys1, sys2, "<->"))


def _joined(sys1: StateSpace, sys2: StateSpace, arrow: str) -> str:
    return f"{sys1.name or 'sys1'} {arrow} {sys2.name or 'sys2'}"
