"""Textbook systems in SI units, for tests of verdicts and designs on real scales.

`si_systems()` returns a list of `SISystem` records, each a linear model
x' = A x + B u, y = C x with physical parameter values, the unit of every
state (so tests can change units: "m" -> "mm", "rad" -> "mrad"), and the
controllability and observability the physics says it has. The models come
from widely used teaching material (named in each comment); the numbers are
the parameter values given there. Plain module: import it from any test
(``from si_systems import si_systems``).

The set spans eigenvalues from 1e-5 rad/s (a building) to 1e6 rad/s (a motor's
electrical pole) and input gains from 1e-7 to 4e5, which is what breaks a
controllability verdict taken as the rank of Wc.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["SISystem", "si_systems", "in_units"]

G = 9.81  # m/s^2


class SISystem(NamedTuple):
    """One model: matrices in SI units, state units, and its known verdicts."""

    name: str
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    units: tuple[str, ...]   # unit of each state, e.g. ("m", "m/s", "rad", "rad/s")
    controllable: bool
    observable: bool
    source: str


def _arr(rows) -> np.ndarray:
    return np.array(rows, dtype=float)


def dc_motor(C=((1, 0, 0),)) -> SISystem:
    # Armature-controlled DC motor, position output: the "DC Motor Position" model of the
    # Control Tutorials for MATLAB and Simulink (Messner, Tilbury). States theta (rad),
    # omega (rad/s), current i (A); input the armature voltage (V). Eigenvalues 0, -1.3,
    # -1.45e6: Wc spans 12 orders of magnitude, yet the chain theta <- omega <- i <- V
    # makes it controllable, and theta measured makes it observable.
    J, b, K, R, L = 3.2284e-6, 3.5077e-6, 0.0274, 4.0, 2.75e-6
    A = _arr([[0, 1, 0], [0, -b / J, K / J], [0, -K / L, -R / L]])
    B = _arr([[0], [0], [1 / L]])
    return SISystem("dc_motor", A, B, _arr(C), ("rad", "rad/s", "A"), True, True,
                    "CTMS DC Motor Position")


def cart_pendulum(C=((1, 0, 0, 0), (0, 0, 1, 0))) -> SISystem:
    # Inverted pendulum on a cart linearized upright: CTMS "Inverted Pendulum" (M = 0.5 kg
    # cart, m = 0.2 kg rod, b = 0.1 N s/m friction, l = 0.3 m to the centre of mass,
    # I = 0.006 kg m^2). States x (m), x' (m/s), phi (rad), phi' (rad/s); input the force on
    # the cart (N). Controllable; observable with cart position and angle measured.
    M, m, b, l, I = 0.5, 0.2, 0.1, 0.3, 0.006
    p = I * (M + m) + M * m * l**2
    A = _arr([[0, 1, 0, 0],
              [0, -(I + m * l**2) * b / p, m**2 * G * l**2 / p, 0],
              [0, 0, 0, 1],
              [0, -m * l * b / p, m * G * l * (M + m) / p, 0]])
    B = _arr([[0], [(I + m * l**2) / p], [0], [m * l / p]])
    C = _arr(C)
    # x enters no equation (its column of A is zero), so it is seen only if C measures it
    observable = bool(np.any(C[:, 0] != 0))
    return SISystem("cart_pendulum" if observable else "cart_pendulum_angle_only", A, B, C,
                    ("m", "m/s", "rad", "rad/s"), True, observable, "CTMS Inverted Pendulum")


def quarter_car() -> SISystem:
    # Active quarter-car suspension: CTMS "Suspension" (bus) parameters: body mass
    # 2500 kg, wheel mass 320 kg, suspension spring 80 000 N/m and damper 350 N s/m, tyre
    # stiffness 500 000 N/m; the actuator force u (N) acts between body and wheel. States
    # body and wheel positions (m) and velocities (m/s); y = body position. Controllable
    # and observable.
    m1, m2, k1, b1, k2 = 2500.0, 320.0, 80_000.0, 350.0, 500_000.0
    A = _arr([[0, 1, 0, 0],
              [-k1 / m1, -b1 / m1, k1 / m1, b1 / m1],
              [0, 0, 0, 1],
              [k1 / m2, b1 / m2, -(k1 + k2) / m2, -b1 / m2]])
    B = _arr([[0], [1 / m1], [0], [-1 / m2]])
    return SISystem("quarter_car", A, B, _arr([[1, 0, 0, 0]]), ("m", "m/s", "m", "m/s"),
                    True, True, "CTMS Suspension")


def rlc_circuit() -> SISystem:
    # Series RLC circuit driven by a voltage source (V): R = 10 ohm, L = 1 mH, C = 1 uF,
    # a standard circuits-course example (resonance 1/sqrt(LC) = 3.2e4 rad/s). States the
    # capacitor voltage (V) and the loop current (A); y = capacitor voltage.
    # Controllable and observable.
    R, L, Cap = 10.0, 1e-3, 1e-6
    A = _arr([[0, 1 / Cap], [-1 / L, -R / L]])
    B = _arr([[0], [1 / L]])
    return SISystem("rlc_circuit", A, B, _arr([[1, 0]]), ("V", "A"), True, True,
                    "series RLC circuit")


def building() -> SISystem:
    # Two-node thermal RC model of a room (a classic grey-box building model): air and
    # furniture C1 = 2e6 J/K, walls C2 = 1e7 J/K, air-wall resistance 5e-3 K/W, wall-outside
    # 1e-2 K/W; input the heater power (W), y = room temperature. States the deviations of
    # the room and wall temperatures (K). Time constants of hours (eigenvalues ~1e-5 rad/s),
    # input gain 5e-7: controllable and observable.
    C1, C2, Rrw, Rwa = 2e6, 1e7, 5e-3, 1e-2
    A = _arr([[-1 / (Rrw * C1), 1 / (Rrw * C1)],
              [1 / (Rrw * C2), -(1 / Rrw + 1 / Rwa) / C2]])
    B = _arr([[1 / C1], [0]])
    return SISystem("building", A, B, _arr([[1, 0]]), ("K", "K"), True, True,
                    "two-node RC thermal model")


def _tank_time_constant(area, outlet, h0):
    # linearizing area h' = q_in - outlet sqrt(2 g h) at h0 gives h' = -h / tau + q_in / area
    return area / outlet * np.sqrt(2 * h0 / G)


# Quanser coupled-tanks values: tank area 15.5 cm^2, outlet 0.178 cm^2, pump 3.3 cm^3/(s V)
_TANK_AREA, _OUTLET, _PUMP, _H0 = 1.55e-3, 1.78e-5, 3.3e-6, 0.15


def cascaded_tanks() -> SISystem:
    # Two tanks in cascade (Quanser coupled tanks): the pump (V) fills tank 1, which drains
    # into tank 2; linearized at 15 cm. States the two levels (m), y = level of tank 2.
    # Controllable (tank 2 is reached through tank 1) and observable (tank 1 shows in tank 2).
    tau = _tank_time_constant(_TANK_AREA, _OUTLET, _H0)
    A = _arr([[-1 / tau, 0], [1 / tau, -1 / tau]])
    B = _arr([[_PUMP / _TANK_AREA], [0]])
    return SISystem("cascaded_tanks", A, B, _arr([[0, 1]]), ("m", "m"), True, True,
                    "Quanser coupled tanks")


def parallel_tanks() -> SISystem:
    # Two identical tanks side by side, one pump whose flow is split equally between them
    # (the notes' two-tank example in physical units): both levels obey the same equation
    # with the same input, so their difference is untouched by u: NOT controllable. Both
    # levels are measured: observable.
    tau = _tank_time_constant(_TANK_AREA, _OUTLET, _H0)
    A = _arr([[-1 / tau, 0], [0, -1 / tau]])
    B = _arr([[_PUMP / (2 * _TANK_AREA)], [_PUMP / (2 * _TANK_AREA)]])
    return SISystem("parallel_tanks", A, B, np.eye(2), ("m", "m"), False, True,
                    "Quanser coupled tanks, parallel configuration")


def aircraft_pitch() -> SISystem:
    # Longitudinal pitch dynamics of a Boeing commercial aircraft in cruise: CTMS "Aircraft
    # Pitch" (numerical values from the tutorial's derivation). States angle of attack
    # (rad), pitch rate (rad/s), pitch angle (rad); input the elevator deflection (rad);
    # y = pitch angle. Controllable and observable.
    A = _arr([[-0.313, 56.7, 0], [-0.0139, -0.426, 0], [0, 56.7, 0]])
    B = _arr([[0.232], [0.0203], [0]])
    return SISystem("aircraft_pitch", A, B, _arr([[0, 0, 1]]), ("rad", "rad/s", "rad"),
                    True, True, "CTMS Aircraft Pitch")


def quadrotor_axis() -> SISystem:
    # One horizontal axis of a Crazyflie 2.0 nano-quadrotor near hover (inertia about the
    # roll axis 1.66e-5 kg m^2, Foerster 2015): x'' = g phi, phi'' = torque / Ixx. States
    # x (m), x' (m/s), phi (rad), phi' (rad/s); input the roll torque (N m), y = x. A chain
    # of four integrators with gain 6e4 at the input: controllable and observable.
    Ixx = 1.66e-5
    A = _arr([[0, 1, 0, 0], [0, 0, G, 0], [0, 0, 0, 1], [0, 0, 0, 0]])
    B = _arr([[0], [0], [0], [1 / Ixx]])
    return SISystem("quadrotor_axis", A, B, _arr([[1, 0, 0, 0]]), ("m", "m/s", "rad", "rad/s"),
                    True, True, "Crazyflie 2.0 hover model")


def si_systems() -> list[SISystem]:
    """Every model of this module, including the uncontrollable and unobservable ones."""
    return [dc_motor(), cart_pendulum(), cart_pendulum(C=((0, 0, 1, 0),)), quarter_car(),
            rlc_circuit(), building(), cascaded_tanks(), parallel_tanks(), aircraft_pitch(),
            quadrotor_axis()]


_MILLI = {"m": 1e3, "m/s": 1e3, "rad": 1e3, "rad/s": 1e3}


def in_units(sys: SISystem, *, time: float = 1.0, milli: bool = False):
    """(A, B, C) of `sys` with time in units of `time` seconds and, with `milli`, lengths
    in mm and angles in mrad.

    Time: t = time * t', so d/dt' = time d/dt: A -> time A, B -> time B. States:
    x' = D x with D = 1000 for states in m, m/s, rad, rad/s: A -> D A D^-1, B -> D B,
    C -> C D^-1. The scalings are applied exactly as products (no matrix inverse).
    """
    d = np.array([_MILLI.get(u, 1.0) if milli else 1.0 for u in sys.units])
    A = time * (d[:, None] * sys.A / d[None, :])
    B = time * (d[:, None] * sys.B)
    C = sys.C / d[None, :]
    return A, B, C
