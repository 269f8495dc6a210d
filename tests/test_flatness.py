"""Flat outputs and the maps psi_x, psi_u (section 2.4)."""


import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck


def test_linear_example_2_80_gives_2_84_and_2_86():
    flat = ck.linear_flatness([[0, 2], [1, -3]], [[1], [0]])
    np.testing.assert_allclose(flat.T1, [0, 1])  # F = x2 (2.82)
    F, dF, ddF = 0.7, -1.3, 2.1
    # (2.84): x1 = 3F + F', x2 = F
    np.testing.assert_allclose(flat.psi_x([F, dF]), [3 * F + dF, F])
    # (2.86): u = -2F + 3F' + F''
    np.testing.assert_allclose(flat.psi_u([F, dF, ddF]), [-2 * F + 3 * dF + ddF])
    np.testing.assert_allclose(flat.phi([0.2, 0.5]), [0.5])


@given(n=st.integers(1, 4), seed=st.integers(0, 10_000))
def test_linear_flatness_is_consistent_with_the_dynamics(n, seed):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    flat = ck.linear_flatness(A, B)
    # along any F(t): x = psi_x, u = psi_u must satisfy x' = A x + B u
    derivs = [float(v) for v in rng.normal(size=n + 1)]
    x = flat.psi_x(derivs)
    x_dot = flat.psi_x(derivs[1:])  # psi_x is linear: its derivative uses F', ..., F^(n)
    u = flat.psi_u(derivs)
    size = 1 + np.abs(x_dot).max() + np.abs(A @ x).max()
    np.testing.assert_allclose(x_dot, A @ x + B[:, 0] * u[0], atol=1e-7 * size)
    # phi inverts psi_x on F
    np.testing.assert_allclose(flat.phi(x), derivs[0], atol=1e-8 * (1 + np.abs(x).max()))


def test_linear_flatness_not_controllable():
    with pytest.raises(ck.NotControllableError, match=r"not controllable"):
        ck.linear_flatness([[-1, 1, 0], [1, -1, 1], [0, 1, -1]], [[0], [1], [0]])


def test_pendulum_psi_u_is_2_92_plus_damping():
    flat = ck.pendulum_flatness(m=2.0, l=0.5, g=9.81, d_theta=0.1)
    F, dF, ddF = 0.4, 0.3, -1.0
    np.testing.assert_allclose(flat.psi_x([F, dF]), [F, dF])
    expected = 2.0 * 0.25 * ddF + 0.1 * 0.25 * dF + 2.0 * 9.81 * 0.5 * np.sin(F)
    np.testing.assert_allclose(flat.psi_u([F, dF, ddF]), [expected])


def test_pendulum_swing_on_the_nonlinear_model():
    flat = ck.pendulum_flatness(m=1.0, l=0.5, d_theta=0.2)
    plan = ck.plan_flat_output(flat, 2.0, [0.0, 0.0, 0.0], [np.pi / 3, 0.0, 0.0])
    t = np.linspace(0, 2, 201)
    res = ck.simulate(ck.models.pendulum(m=1.0, l=0.5, d_theta=0.2), t, u=plan.input, x0=plan.x0)
    np.testing.assert_allclose(res.x, plan.x(t), atol=1e-6)
    np.testing.assert_allclose(res.x[-1], [np.pi / 3, 0.0], atol=1e-6)
    # with F''(T) = 0 the end torque is the holding torque m g l sin(theta_T)
    np.testing.assert_allclose(plan.u(2.0), [9.81 * 0.5 * np.sin(np.pi / 3)])


@pytest.mark.parametrize("L", [None, 2.5])
@pytest.mark.parametrize("speed", [1.0, -0.8])
def test_robot_manoeuvres_are_driven_by_the_nonlinear_models(L, speed):
    start, end = [0.0, 0.0, 0.0], [4.0, 3.0, np.pi / 2]
    if speed < 0:
        end = [-4.0, 3.0, -np.pi / 2]
    plan = ck.plan_robot(start, end, 6.0, speed=speed, L=L)
    model = ck.models.two_wheeled_robot() if L is None else ck.models.car_like_robot(L)
    t = np.linspace(0, 6, 301)
    res = ck.simulate(model, t, u=plan.input, x0=start)
    np.testing.assert_allclose(res.x[-1, :2], end[:2], atol=1e-6)
    # headings agree modulo 2 pi
    np.testing.assert_allclose(np.cos(res.x[-1, 2] - end[2]), 1.0, atol=1e-9)
    assert np.sign(plan.u(3.0)[0]) == np.sign(speed)
    assert plan.min_speed > 0
    fig = plan.plot(samples=50)
    assert len(fig.axes[0].lines) == 3 and len(fig.axes[1].lines) == 2


def test_two_wheeled_psi_matches_2_97_and_2_102():
    flat = ck.two_wheeled_flatness()
    F, dF, ddF = np.array([1.0, 2.0]), np.array([-3.0, 4.0]), np.array([0.5, -1.0])
    x = flat.psi_x([F, dF])
    np.testing.assert_allclose(x, [1.0, 2.0, np.arctan2(4.0, -3.0)])
    # the notes' arctan(F2'/F1') would point the wrong way here: quadrant II
    assert x[2] > np.pi / 2
    u = flat.psi_u([F, dF, ddF])
    np.testing.assert_allclose(u, [5.0, (-1.0 * -3.0 - 0.5 * 4.0) / 25.0])


def test_car_like_steering_angle_from_the_curvature():
    L = 2.5
    flat = ck.car_like_flatness(L)
    # a circle of radius R driven at speed v: F = R (sin(w t), 1 - cos(w t)), w = v / R
    R, v, t = 10.0, 2.0, 0.7
    w = v / R
    F = R * np.array([np.sin(w * t), 1 - np.cos(w * t)])
    dF = R * w * np.array([np.cos(w * t), np.sin(w * t)])
    ddF = R * w**2 * np.array([-np.sin(w * t), np.cos(w * t)])
    u = flat.psi_u([F, dF, ddF])
    np.testing.assert_allclose(u, [v, np.arctan(L / R)])
    np.testing.assert_allclose(flat.psi_x([F, dF])[2], w * t)


def test_time_major_evaluation():
    flat = ck.two_wheeled_flatness()
    N = 5
    derivs = [np.ones((N, 2)), np.tile([1.0, 1.0], (N, 1)), np.zeros((N, 2))]
    assert flat.psi_x(derivs).shape == (N, 3)
    assert flat.psi_u(derivs).shape == (N, 2)


def test_zero_speed_singularity_is_explained():
    flat = ck.two_wheeled_flatness()
    with pytest.raises(ValueError, match=r"singular at zero speed.*atan2\(F2', F1'\) \(2.97\)"):
        flat.psi_u([[0, 0], [0, 0], [1, 0]])
    with pytest.raises(ValueError, match=r"speed must be nonzero and of the same sign at both ends"):
        ck.plan_robot([0, 0, 0], [3, 1, 0], 5.0, speed=0.0)
    with pytest.raises(ValueError, match=r"speed must be nonzero and of the same sign"):
        ck.plan_robot([0, 0, 0], [3, 1, 0], 5.0, speed=[1.0, -1.0])
    # 0 m/s as np.arange(-2, 2.01, 0.1) gives it, 1.8e-15: zero to rounding, refused as 0 (it
    # passed, and psi_x returned NaN with a warning about a missed start pose)
    assert 0 < np.arange(-2, 2.01, 0.1)[20] < 1e-14
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"speed must be nonzero.*zero to rounding"):
            ck.plan_robot([0, 0, 0], [4, 2, np.pi / 2], 6.0, speed=np.arange(-2, 2.01, 0.1)[20])
    assert ck.plan_robot([0, 0, 0], [4, 2, np.pi / 2], 6.0, speed=1e-6).min_speed > 0   # slow, not zero
    # straight back along the x1 axis: F1' goes from +1 to -1 and passes through zero
    with pytest.raises(ValueError, match=r"the planned path stops on the way"):
        ck.plan_robot([0, 0, 0], [-3, 0, np.pi], 5.0, speed=1.0)


def test_flatness_bad_input():
    flat = ck.pendulum_flatness()
    with pytest.raises(ValueError, match=r"derivs must list F and its derivatives \[F, F', \.\.\., F\^\(2\)\]"):
        flat.psi_u([0.1, 0.2])
    with pytest.raises(ValueError, match=r"derivs\[1\] has the wrong number of columns"):
        ck.two_wheeled_flatness().psi_x([[1, 2], [1, 2, 3]])
    with pytest.raises(ValueError, match=r"flat must be a FlatSystem"):
        ck.plan_flat_output("pendulum", 1.0, [0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"end must have the shape of start"):
        ck.plan_flat_output(flat, 1.0, [0, 0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"start has the wrong length: received 2 entries, expected 3"):
        ck.plan_robot([0, 0], [1, 1, 0], 1.0)
    with pytest.raises(ValueError, match=r"L must be positive"):
        ck.car_like_flatness(L=0)
    # a truthy string used to mean "reverse"
    with pytest.raises(ValueError, match=r"reverse must be True or False: received str 'no'"):
        ck.two_wheeled_flatness(reverse="no")
    # complex boundary data were cast to real with numpy's ComplexWarning only
    with pytest.raises(ValueError, match=r"start must contain real numbers"):
        ck.plan_flat_output(flat, 1.0, np.array([0.0, 0.0]) + 0j, [1, 0])
    with pytest.raises(ValueError, match=r"x must contain real numbers"):
        flat.phi([0.1 + 1j, 0.0])
    plan = ck.plan_flat_output(flat, 1.0, [0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"\bt must contain real numbers"):
        plan.input("0.5")
    with pytest.raises(ValueError, match=r"samples must be at least 2"):
        plan.plot(samples=1)


# ---- the planners check their boundary states (issue 14) ----------------------------------

def test_linear_flatness_warns_when_its_maps_miss_2_77_to_2_79():
    # A = diag(1..10), B = ones: controllable, but the CCF transform has cond ~ 3e11, so
    # Lambda e_n = B holds only to ~1e-7 (rounding of a 1e11-conditioned inverse)
    with pytest.warns(ck.AccuracyWarning, match=r"linear_flatness: the flat maps miss .*"
                                                r"Lambda e_n = B holds only to .* condition number"):
        ck.linear_flatness(np.diag(np.arange(1.0, 11.0)), np.ones((10, 1)))


@settings(max_examples=20)
@given(n=st.integers(1, 6), seed=st.integers(0, 10_000), logT=st.floats(-2, 2))
def test_linear_flat_plan_meets_the_requested_states(n, seed, logT):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    flat = ck.linear_flatness(A, B)   # no AccuracyWarning: cond(T) is moderate here
    T = 10.0**logT
    start, end = rng.normal(size=n + 1), rng.normal(size=n + 1)
    plan = ck.plan_flat_output(flat, T, start, end)   # no AccuracyWarning either
    # psi_x of the planned F_d at the ends is psi_x of the requested data (2.78): the trajectory
    # meets its conditions to a few ulps, Lambda adds its rounding (cond(T) eps)
    for when, data in ((0.0, start), (T, end)):
        want = flat.psi_x(list(data[:n]))
        np.testing.assert_allclose(plan.x(when), want, rtol=0, atol=1e-9 * max(1.0, np.abs(want).max()))


@pytest.mark.parametrize("T", [1e200, 1e-300])
def test_flat_plans_with_an_unrepresentable_horizon_are_refused(T):
    flat = ck.pendulum_flatness()
    # T^2 = 1e400 overflows (the planned F_d would be NaN), or 1/T^2 does (F_d'' would be inf)
    with pytest.raises(ValueError, match=r"T = 1e[+-]\d+ is out of reach of double precision"):
        ck.plan_flat_output(flat, T, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])


def test_robot_plan_over_a_huge_horizon_is_finite():
    # issue 35: |F'|^2 overflowed in the search for the slowest point (LinAlgError)
    plan = ck.plan_robot([0.0, 0.0, 0.0], [4.0, 2.0, 1.5], 1e300)
    assert 0 < plan.min_speed <= 1.0
    assert np.isfinite([plan.x(t) for t in np.linspace(0, 1e300, 7)]).all()
    assert np.isfinite([plan.u(t) for t in np.linspace(0, 1e300, 7)]).all()


def test_robot_plan_meets_the_requested_poses():
    # headings compared modulo 2 pi: theta_T = 3 pi / 2 + 2 pi is the same pose as -pi/2
    start, end = [1.0, -2.0, 0.3], [6.0, 1.0, 3 * np.pi / 2 + 2 * np.pi]
    plan = ck.plan_robot(start, end, 7.0, speed=0.7)   # no AccuracyWarning
    np.testing.assert_allclose(plan.x(0.0), start, atol=1e-12)
    np.testing.assert_allclose(plan.x(7.0)[:2], end[:2], atol=1e-12)
    assert np.cos(plan.x(7.0)[2] - end[2]) == pytest.approx(1.0, abs=1e-12)
