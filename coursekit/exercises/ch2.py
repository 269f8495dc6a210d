"""Exercises of chapter 2 (controllability and open-loop control).

1. `CTRB`: compute the controllability matrix Wc (2.13).
2. `KALMAN`: rank of Wc and the decision of Kalman's criterion (section 2.2.3).
3. `CCF`: the transform z = T x to the controllability canonical form (2.59)-(2.65).
4. `CAR`: the car-like robot is flat (the notes' exercise after (2.102)): speed and
   steering angle from the derivatives of the flat output F = (x1, x2).
5. `TRAJECTORY`: coefficients of the cubic rest-to-rest trajectory (2.33)-(2.38).
"""

from __future__ import annotations

import numpy as np

from ..controllability import ccf_transform, ctrb
from ..flatness import car_like_flatness
from ._catalog import exercise
from ._data import ExerciseData
from ._feedback import CheckResult, Report, close, matrix_feedback, rank_decision_feedback, read_numbers

__all__ = [
    "CTRB", "check_ctrb_matrix",
    "KALMAN", "check_kalman_decision",
    "CCF", "check_ccf_transform",
    "CAR", "check_car_flatness",
    "TRAJECTORY", "check_trajectory_coefficients",
]

#: x' = A x + B u with three states and one input.
CTRB = ExerciseData({"A": ((1.0, 2.0, 0.0), (0.0, -1.0, 1.0), (1.0, 0.0, -2.0)),
                     "B": ((0.0,), (1.0,), (1.0,))})

#: is this (A, B) controllable?
KALMAN = ExerciseData({"A": ((0.0, 1.0, 1.0), (1.0, 0.0, 1.0), (1.0, 1.0, 0.0)),
                       "B": ((1.0,), (-1.0,), (0.0,))})

#: a second-order system that is not in CCF.
CCF = ExerciseData({"A": ((1.0, 2.0), (3.0, 0.0)), "B": ((0.0,), (1.0,))})

#: car-like robot (1.11): wheelbase L [m] and, at one instant, F' = (x1', x2') [m/s],
#: F'' = (x1'', x2'') [m/s^2] of the flat output F = (x1, x2).
CAR = ExerciseData({"L": 2.5, "dF": (3.0, 4.0), "ddF": (-1.0, 2.0)})

#: y'' = u (a CCF with a0 = a1 = 0): move from x(0) = (y, y') = x0 to x(T) = xT in T seconds.
TRAJECTORY = ExerciseData({"T": 2.0, "x0": (0.0, 1.0), "xT": (2.0, 0.0)})


@exercise("2.1", "the controllability matrix",
          section="2.2 Controllability and the Kalman criterion")
def check_ctrb_matrix(Wc) -> CheckResult:
    """Check the controllability matrix Wc = [B, AB, A^2 B] of `CTRB` (2.13)."""
    report = Report("controllability matrix")
    A, B = np.array(CTRB["A"]), np.array(CTRB["B"])
    Wc_ok = ctrb(A, B)   # (2.13); one input, so a block is a column
    matrix_feedback(Wc, Wc_ok, "Wc", report, known_mistakes=[
        (Wc_ok[:, ::-1], "Wc: the columns are in reverse order: B comes first, then AB, "
                         "then A^2 B (2.13)."),
    ], shape_hint="Wc stacks the columns B, AB, A^2 B side by side: n x n for one input "
        "((2.13) prints A as the first block: a typo, the first block is B, see (2.12)).",
        entry_hint="Compute AB = A @ B and A^2 B = A @ (A @ B) and put them side by side (2.13).")
    return report.show("Wc = [B, AB, A^2 B] (2.13).")


@exercise("2.2", "Kalman's criterion",
          section="2.2 Controllability and the Kalman criterion")
def check_kalman_decision(rank, controllable) -> CheckResult:
    """Check the rank of Wc for `KALMAN` and the decision of Kalman's criterion."""
    report = Report("Kalman criterion")
    A, B = np.array(KALMAN["A"]), np.array(KALMAN["B"])
    rank_decision_feedback(rank, controllable, int(np.linalg.matrix_rank(ctrb(A, B))), A.shape[0],
                           report, word="controllable",
                           rank_hint="count the linearly independent columns of [B, AB, A^2 B] "
                                     "(is AB a multiple of B?).",
                           decision_hint="(A, B) is controllable exactly when rank Wc = n "
                                         "(section 2.2.3).")
    return report.show("rank Wc decides controllability (Kalman's criterion).")


@exercise("2.3", "the transform to the CCF",
          section="2.3 Open-loop control")
def check_ccf_transform(T) -> CheckResult:
    """Check the transform z = T x that puts `CCF` in controllability canonical form (2.65)."""
    report = Report("CCF transform")
    A, B = np.array(CCF["A"]), np.array(CCF["B"])
    T_ok = ccf_transform(A, B)
    Wc = ctrb(A, B)
    T1_wrong = np.array([[0.0, 1.0]]) @ Wc          # B~^T Wc instead of B~^T Wc^-1
    matrix_feedback(T, T_ok, "T", report, known_mistakes=[
        (np.linalg.inv(T_ok), "T is inverted: z = T x (2.57), and your matrix maps z back to x."),
        (T_ok[::-1], "T: the rows are in the wrong order: T1 is the first row and T2 = T1 A (2.61)."),
        (np.vstack([T1_wrong, T1_wrong @ A]), "T1 = B~^T Wc^-1 needs the inverse of Wc (2.65), "
                                              "not Wc itself."),
        (np.vstack([T_ok[0], T_ok[0] @ A.T]), "T2 = T1 A: multiply the row T1 by A from the right (2.61)."),
    ], entry_hint="T1 = [0 1] Wc^-1 (2.65), then T2 = T1 A (2.61); check T A T^-1 is a CCF.")
    return report.show("T A T^-1 is in CCF and T B = [0, 1]^T (2.65).")


def _car_solution(sign: float) -> tuple[float, float]:
    """(v, delta) from psi_u of the car-like robot's flat output F = (x1, x2) (2.89)."""
    flat = car_like_flatness(L=CAR["L"], reverse=sign < 0)
    # (2.99), (2.101) and theta' = v tan(delta) / L (1.11); the position F itself does not matter
    v, delta = flat.psi_u([np.zeros(2), np.array(CAR["dF"]), np.array(CAR["ddF"])])
    return float(v), float(delta)


@exercise("2.4", "the car-like robot is flat",
          section="2.4 Flatness")
def check_car_flatness(v, delta) -> CheckResult:
    """Check the speed v [m/s] and steering angle delta [rad] of the car-like robot at `CAR`.

    Either sign of v is accepted (driving forwards or backwards along the same
    path, as the +- in (2.99)), with the steering angle that goes with it.
    """
    report = Report("car-like robot")
    L = CAR["L"]
    (d1, d2), (dd1, dd2) = CAR["dF"], CAR["ddF"]
    vv = read_numbers(v, "v", 1, report)
    dd = read_numbers(delta, "delta", 1, report)
    if vv is None or dd is None:
        return report.show("")
    vv, dd = float(vv[0]), float(dd[0])
    sign = 1.0 if vv >= 0 else -1.0
    v_ok, delta_ok = _car_solution(sign)
    if not close(np.array(vv), np.array(v_ok)):
        report.add("v is off: the speed is the length of the velocity vector, "
                   "v^2 = x1'^2 + x2'^2 (as (2.98) for the two-wheeled robot).")
    if not close(np.array(dd), np.array(delta_ok)):
        dtheta = (dd2 * d1 - dd1 * d2) / (d1**2 + d2**2)
        hints = [
            (np.arctan(dtheta / v_ok), "delta: you forgot the wheelbase L: theta' = v tan(delta) / L (1.11), "
                                       "so tan(delta) = L theta' / v."),
            (np.arctan(-L * dtheta / v_ok), "delta has the wrong sign: theta' = (F2'' F1' - F1'' F2') / "
                                            "(F1'^2 + F2'^2) as in (2.101)."),
            (L * dtheta / v_ok, "delta: that is tan(delta); take the arctangent."),
            (np.degrees(delta_ok), "delta looks like degrees: give the angle in radians."),
            (np.arctan(L * dtheta), "delta: divide L theta' by the speed v: tan(delta) = L theta' / v (1.11)."),
        ]
        for wrong, message in hints:
            if close(np.array(dd), np.array(wrong)):
                report.add(message)
                break
        else:
            report.add("delta is off: find theta' from F as in (2.101), then solve "
                       "theta' = v tan(delta) / L (1.11) for delta.")
    return report.show("v and delta follow from F', F'' alone, so the car-like robot is flat "
                       "with F = (x1, x2) and therefore controllable.")


@exercise("2.5", "a polynomial trajectory",
          section="2.3 Open-loop control")
def check_trajectory_coefficients(alpha) -> CheckResult:
    """Check [alpha0, alpha1, alpha2, alpha3] of y_d(t) for `TRAJECTORY` (2.33)-(2.38)."""
    report = Report("trajectory coefficients")
    T = TRAJECTORY["T"]
    (x10, x20), (x1T, x2T) = TRAJECTORY["x0"], TRAJECTORY["xT"]
    # (2.34): alpha0, alpha1 from the start; (2.37)-(2.38): alpha2, alpha3 from the end
    M = np.array([[T**2, T**3], [2 * T, 3 * T**2]])
    a23 = np.linalg.solve(M, [x1T - (x10 + x20 * T), x2T - x20])
    alpha_ok = np.array([[x10, x20, *a23]])
    matrix_feedback(alpha, alpha_ok, "alpha", report, known_mistakes=[
        (alpha_ok[:, ::-1], "alpha is in descending order: the course writes "
                            "y_d = alpha0 + alpha1 t + alpha2 t^2 + alpha3 t^3 (2.33), so alpha0 first."),
    ], shape_hint="alpha has 4 numbers: [alpha0, alpha1, alpha2, alpha3].",
        entry_hint="alpha0, alpha1 come from x(0) (2.34); solve the 2x2 system (2.37) for alpha2, alpha3.",
        vector=True)
    return report.show("y_d(t) starts at x0 and ends at xT with these coefficients (2.38).")
