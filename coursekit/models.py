"""The example systems of the notes, with the notes' parameter names.

Linear systems are returned as `StateSpace`, nonlinear ones as
`NonlinearSystem`; every factory takes the physical parameters as keyword
arguments with the defaults documented below, so ``models.pendulum(l=0.5)``
reads like the notes.

===============================  ==========================  ======================
factory                          notes                       kind
===============================  ==========================  ======================
`bank_account`                   (1.1)-(1.2)                 discrete, dt = 1 year
`mass_spring_damper`             (1.3), (1.54)-(1.57)        linear
`compartment`                    (1.4)-(1.5), (1.20)-(1.25)  linear
`pendulum`                       (1.6)-(1.8), (1.77)-(1.80)  nonlinear
`lorenz`                         (1.9), (1.29)-(1.31)        nonlinear
`two_wheeled_robot`              (1.10)                      nonlinear
`car_like_robot`                 (1.11)                      nonlinear
`state_example`                  (1.15)-(1.16)               discrete
`fibonacci`                      (1.72)-(1.75)               discrete
`vehicle`                        (4.1)-(4.3)                 linear
===============================  ==========================  ======================
"""

from __future__ import annotations

import numpy as np

from ._validation import as_scalar
from .systems import NonlinearSystem, StateSpace

__all__ = ["bank_account", "mass_spring_damper", "compartment", "pendulum", "lorenz", "two_wheeled_robot",
           "car_like_robot", "state_example", "fibonacci", "vehicle"]


def bank_account(rate: float = 0.03) -> StateSpace:
    """Savings y(k+1) = (1 + rate) y(k) + u(k) (1.2), k in years, u the yearly deposit.

    The notes state an interest of 3 % a year; (1.1) prints the factor as
    1 + 0.003, which is 0.3 % (a typo). The default here is 3 %.
    """
    rate = as_scalar(rate, "rate")
    return StateSpace([[1.0 + rate]], [[1.0]], [[1.0]], dt=1.0, name="bank account")


def mass_spring_damper(m: float = 1.0, d: float = 0.5, k: float = 2.0) -> StateSpace:
    """m y'' + d y' + k y = u (1.54) with state x = [y, y'] (1.55).

    Output: the position y = x1, so C = [1, 0]. (The notes print C = [0 1]
    under (1.57), which would measure the velocity; it is a typo.)
    Units: m [kg], d [N s/m], k [N/m], u [N], y [m].
    """
    m = as_scalar(m, "m", positive=True)
    d, k = as_scalar(d, "d"), as_scalar(k, "k")
    A = [[0.0, 1.0], [-k / m, -d / m]]
    return StateSpace(A, [[0.0], [1.0 / m]], [[1.0, 0.0]], name="mass-spring-damper")


def compartment(V1: float = 1.0, V2: float = 2.0, q: float = 0.5, q0: float = 0.2,
                c0: float = 1.0) -> StateSpace:
    """Two-compartment drug model (1.20)-(1.25), state x = [c1, c2], output y = c2.

    V1, V2 [l] volumes; q, q0 [l/min] exchange and outflow rates; c0 [mg/l]
    concentration of the injected drug; u [l/min] injection flow rate.
    """
    V1, V2 = as_scalar(V1, "V1", positive=True), as_scalar(V2, "V2", positive=True)
    q, q0, c0 = as_scalar(q, "q"), as_scalar(q0, "q0"), as_scalar(c0, "c0")
    # (1.23)
    A = [[-(q + q0) / V1, q / V1], [q / V2, -q / V2]]
    return StateSpace(A, [[c0 / V1], [0.0]], [[0.0, 1.0]], name="compartment model")


def pendulum(m: float = 1.0, l: float = 1.0, g: float = 9.81, d_theta: float = 0.0) -> NonlinearSystem:
    """m l^2 theta'' + d_theta l^2 theta' + m g l sin(theta) = tau (1.8).

    State x = [theta, theta'] (1.79), input u = tau [N m], output y = theta [rad].
    theta = 0 hangs down. m [kg] tip mass, l [m] length, g [m/s^2], d_theta
    [N m s / m^2] rotational damping (0 gives (1.6)/(1.77)).
    """
    m, l = as_scalar(m, "m", positive=True), as_scalar(l, "l", positive=True)
    g, d_theta = as_scalar(g, "g"), as_scalar(d_theta, "d_theta")

    def f(x, u):
        # (1.80) with damping: theta'' = -(d/m) theta' - (g/l) sin(theta) + tau / (m l^2)
        return np.array([x[1], -d_theta / m * x[1] - g / l * np.sin(x[0]) + u[0] / (m * l**2)])

    return NonlinearSystem(f, n=2, m=1, h=lambda x, u: x[:1], name="pendulum",
                           params=dict(m=m, l=l, g=g, d_theta=d_theta))


def lorenz(p: float = 10.0, r: float = 0.0, b: float = 1.0) -> NonlinearSystem:
    """The Lorenz system; with the defaults exactly the version (1.9)/(1.29), no input, y = x.

    x1' = p (x2 - x1),  x2' = r x1 - x2 - x1 x3,  x3' = x1 x2 - b x3.

    The notes' version (r = 0, b = 1) has no chaos: V = x1^2/(2p) + (x2^2 + x3^2)/2
    decreases along every solution, so all of them go to the origin. Lorenz's
    classical chaotic parameters are p = 10, r = 28, b = 8/3.
    """
    p, r, b = as_scalar(p, "p"), as_scalar(r, "r"), as_scalar(b, "b")

    def f(x, u):
        return np.array([-p * x[0] + p * x[1], r * x[0] - x[0] * x[2] - x[1], x[0] * x[1] - b * x[2]])

    return NonlinearSystem(f, n=3, name="Lorenz", params=dict(p=p, r=r, b=b))


def two_wheeled_robot() -> NonlinearSystem:
    """Unicycle (1.10): state [x1, x2, theta] (m, m, rad), inputs [u1, u2] = [speed m/s, turn rate rad/s]."""
    def f(x, u):
        return np.array([u[0] * np.cos(x[2]), u[0] * np.sin(x[2]), u[1]])

    return NonlinearSystem(f, n=3, m=2, name="two-wheeled robot")


def car_like_robot(L: float = 2.5) -> NonlinearSystem:
    """Car-like robot (1.11): state [x1, x2, theta], inputs [v, delta] (m/s, rad).

    theta' = v tan(delta) / L, with L [m] the distance between the axles.
    """
    L = as_scalar(L, "L", positive=True)

    def f(x, u):
        return np.array([u[0] * np.cos(x[2]), u[0] * np.sin(x[2]), u[0] * np.tan(u[1]) / L])

    return NonlinearSystem(f, n=3, m=2, name="car-like robot", params=dict(L=L))


def state_example() -> StateSpace:
    """The discrete example (1.15): x1(t+1) = x2(t), x2(t+1) = x1(t).

    The notes print the second line as x2(t+2) = x1(t); with a state vector
    x = [x1, x2] both lines must step by one, as figure 1.18 shows.
    """
    return StateSpace([[0.0, 1.0], [1.0, 0.0]], dt=1.0, name="example (1.15)")


def fibonacci() -> StateSpace:
    """Fibonacci numbers (1.72) as x(t+1) = [[0, 1], [1, 1]] x(t), y = x1 (1.74)-(1.75).

    Start from x(0) = [y(0), y(1)] = [0, 1].
    """
    return StateSpace([[0.0, 1.0], [1.0, 1.0]], C=[[1.0, 0.0]], dt=1.0, name="Fibonacci")


def vehicle(m: float = 1000.0, d: float = 50.0, sensor: str = "gps") -> StateSpace:
    """Vehicle on a straight road (4.1): x = [position, velocity], u = traction force [N].

    ``sensor="gps"`` measures the position (4.2), ``"speedometer"`` the
    velocity (4.3). m [kg] mass, d [N s/m] friction.
    """
    m, d = as_scalar(m, "m", positive=True), as_scalar(d, "d")
    rows = {"gps": [[1.0, 0.0]], "speedometer": [[0.0, 1.0]]}
    if sensor not in rows:
        raise ValueError(f"sensor must be 'gps' or 'speedometer': received {sensor!r}.")
    return StateSpace([[0.0, 1.0], [0.0, -d / m]], [[0.0], [1.0 / m]], rows[sensor],
                      name=f"vehicle with {sensor}")
