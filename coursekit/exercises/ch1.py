"""Exercises of chapter 1 (representations), each with its data and a `check_*`.

1. `MSD`: state-space form of the mass-spring-damper (1.3), (1.54)-(1.57).
2. `COMPARTMENT`: state-space form of the compartment model (1.4)-(1.5).
3. `PENDULUM`: the nonlinear pendulum with damping and torque (1.8) as ``f(x, u)``.
4. `ODE`: realization of a third-order ODE in the form (1.52)-(1.53).
5. `EULER`: Euler discretization (1.43) of a linear system.

Every check prints "Correct: ..." or what is off, returns a `CheckResult`
(true when correct), and never prints the expected answer.
"""

from __future__ import annotations

import numpy as np

from .. import models
from ..realization import euler_discretize, ode_to_ss
from ..systems import StateSpace
from ._catalog import exercise
from ._data import ExerciseData
from ._feedback import CheckResult, Report, call_student_function, close, matrix_feedback

__all__ = [
    "MSD", "check_msd_state_space",
    "COMPARTMENT", "check_compartment_state_space",
    "PENDULUM", "check_pendulum_f",
    "ODE", "check_ode_realization",
    "EULER", "check_euler_discretization",
]

#: m y'' + d y' + k y = u, m [kg], d [N s/m], k [N/m]; state x = [y, y'], output y.
MSD = ExerciseData({"m": 2.0, "d": 0.4, "k": 8.0})

#: compartment model (1.4)-(1.5): volumes [l], rates [l/min], c0 [mg/l]; x = [c1, c2], y = c2.
COMPARTMENT = ExerciseData({"V1": 2.0, "V2": 4.0, "q": 0.6, "q0": 0.2, "c0": 5.0})

#: pendulum (1.8) with damping and torque: m [kg], l [m], g [m/s^2], d_theta [N m s]; x = [theta, theta'].
PENDULUM = ExerciseData({"m": 0.5, "l": 0.8, "g": 9.81, "d_theta": 0.3})

#: y''' + a2 y'' + a1 y' + a0 y = b u with a = [a0, a1, a2] (ascending, as in (1.47)).
ODE = ExerciseData({"a": (3.0, 5.0, 2.0), "b": 4.0})

#: x' = A x + B u discretized by Euler (1.43) with sampling period Ts [s].
EULER = ExerciseData({"A": ((0.0, 1.0), (-2.0, -3.0)), "B": ((0.0,), (1.0,)), "Ts": 0.1})


@exercise("1.1", "the mass-spring-damper in state-space form",
          section="1.6 Bridges")
def check_msd_state_space(A, B, C) -> CheckResult:
    """Check A, B, C of the mass-spring-damper `MSD` with x = [y, y'] and y the position."""
    report = Report("mass-spring-damper")
    m, d, k = MSD["m"], MSD["d"], MSD["k"]
    sys = models.mass_spring_damper(m=m, d=d, k=k)
    matrix_feedback(A, sys.A, "A", report, known_mistakes=[
        ([[0, 1], [-k, -d]], "A: the second row must be divided by m: y'' = (u - d y' - k y) / m (1.56)."),
        ([[0, 1], [k / m, d / m]], "A: the signs of the second row are flipped: move d y' and k y "
                                   "to the right-hand side (1.56)."),
    ], entry_hint="Rewrite (1.3) as y'' = ... and read off the rows of (1.57).")
    matrix_feedback(B, sys.B, "B", report, known_mistakes=[
        ([[0], [1]], "B: the force u enters y'' divided by the mass m (1.56)."),
    ], shape_hint="B must be a column (n x 1): one entry per state (1.57).")
    matrix_feedback(C, sys.C, "C", report, known_mistakes=[
        ([[0, 1]], "C = [0 1] measures the velocity x2; the output is the position y = x1 "
                   "(the notes print C = [0 1] under (1.57): that is a typo)."),
    ], shape_hint="C must be a row (1 x n): y = C x.")
    return report.show("x' = A x + B u, y = C x is the mass-spring-damper (1.57).")


@exercise("1.2", "the compartment model in state-space form",
          section="1.2 A few systems")
def check_compartment_state_space(A, B, C) -> CheckResult:
    """Check A, B, C of the compartment model `COMPARTMENT` with x = [c1, c2], y = c2."""
    report = Report("compartment model")
    p = COMPARTMENT
    sys = models.compartment(**p)
    V1, V2, q, q0 = p["V1"], p["V2"], p["q"], p["q0"]
    matrix_feedback(A, sys.A, "A", report, known_mistakes=[
        ([[-(q + q0), q], [q, -q]], "A: divide each equation of (1.4) by its volume V1 or V2 first."),
        ([[-q / V1, q / V1], [q / V2, -q / V2]], "A: the outflow q0 also empties compartment 1 (1.4)."),
    ], entry_hint="Expand q (c2 - c1) - q0 c1 in (1.4) and divide by V1 (first row), V2 (second row).")
    matrix_feedback(B, sys.B, "B", report, known_mistakes=[
        ([[p["c0"]], [0]], "B: the injected c0 u enters V1 c1', so divide it by V1 (1.4)."),
    ], shape_hint="B must be a column (n x 1): one entry per state.")
    matrix_feedback(C, sys.C, "C", report, known_mistakes=[
        ([[1, 0]], "C: the output is the concentration of compartment 2, y = c2 (1.5)."),
    ], shape_hint="C must be a row (1 x n): y = C x.")
    return report.show("this is the compartment model in state-space form (1.4)-(1.5).")


def _pendulum_points():
    rng = np.random.default_rng(1)
    return [(rng.uniform(-3, 3, size=2), rng.uniform(-2, 2, size=1)) for _ in range(6)]


def _student_f(f, x, u, report: Report):
    """Call f(x, u) with u as a 1-element array; retry with a plain number."""
    probe = Report("f")
    out = call_student_function(f, (x.copy(), u.copy()), "f", 2, probe)
    if out is None and callable(f):
        out = call_student_function(f, (x.copy(), float(u[0])), "f", 2, Report("f"))
    if out is None:
        report.problems.extend(probe.problems)
    return out


@exercise("1.3", "the nonlinear pendulum as x' = f(x, u)",
          section="1.2 A few systems")
def check_pendulum_f(f) -> CheckResult:
    """Check a Python function ``f(x, u)`` returning [theta', theta''] for the pendulum (1.8).

    ``x = [theta, theta']`` (theta in rad, 0 hanging down) and ``u = [tau]`` [N m];
    the numbers are those of `PENDULUM`.
    """
    report = Report("pendulum f(x, u)")
    p = PENDULUM
    true_f = models.pendulum(**p).f
    m, l, g, d = p["m"], p["l"], p["g"], p["d_theta"]
    variants = {
        "linear": lambda x, u: [x[1], -g / l * x[0] - d / m * x[1] + u[0] / (m * l**2)],
        "torque": lambda x, u: [x[1], -g / l * np.sin(x[0]) - d / m * x[1] + u[0]],
        "gravity": lambda x, u: [x[1], g / l * np.sin(x[0]) - d / m * x[1] + u[0] / (m * l**2)],
        "damping": lambda x, u: [x[1], -g / l * np.sin(x[0]) + u[0] / (m * l**2)],
    }
    outs, wanted = [], []
    for x, u in _pendulum_points():
        out = _student_f(f, x, u, report)
        if out is None:
            return report.show("")
        outs.append(out)
        wanted.append(true_f(x, u))
    outs, wanted = np.array(outs), np.array(wanted)
    if np.all(close(outs, wanted)):
        return report.show("f(x, u) is the damped pendulum with torque (1.8) in state form.")
    if not np.all(close(outs[:, 0], wanted[:, 0])):
        report.add("the first entry must be theta' = x[1]: the derivative of x1 = theta is x2 (1.79).")
    messages = {
        "linear": "f is linear in theta: the pendulum is nonlinear, keep sin(theta) (1.8); "
                  "sin(theta) ~ theta only holds near theta = 0.",
        "torque": "the torque tau enters theta'' divided by m l^2: divide (1.8) by m l^2 first.",
        "gravity": "the gravity term has the wrong sign: it pulls back towards theta = 0, "
                   "theta'' = -(g/l) sin(theta) + ...",
        "damping": "the damping d_theta l^2 theta' of (1.8) is missing (after dividing by m l^2: "
                   "-(d_theta/m) theta').",
    }
    for key, variant in variants.items():
        if np.all(close(outs[:, 1], [variant(x, u)[1] for x, u in _pendulum_points()])):
            report.add(messages[key])
            break
    else:
        if np.all(close(outs[:, 0], wanted[:, 0])):
            report.add("theta'' is off: solve (1.8) for theta'' (divide by m l^2) and check "
                       "each of its three terms.")
    return report.show("")


@exercise("1.4", "from an ODE to a state-space form",
          section="1.6 Bridges")
def check_ode_realization(A, B, C) -> CheckResult:
    """Check the realization of the `ODE` with state x = [y, y', y''] (1.48)-(1.53)."""
    report = Report("ODE realization")
    a = np.asarray(ODE["a"], dtype=float)
    b = ODE["b"]
    n = a.size
    ok = ode_to_ss(a, b)       # (1.52)-(1.53): superdiagonal ones, last row -a, B = b e_n, C = e_1^T
    A_ok, B_ok, C_ok = ok.A, ok.B, ok.C
    matrix_feedback(A, A_ok, "A", report, known_mistakes=[
        (np.vstack([np.eye(n)[1:], a]), "A: the last row is minus the coefficients: "
                                        "y''' = -a0 y - a1 y' - a2 y'' + b u (1.50)."),
        (np.vstack([np.eye(n)[1:], -a[::-1]]), "A: the coefficients of the last row are in reverse order: "
                                               "from left to right they multiply y, y', y'' (1.53)."),
    ], entry_hint="Each xi' is the next state; the last row comes from solving the ODE for y''' (1.50).")
    matrix_feedback(B, B_ok, "B", report, known_mistakes=[
        (np.eye(n)[:, -1:], "B: the input enters y''' multiplied by b, so the last entry of B is b (1.53)."),
    ], shape_hint="B must be a column (n x 1).")
    matrix_feedback(C, C_ok, "C", report, known_mistakes=[
        (b * np.eye(n)[:1], "C: with the state [y, y', y''] the output is y = x1; the factor b belongs "
                            "in B (1.52)-(1.53)."),
    ], shape_hint="C must be a row (1 x n).")
    return report.show("this is the realization (1.52)-(1.53) of the ODE.")


@exercise("1.5", "Euler discretization",
          section="1.6 Bridges")
def check_euler_discretization(Ad, Bd) -> CheckResult:
    """Check x(t+1) = Ad x(t) + Bd u(t), the Euler discretization (1.43) of `EULER`."""
    from scipy.linalg import expm
    report = Report("Euler discretization")
    A, B, Ts = np.array(EULER["A"]), np.array(EULER["B"]), EULER["Ts"]
    # (1.43): x(t+1) = x(t) + Ts (A x(t) + B u(t))
    discrete = euler_discretize(StateSpace(A, B), Ts)
    Ad_ok, Bd_ok = discrete.A, discrete.B
    matrix_feedback(Ad, Ad_ok, "Ad", report, known_mistakes=[
        (Ts * A, "Ad: x(t+1) = x(t) + Ts f(x, u) keeps x(t) itself: Ad = I + Ts A, not Ts A (1.43)."),
        (A, "Ad: multiply A by the sampling period Ts and add the identity (1.43)."),
        (expm(Ts * A), "Ad: that is the exact discretization e^(A Ts); the exercise asks for "
                       "Euler's approximation (1.43)."),
    ], entry_hint="Apply (1.43) with f(x, u) = A x + B u.")
    matrix_feedback(Bd, Bd_ok, "Bd", report, known_mistakes=[
        (B, "Bd: the input term is multiplied by Ts too (1.43)."),
    ], shape_hint="Bd must be a column (n x 1) like B.")
    return report.show("Euler (1.43) gives x(t+1) = (I + Ts A) x(t) + Ts B u(t).")
