"""Exercises of chapter 3 (stability and state feedback).

1. `STABILITY`: decide which of four systems x' = A x are stable (section 3.2.2).
2. `PLACE_CCF`: the gain K of a system in CCF from (3.44).
3. `PLACE_GENERAL`: the gain K of a 2x2 system not in CCF, through z = T x (3.46)-(3.47).
4. `LINEARIZE`: the linearization of the damped pendulum at the upright equilibrium (3.67)-(3.70).

The course's convention is u = K x with closed loop A + B K (3.17)-(3.21).
"""

from __future__ import annotations

import numpy as np

from .. import models
from ..linearization import linearize
from ..placement import place
from ..stability import is_stable
from ._catalog import exercise
from ._data import ExerciseData
from ._feedback import CheckResult, Report, matrix_feedback, read_decision

__all__ = [
    "STABILITY", "check_stability",
    "PLACE_CCF", "check_gain_ccf",
    "PLACE_GENERAL", "check_gain_general",
    "LINEARIZE", "check_pendulum_linearization",
]

#: four continuous-time systems x' = A x (A1 ... A4); which are (asymptotically) stable?
STABILITY = ExerciseData({
    "A1": ((-1.0, 2.0), (-2.0, -1.0)),
    "A2": ((1.0, 2.0), (3.0, -4.0)),
    "A3": ((0.0, 1.0), (-4.0, 0.0)),
    "A4": ((-2.0, 5.0, 0.0), (0.0, -1.0, 7.0), (0.0, 0.0, -0.5)),
})

#: x' = A x + B u in CCF (last-row form (2.16)) and the wanted closed-loop poles.
PLACE_CCF = ExerciseData({"A": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (4.0, -1.0, 2.0)),
                          "B": ((0.0,), (0.0,), (1.0,)), "poles": (-1.0, -2.0, -4.0)})

#: a 2x2 system that is not in CCF and the wanted closed-loop poles.
PLACE_GENERAL = ExerciseData({"A": ((1.0, 2.0), (3.0, 0.0)), "B": ((0.0,), (1.0,)), "poles": (-2.0, -3.0)})

#: damped pendulum (1.8), linearized at the upright equilibrium x* = [pi, 0], u* = 0.
LINEARIZE = ExerciseData({"m": 0.5, "l": 0.8, "g": 9.81, "d_theta": 0.3, "x_eq": (np.pi, 0.0)})


@exercise("3.1", "stable or not?",
          section="3.2 Stability of linear time-invariant systems")
def check_stability(answers) -> CheckResult:
    """Check a list of four True/False: is x' = A x stable, for A1 ... A4 of `STABILITY`?"""
    report = Report("stability")
    matrices = list(STABILITY.values())
    truth = [is_stable(A) for A in matrices]   # every eigenvalue strictly in the left half-plane
    if isinstance(answers, (str, bytes)) or not hasattr(answers, "__len__"):
        report.add(f"answers must be a list of {len(truth)} True/False, one per matrix: "
                   f"received {answers!r}.")
        return report.show("")
    if len(answers) != len(truth):
        report.add(f"answers must have {len(truth)} entries, one per matrix: yours has {len(answers)}.")
        return report.show("")
    for i, (answer, right) in enumerate(zip(answers, truth), start=1):
        decision = read_decision(answer, f"answer {i}", report)
        if decision is None or decision == right:
            continue
        A = np.array(matrices[i - 1])
        if np.allclose(np.linalg.eigvals(A).real.max(), 0, atol=1e-9):
            hint = ("an eigenvalue with real part 0 (on the imaginary axis) is not strictly "
                    "negative: the state oscillates or stays, it does not go to 0.")
        elif np.trace(A) < 0:
            hint = ("a negative trace (sum of the eigenvalues) does not make every eigenvalue "
                    "negative: compute them.")
        else:
            hint = "compute the eigenvalues: for a triangular matrix they are the diagonal entries."
        report.add(f"the matrix A{i} is decided wrongly: stable means every eigenvalue of A has a "
                   f"strictly negative real part (section 3.2.2); {hint}")
    return report.show("each decision follows from the real parts of the eigenvalues (3.2.2).")


def _gain_feedback(K, A: np.ndarray, B: np.ndarray, poles, report: Report, *, hint: str) -> bool:
    """Compare a state-feedback gain with the course's K (u = K x), explaining the usual slips."""
    K_ok = place(A, B, poles)
    ok = matrix_feedback(K, K_ok, "K", report, known_mistakes=[
        (-K_ok, "your K has the MATLAB sign: the course uses u = K x with closed loop A + B K (3.17), "
                "so K is minus MATLAB's and SciPy's place()."),
    ], shape_hint="K is m x n (3.19): one row per input, one column per state.", entry_hint=hint)
    if not ok and len(report.problems) == 1 and "off" in report.problems[0]:
        try:
            Kst = np.asarray(K, dtype=float).reshape(K_ok.shape)
            eig = np.sort_complex(np.linalg.eigvals(A + B @ Kst))
            report.add("with your K the closed loop A + B K has the eigenvalues "
                       + ", ".join(f"{e.real:.3g}" + (f"{e.imag:+.3g}j" if abs(e.imag) > 1e-9 else "")
                                   for e in eig) + ".")
        except (TypeError, ValueError):
            pass
    return ok


def _check_gain(K, data: ExerciseData, title: str, hint: str, praise: str) -> CheckResult:
    report = Report(title)
    _gain_feedback(K, np.array(data["A"]), np.array(data["B"]), data["poles"], report, hint=hint)
    return report.show(praise)


@exercise("3.2", "pole placement for a CCF",
          section="3.3 Stabilization of LTI systems by state feedback")
def check_gain_ccf(K) -> CheckResult:
    """Check the gain K (u = K x) placing the poles of `PLACE_CCF`, from (3.42)-(3.44)."""
    return _check_gain(K, PLACE_CCF, "pole placement in CCF",
                       hint="Read a0, a1, a2 from the last row of A (it is -[a0 a1 a2]), expand "
                            "p(s) = (s - p1)(s - p2)(s - p3) and use k_i = a_(i-1) - p_(i-1) (3.44).",
                       praise="eig(A + B K) are the wanted poles (3.44).")


@exercise("3.3", "pole placement, the general case",
          section="3.3 Stabilization of LTI systems by state feedback")
def check_gain_general(K) -> CheckResult:
    """Check the gain K (u = K x) placing the poles of `PLACE_GENERAL` via the CCF (3.46)-(3.47)."""
    return _check_gain(K, PLACE_GENERAL, "pole placement, general case",
                       hint="Find T (2.65), the CCF's a~ from T A T^-1, K~ from (3.46), then "
                            "K = K~ T (3.47): the gain acts on x, not on z.",
                       praise="eig(A + B K) are the wanted poles, K = K~ T (3.47).")


@exercise("3.4", "linearize the pendulum at the top",
          section="3.4 Linear state feedback for nonlinear systems")
def check_pendulum_linearization(A, B) -> CheckResult:
    """Check (A, B) of the pendulum `LINEARIZE` linearized at theta = pi, theta' = 0 (3.67)."""
    report = Report("linearized pendulum")
    m, l, g, d = (LINEARIZE[k] for k in ("m", "l", "g", "d_theta"))
    # (3.67): A = df/dx, B = df/du at x* = [pi, 0], u* = 0
    A_ok, B_ok = linearize(models.pendulum(m=m, l=l, g=g, d_theta=d), LINEARIZE["x_eq"], [0.0])
    matrix_feedback(A, A_ok, "A", report, known_mistakes=[
        ([[0, 1], [-g / l, -d / m]], "A: that is the linearization at the hanging equilibrium "
                                     "theta = 0; at theta = pi, cos(theta) = -1 (3.69)-(3.70)."),
        ([[0, 1], [g / l, 0]], "A: the damping term -(d_theta/m) theta' of (1.8) is missing."),
        ([[0, 1], [g / l, -d / (m * l**2)]], "A: after dividing (1.8) by m l^2 the damping "
                                             "coefficient is d_theta / m."),
    ], entry_hint="A is the Jacobian df/dx (3.65) evaluated at x* = [pi, 0].")
    matrix_feedback(B, B_ok, "B", report, known_mistakes=[
        ([[0], [1]], "B: the torque enters theta'' divided by m l^2 (1.8)."),
    ], shape_hint="B must be a column (n x 1): df/du.")
    return report.show("A and B are the Jacobians at the upright equilibrium (3.67).")
