"""models: each system of section 1.2 against its equation in the notes and a closed form."""

import numpy as np
import pytest

import coursekit as ck
from coursekit import models


def test_bank_account_compound_interest_1_1():
    sys = models.bank_account()
    res = ck.simulate(sys, np.arange(11.0), x0=[10_000.0])
    np.testing.assert_allclose(res.y[:, 0], 10_000 * 1.03 ** np.arange(11))
    assert sys.dt == 1.0


def test_bank_account_with_deposits_1_2():
    sys = models.bank_account(rate=0.03)
    u = np.full((6, 1), 1000.0)
    res = ck.simulate(sys, np.arange(6.0), u=u, x0=[10_000.0])
    y = [10_000.0]
    for _ in range(5):
        y.append(1.03 * y[-1] + 1000.0)
    np.testing.assert_allclose(res.y[:, 0], y)


def test_mass_spring_damper_matrices_1_57_and_static_gain():
    m, d, k = 2.0, 0.4, 8.0
    sys = models.mass_spring_damper(m=m, d=d, k=k)
    np.testing.assert_allclose(sys.A, [[0, 1], [-k / m, -d / m]])
    np.testing.assert_allclose(sys.B, [[0], [1 / m]])
    np.testing.assert_allclose(sys.C, [[1, 0]])  # position, see the erratum of (1.57)
    # steady state under a constant force u: y = u / k
    t = np.linspace(0, 200, 2001)
    res = ck.simulate(sys, t, u=np.full((t.size, 1), 3.0))
    assert np.isclose(res.y[-1, 0], 3.0 / k, atol=1e-6)


def test_mass_spring_damper_undamped_is_a_cosine():
    sys = models.mass_spring_damper(m=1.0, d=0.0, k=4.0)
    t = np.linspace(0, 5, 51)
    res = ck.simulate(sys, t, x0=[1.0, 0.0])
    np.testing.assert_allclose(res.y[:, 0], np.cos(2 * t), atol=1e-10)


def test_compartment_matrices_1_23_1_25():
    V1, V2, q, q0, c0 = 2.0, 3.0, 0.5, 0.1, 4.0
    sys = models.compartment(V1=V1, V2=V2, q=q, q0=q0, c0=c0)
    x = np.array([1.3, 0.4])
    u = np.array([0.7])
    # (1.4) directly
    c1dot = (q * (x[1] - x[0]) - q0 * x[0] + c0 * u[0]) / V1
    c2dot = q * (x[0] - x[1]) / V2
    np.testing.assert_allclose(sys.f(x, u), [c1dot, c2dot])
    np.testing.assert_allclose(sys.C, [[0, 1]])
    assert np.all(np.linalg.eigvals(sys.A).real < 0)


def test_pendulum_vector_field_1_8_and_1_80():
    m, l, g, dth = 0.5, 2.0, 9.81, 0.3
    sys = models.pendulum(m=m, l=l, g=g, d_theta=dth)
    x, u = np.array([0.4, -1.2]), np.array([0.9])
    # m l^2 theta'' + d l^2 theta' + m g l sin(theta) = tau
    thdd = (u[0] - dth * l**2 * x[1] - m * g * l * np.sin(x[0])) / (m * l**2)
    np.testing.assert_allclose(sys.f(x, u), [x[1], thdd])
    np.testing.assert_allclose(sys.h(x, u), [0.4])


def test_pendulum_small_angle_period():
    # small oscillations: theta'' = -(g/l) theta, period 2 pi sqrt(l/g)
    sys = models.pendulum(l=1.0, g=9.81)
    w = np.sqrt(9.81)
    t = np.linspace(0, 2, 201)
    res = ck.simulate(sys, t, x0=[1e-4, 0.0])
    np.testing.assert_allclose(res.x[:, 0], 1e-4 * np.cos(w * t), atol=1e-10)


def test_pendulum_conserves_energy_without_damping():
    m, l, g = 1.0, 1.0, 9.81
    sys = models.pendulum(m=m, l=l, g=g)
    res = ck.simulate(sys, np.linspace(0, 10, 501), x0=[2.0, 0.0])
    E = 0.5 * m * l**2 * res.x[:, 1] ** 2 - m * g * l * np.cos(res.x[:, 0])
    assert np.ptp(E) < 1e-6


def test_lorenz_notes_version_1_9():
    sys = models.lorenz(p=10.0)
    x = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(sys.f(x, np.zeros(0)), [-10 + 20, -3 - 2, 2 - 3])


def test_lorenz_notes_version_goes_to_the_origin():
    # V = x1^2/(2p) + (x2^2 + x3^2)/2 decreases: no chaos with r = 0, b = 1
    res = ck.simulate(models.lorenz(), np.linspace(0, 30, 301), x0=[5.0, -3.0, 8.0])
    assert np.linalg.norm(res.x[-1]) < 1e-6


def test_lorenz_classical_has_the_classical_equilibria():
    p, r, b = 10.0, 28.0, 8 / 3
    sys = models.lorenz(p=p, r=r, b=b)
    c = np.sqrt(b * (r - 1))
    np.testing.assert_allclose(sys.f(np.array([c, c, r - 1]), np.zeros(0)), 0, atol=1e-12)


def test_two_wheeled_robot_drives_a_circle():
    # constant speed v and turn rate w: a circle of radius v / w
    v, w = 2.0, 0.5
    t = np.linspace(0, 2 * np.pi / w, 201)
    res = ck.simulate(models.two_wheeled_robot(), t, u=np.tile([v, w], (t.size, 1)))
    np.testing.assert_allclose(res.x[:, 0], v / w * np.sin(w * t), atol=1e-8)
    np.testing.assert_allclose(res.x[:, 1], v / w * (1 - np.cos(w * t)), atol=1e-8)


def test_car_like_robot_turning_radius():
    L, v, delta = 2.5, 1.0, 0.3
    t = np.linspace(0, 10, 101)
    res = ck.simulate(models.car_like_robot(L=L), t, u=np.tile([v, delta], (t.size, 1)))
    w = v * np.tan(delta) / L
    np.testing.assert_allclose(res.x[:, 2], w * t, atol=1e-9)
    np.testing.assert_allclose(res.x[:, 1], (1 - np.cos(w * t)) / w * v, atol=1e-8)


def test_state_example_1_15_swaps_the_states():
    res = ck.simulate(models.state_example(), np.arange(4.0), x0=[1.0, 0.0])
    np.testing.assert_array_equal(res.x, [[1, 0], [0, 1], [1, 0], [0, 1]])
    res = ck.simulate(models.state_example(), np.arange(4.0), x0=[1.0, -1.0])
    np.testing.assert_array_equal(res.x, [[1, -1], [-1, 1], [1, -1], [-1, 1]])


def test_fibonacci_1_74_1_75():
    res = ck.simulate(models.fibonacci(), np.arange(10.0), x0=[0.0, 1.0])
    np.testing.assert_array_equal(res.y[:, 0], [0, 1, 1, 2, 3, 5, 8, 13, 21, 34])


def test_vehicle_sensors():
    assert np.array_equal(models.vehicle().C, [[1, 0]])
    assert np.array_equal(models.vehicle(sensor="speedometer").C, [[0, 1]])


@pytest.mark.parametrize("call, match", [
    (lambda: models.mass_spring_damper(m=0.0), "m must be positive"),
    (lambda: models.pendulum(l=-1.0), "l must be positive"),
    (lambda: models.compartment(V1=np.nan), "V1 contains NaN"),
    (lambda: models.car_like_robot(L=0.0), "L must be positive"),
    (lambda: models.vehicle(sensor="radar"), "sensor must be"),
])
def test_bad_parameters_raise_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
