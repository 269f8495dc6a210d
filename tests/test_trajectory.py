"""poly_trajectory, feedforward and open_loop_control (section 2.3)."""

import numpy as np
import pytest
from hypothesis import given, strategies as st

import coursekit as ck


def _random_controllable(n, seed, max_cond=1e6):
    """A random single-input pair with a well-conditioned Wc, or None."""
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > max_cond:
        return None
    return A, B


# ---- polynomial trajectories (2.31)-(2.38) ----------------------------------------------

def test_cubic_matches_the_closed_form_2_34_to_2_38():
    T, x10, x20, x1T, x2T = 2.0, 1.0, -0.5, 3.0, 0.25
    traj = ck.poly_trajectory(T, [x10, x20], [x1T, x2T])
    # (2.34) and (2.38) by hand
    a0, a1 = x10, x20
    a2, a3 = np.linalg.solve([[T**2, T**3], [2 * T, 3 * T**2]], [x1T - (x10 + x20 * T), x2T - x20])
    t = np.linspace(-1, 3, 41)
    np.testing.assert_allclose(traj(t), a0 + a1 * t + a2 * t**2 + a3 * t**3, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(traj(t, 1), a1 + 2 * a2 * t + 3 * a3 * t**2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(traj(t, 2), 2 * a2 + 6 * a3 * t, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(traj(t, 3), 6 * a3 + 0 * t, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(traj(t, 4), 0.0)
    assert traj.degree == 3 and isinstance(traj(1.0), float)


@given(r=st.integers(1, 5), logT=st.floats(-2, 3), seed=st.integers(0, 10_000))
def test_boundary_conditions_hold_for_r_1_to_5_and_T_from_0_01_to_1000(r, logT, seed):
    T = 10.0**logT
    rng = np.random.default_rng(seed)
    start, end = rng.normal(size=r), rng.normal(size=r)
    traj = ck.poly_trajectory(T, start, end)
    # compare derivatives in the natural scale (T/2)^k of each order, relative to the data
    scale = (T / 2) ** np.arange(r)
    size = max(np.abs(start * scale).max(), np.abs(end * scale).max())
    for k in range(r):
        assert abs(traj(0.0, k) - start[k]) * scale[k] <= 1e-11 * size
        assert abs(traj(T, k) - end[k]) * scale[k] <= 1e-11 * size
    # the polynomial has degree 2r - 1: its 2r-th derivative vanishes
    assert traj(0.3 * T, 2 * r) == 0.0


def test_derivative_is_consistent_with_finite_differences():
    traj = ck.poly_trajectory(5.0, [0, 1, 0, 2], [3, 0, -1, 0])
    t = np.linspace(0.5, 4.5, 9)
    h = 1e-5
    for k in range(4):
        fd = (traj(t + h, k) - traj(t - h, k)) / (2 * h)
        np.testing.assert_allclose(traj(t, k + 1), fd, rtol=1e-6, atol=1e-6)


def test_poly_trajectory_bad_input():
    with pytest.raises(ValueError, match=r"T must be positive: received 0.0"):
        ck.poly_trajectory(0.0, [0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"end has the wrong length: received 1 entries, expected 2"):
        ck.poly_trajectory(1.0, [0, 0], [1])
    with pytest.raises(ValueError, match=r"start is empty"):
        ck.poly_trajectory(1.0, [], [])
    with pytest.raises(ValueError, match=r"start contains NaN"):
        ck.poly_trajectory(1.0, [np.nan, 0], [1, 0])
    traj = ck.poly_trajectory(1.0, [0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"k must be a derivative order >= 0: received -1"):
        traj(0.5, -1)
    with pytest.raises(ValueError, match=r"k must be a whole number"):
        traj(0.5, 1.5)


# ---- feedforward (2.25), (2.30) -----------------------------------------------------------

def test_feedforward_of_the_mass_spring_damper_is_2_43():
    m, d, k = 2.0, 0.3, 5.0
    traj = ck.poly_trajectory(3.0, [0.0, 0.0], [1.0, 0.0])
    ud = ck.feedforward([k / m, d / m], 1 / m, traj)
    t = np.linspace(0, 3, 31)
    # (2.30): u_d = k y_d + d y_d' + m y_d''
    np.testing.assert_allclose(ud(t), k * traj(t) + d * traj(t, 1) + m * traj(t, 2), rtol=1e-12)
    # simulated on the plant, the output follows y_d
    res = ck.simulate(ck.models.mass_spring_damper(m=m, d=d, k=k), np.linspace(0, 3, 301),
                      u=lambda t, x: [ud(t)])
    np.testing.assert_allclose(res.y[:, 0], traj(res.t), atol=1e-8)


def test_feedforward_bad_input():
    traj = ck.poly_trajectory(1.0, [0, 0], [1, 0])
    with pytest.raises(ValueError, match=r"b must be nonzero"):
        ck.feedforward([1.0, 2.0], 0.0, traj)
    with pytest.raises(ValueError, match=r"traj must be a function traj\(t, k\)"):
        ck.feedforward([1.0, 2.0], 1.0, [0, 1])
    with pytest.raises(ValueError, match=r"traj\(0.0, 0\) returned shape \(2,\)"):
        ck.feedforward([1.0, 2.0], 1.0, lambda t, k: np.zeros(2))


# ---- open-loop control for a general LTI system (2.73) -------------------------------------

def test_example_2_66_end_to_end():
    A, B = [[0, 2], [1, -3]], [[1], [0]]
    plan = ck.open_loop_control(A, B, x0=[1.0, -1.0], xT=[0.0, 2.0], T=2.0)
    np.testing.assert_allclose(plan.transform, [[0, 1], [1, -3]])  # (2.71)
    np.testing.assert_allclose(plan.a, [-2, 3])  # (2.72): last row [2, -3]
    np.testing.assert_allclose(plan.z0, [-1.0, 4.0])
    t = np.linspace(0, 2, 401)
    res = ck.simulate(ck.StateSpace(A, B), t, u=plan.input, x0=plan.x0)
    np.testing.assert_allclose(res.x[-1], [0.0, 2.0], atol=1e-7)
    np.testing.assert_allclose(res.x, plan.x(t), atol=1e-7)
    # in the z-coordinates the planned state is (y_d, y_d')
    np.testing.assert_allclose(plan.z(t)[:, 1], plan.yd(t, 1))
    assert "OpenLoopPlan" in repr(plan)
    fig = plan.plot()
    ax_x, ax_u = fig.axes
    np.testing.assert_allclose(ax_x.lines[0].get_ydata()[[0, -1]], [1.0, 0.0], atol=1e-12)
    assert ax_u.get_xlabel() == "time t [s]" and fig._suptitle.get_text().startswith("open-loop plan")


@given(n=st.integers(1, 4), seed=st.integers(0, 10_000))
def test_open_loop_steering_lands_on_the_target(n, seed):
    pair = _random_controllable(n, seed)
    if pair is None:
        return
    A, B = pair
    rng = np.random.default_rng(seed + 1)
    x0, xT = rng.normal(size=n), rng.normal(size=n)
    A = A / max(1.0, np.abs(np.linalg.eigvals(A)).max())  # keep e^{A T} moderate
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    plan = ck.open_loop_control(A, B, x0, xT, T=1.5)
    # the plan's transform gives the CCF (2.72) with last row -a
    ccf = ck.similarity_transform(ck.StateSpace(A, B), plan.transform)
    expected = np.eye(n, k=1)
    expected[-1] = -plan.a
    np.testing.assert_allclose(ccf.A, expected, atol=1e-7 * (1 + np.abs(expected).max()))
    np.testing.assert_allclose(ccf.B[:, 0], np.eye(n)[-1], atol=1e-8)
    t = np.linspace(0, 1.5, 151)
    res = ck.simulate(ck.StateSpace(A, B), t, u=plan.input, x0=x0)
    size = 1 + np.abs(plan.x(t)).max()
    np.testing.assert_allclose(res.x[-1], xT, atol=1e-6 * size)
    np.testing.assert_allclose(plan.x(0.0), x0, atol=1e-8 * size)


def test_smooth_plan_starts_and_ends_at_the_holding_input():
    A, B = [[0, 2], [1, -3]], [[1], [0]]
    # xT = [3, 1] is an equilibrium for u = -2: 2*1 + (-2) = 0 and 3 - 3*1 = 0
    plan = ck.open_loop_control(A, B, [0, 0], [3, 1], 3.0, smooth=1)
    assert plan.yd.degree == 5
    assert plan.ud(0.0) == pytest.approx(0.0, abs=1e-12)
    assert plan.ud(3.0) == pytest.approx(-2.0)
    assert plan.ud(10.0) == plan.ud(3.0)  # held after T
    t = np.linspace(0, 6, 601)
    res = ck.simulate(ck.StateSpace(A, B), t, u=plan.input)
    np.testing.assert_allclose(res.x[300], [3, 1], atol=1e-7)
    np.testing.assert_allclose(res.x[-1], [3, 1], atol=1e-5)  # unstable: tiny errors grow after T


def test_open_loop_control_errors():
    with pytest.raises(ck.NotControllableError, match=r"rank 1 < n = 2"):
        # (2.1) with the corrected second line: x1 is not driven by u
        ck.open_loop_control([[-3, 0], [1, -2]], [[0], [1]], [0, 0], [1, 1], 1.0)
    with pytest.raises(ValueError, match=r"xT has the wrong length: received 3 entries, expected 2"):
        ck.open_loop_control([[0, 1], [0, 0]], [[0], [1]], [0, 0], [1, 1, 1], 1.0)
    with pytest.raises(ValueError, match=r"T must be positive"):
        ck.open_loop_control([[0, 1], [0, 0]], [[0], [1]], [0, 0], [1, 1], -1.0)
    with pytest.raises(ValueError, match=r"B must have a single column"):
        ck.open_loop_control(np.eye(2), np.eye(2), [0, 0], [1, 1], 1.0)
    with pytest.raises(ValueError, match=r"smooth must be >= 0"):
        ck.open_loop_control([[0, 1], [0, 0]], [[0], [1]], [0, 0], [1, 1], 1.0, smooth=-1)
