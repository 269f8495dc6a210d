"""Exercises of chapter 4 (observability and observers).

1. `OBSV`: compute the observability matrix Wo (4.15).
2. `VEHICLE`: is the vehicle with only a speedometer (4.3) observable? (rank of Wo and decision)
3. `OBSERVER`: the gain L of a 2x2 observer, error dynamics A - L C (4.25)-(4.27).
4. `SEPARATION`: the eigenvalues of the output-feedback loop u = K x^ (4.73).
"""

from __future__ import annotations

import numpy as np

from ..observability import obsv, place_observer
from ..observers import separation_eigenvalues
from ..systems import StateSpace
from ._catalog import exercise
from ._data import ExerciseData
from ._feedback import (CheckResult, Report, matrix_feedback, poles_feedback, rank_decision_feedback,
                        read_poles)

__all__ = [
    "OBSV", "check_obsv_matrix",
    "VEHICLE", "check_vehicle_observability",
    "OBSERVER", "check_observer_gain",
    "SEPARATION", "check_separation_poles",
]

#: x' = A x, y = C x with three states and one measurement.
OBSV = ExerciseData({"A": ((0.0, 1.0, 0.0), (2.0, 0.0, 1.0), (0.0, -1.0, -3.0)),
                     "C": ((1.0, 0.0, 1.0),)})

#: the vehicle (4.1) with a speedometer (4.3): x = [position, velocity], m [kg], d [N s/m].
VEHICLE = ExerciseData({"A": ((0.0, 1.0), (0.0, -0.05)), "C": ((0.0, 1.0),)})

#: a 2x2 system with one measurement and the wanted poles of the estimation error.
OBSERVER = ExerciseData({"A": ((0.0, 1.0), (-2.0, -3.0)), "C": ((1.0, 0.0),), "poles": (-5.0, -6.0)})

#: plant, state-feedback gain (u = K x^) and observer gain of an output-feedback loop.
SEPARATION = ExerciseData({"A": ((0.0, 1.0), (3.0, -2.0)), "B": ((0.0,), (1.0,)), "C": ((1.0, 0.0),),
                           "K": ((-9.0, -3.0),), "L": ((7.0,), (9.0,))})


@exercise("4.1", "the observability matrix",
          section="4.2 Observability and the Kalman criterion")
def check_obsv_matrix(Wo) -> CheckResult:
    """Check the observability matrix Wo = [C; CA; CA^2] of `OBSV` (4.15)."""
    report = Report("observability matrix")
    A, C = np.array(OBSV["A"]), np.array(OBSV["C"])
    Wo_ok = obsv(A, C)   # (4.15): Wo = [C; CA; CA^2]
    matrix_feedback(Wo, Wo_ok, "Wo", report, known_mistakes=[
        (Wo_ok[::-1], "Wo: the rows are in reverse order: C on top, then CA, then CA^2 (4.15)."),
        (np.vstack([C, (A @ C.T).T, (A @ A @ C.T).T]),
         "Wo: the rows are C A^k (row times matrix, A on the right), not (A^k C^T)^T (4.15)."),
    ], shape_hint="Wo stacks the rows C, CA, CA^2 on top of each other (4.15).",
        entry_hint="Compute CA = C @ A and CA^2 = (C @ A) @ A and stack them under C (4.15).")
    return report.show("Wo = [C; CA; CA^2] (4.15).")


@exercise("4.2", "a car with only a speedometer",
          section="4.2 Observability and the Kalman criterion")
def check_vehicle_observability(rank, observable) -> CheckResult:
    """Check the rank of Wo for `VEHICLE` and whether it is observable (section 4.2.3)."""
    report = Report("vehicle observability")
    A, C = np.array(VEHICLE["A"]), np.array(VEHICLE["C"])
    rank_decision_feedback(rank, observable, int(np.linalg.matrix_rank(obsv(A, C))), A.shape[0],
                           report, word="observable",
                           rank_hint="compute C and CA and check whether one row is a multiple "
                                     "of the other.",
                           decision_hint="observable exactly when rank Wo = n (section 4.2.3). "
                                         "Can a speedometer tell where the car started?")
    return report.show("rank Wo decides observability; a speedometer never reveals the position.")


@exercise("4.3", "an observer gain by hand",
          section="4.3 State estimation using observers")
def check_observer_gain(L) -> CheckResult:
    """Check the observer gain L with eig(A - L C) = the poles of `OBSERVER` (4.27)."""
    report = Report("observer gain")
    A, C = np.array(OBSERVER["A"]), np.array(OBSERVER["C"])
    L_ok = place_observer(A, C, OBSERVER["poles"])
    ok = matrix_feedback(L, L_ok, "L", report, known_mistakes=[
        (-L_ok, "L has the wrong sign: the course's estimation error obeys e' = (A - L C) e (4.27); "
                "you placed the eigenvalues of A + L C."),
    ], shape_hint="L must be a column (n x p) (one column per measurement).",
        entry_hint="Write det(sI - (A - L C)) with L = [l1; l2] and match it with "
                   + "".join(f"(s {'+' if p < 0 else '-'} {abs(p):g})" for p in OBSERVER["poles"]) + ".")
    if not ok and len(report.problems) == 1 and "off" in report.problems[0]:
        try:
            Lst = np.asarray(L, dtype=float).reshape(L_ok.shape)
            eig = np.sort(np.linalg.eigvals(A - Lst @ C))
            report.add("with your L the error dynamics A - L C have the eigenvalues "
                       + ", ".join(f"{e:.3g}" for e in eig) + ".")
        except (TypeError, ValueError):
            pass
    return report.show("eig(A - L C) are the wanted error poles (4.27).")


@exercise("4.4", "output feedback and the separation of poles",
          section="4.6 Output feedback using an observer")
def check_separation_poles(poles) -> CheckResult:
    """Check the 4 eigenvalues of the output-feedback loop of `SEPARATION` (plant + observer)."""
    report = Report("output feedback")
    A, B, C = (np.array(SEPARATION[k]) for k in ("A", "B", "C"))
    K, L = np.array(SEPARATION["K"]), np.array(SEPARATION["L"])
    # in the coordinates (x, e = x - x^) the loop is block triangular [[A + B K, -B K], [0, A - L C]]
    expected = np.concatenate(separation_eigenvalues(StateSpace(A, B, C), K, L))
    n = A.shape[0]
    probe = Report("")
    arr = read_poles(poles, "poles", 2 * n, probe)
    if arr is None and read_poles(poles, "poles", n, Report("")) is not None:
        report.add(f"the closed loop has {2 * n} states (x and the estimate x^), so {2 * n} "
                   "eigenvalues: those of A + B K and those of A - L C (separation principle).")
        return report.show("")
    if arr is None:
        report.problems.extend(probe.problems)
        return report.show("")
    wrong_sign = np.concatenate([np.linalg.eigvals(A - B @ K), np.linalg.eigvals(A + L @ C)])
    if not poles_feedback(arr, expected, "poles", report,
                          hint="Write the loop in x and e = x - x^: it is block triangular, so its "
                               "eigenvalues are those of A + B K (3.21) and of A - L C (4.27)."):
        if poles_feedback(arr, wrong_sign, "poles", Report("")):
            report.problems[-1] = ("poles: you used A - B K and A + L C; the course's signs are "
                                   "A + B K (u = K x, 3.21) and A - L C (4.27).")
    return report.show("the output-feedback loop has the poles of A + B K and of A - L C together.")
