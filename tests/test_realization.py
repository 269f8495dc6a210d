"""ode_to_ss, difference_to_ss, euler_discretize: closed forms, SciPy oracle, properties."""

import numpy as np
import pytest
from hypothesis import assume, given, strategies as st
from scipy.linalg import expm
from scipy.signal import ss2tf

import coursekit as ck
from coursekit import models

coef = st.floats(-5, 5, allow_nan=False).map(lambda v: round(v, 3))


def test_ode_to_ss_scalar_b_is_the_ccf_of_1_52_1_53():
    sys = ck.ode_to_ss([2.0, 3.0, 4.0], 5.0)
    np.testing.assert_array_equal(sys.A, [[0, 1, 0], [0, 0, 1], [-2, -3, -4]])
    np.testing.assert_array_equal(sys.B, [[0], [0], [5]])
    np.testing.assert_array_equal(sys.C, [[1, 0, 0]])
    np.testing.assert_array_equal(sys.D, [[0]])
    assert sys.dt is None


def test_ode_to_ss_sequence_b_is_1_66_1_67():
    sys = ck.ode_to_ss([2.0, 3.0, 4.0], [7.0, 8.0, 9.0])
    np.testing.assert_array_equal(sys.B, [[0], [0], [1]])
    np.testing.assert_array_equal(sys.C, [[7, 8, 9]])


def test_mass_spring_damper_realization_equals_the_model():
    m, d, k = 2.0, 0.6, 5.0
    sys = ck.ode_to_ss([k / m, d / m], 1 / m)
    ref = models.mass_spring_damper(m=m, d=d, k=k)
    np.testing.assert_allclose(sys.A, ref.A)
    np.testing.assert_allclose(sys.B, ref.B)
    np.testing.assert_allclose(sys.C, ref.C)


def test_first_order_ode_gives_exponential():
    # (1.12): y' = -3 y, y(0) = 6
    sys = ck.ode_to_ss([3.0], 0.0)
    t = np.linspace(0, 2, 21)
    res = ck.simulate(sys, t, x0=[6.0])
    np.testing.assert_allclose(res.y[:, 0], 6 * np.exp(-3 * t), rtol=1e-10)


def _tf(sys):
    num, den = ss2tf(sys.A, sys.B, sys.C, sys.D)
    return np.atleast_2d(num)[0], den


@given(st.lists(coef, min_size=1, max_size=5), st.data())
def test_realization_transfer_function_is_b_over_a(a, data):
    n = len(a)
    b = data.draw(st.lists(coef, min_size=n, max_size=n))
    sys = ck.ode_to_ss(a, b)
    num, den = _tf(sys)
    # den = s^n + a_{n-1} s^{n-1} + ... + a_0 (descending for scipy)
    np.testing.assert_allclose(den, np.r_[1.0, a[::-1]], atol=1e-8)
    np.testing.assert_allclose(num[-n:], b[::-1], atol=1e-8)
    np.testing.assert_allclose(num[:-n], 0, atol=1e-8)


@given(st.lists(coef, min_size=1, max_size=5), coef)
def test_scalar_b_transfer_function_is_b_over_a(a, b):
    sys = ck.ode_to_ss(a, b)
    num, den = _tf(sys)
    np.testing.assert_allclose(den, np.r_[1.0, a[::-1]], atol=1e-8)
    np.testing.assert_allclose(num[:-1], 0, atol=1e-8)
    np.testing.assert_allclose(num[-1], b, atol=1e-8)


@given(st.lists(coef, min_size=2, max_size=3), st.data())
def test_realization_matches_python_control(a, data):
    control = pytest.importorskip("control")
    n = len(a)
    b = data.draw(st.lists(coef, min_size=n, max_size=n))
    assume(any(abs(v) > 1e-3 for v in b))
    sys = ck.ode_to_ss(a, b)
    ref = control.tf(b[::-1], np.r_[1.0, a[::-1]])
    for s in (0.3 + 1.1j, 2.0j, -0.7 + 0.2j):
        # skip an s that is (nearly) a pole, where both sides are infinite
        assume(abs(np.polyval(np.r_[1.0, a[::-1]], s)) > 1e-3)
        mine = (sys.C @ np.linalg.solve(s * np.eye(n) - sys.A, sys.B))[0, 0]
        assert np.isclose(mine, ref(s), rtol=1e-7, atol=1e-9)


def test_two_realizations_1_63_1_64_give_the_same_output():
    a0, a1, b = 2.0, 0.8, 3.0
    A = [[0, 1], [-a0, -a1]]
    sys63 = ck.StateSpace(A, [[0], [1]], [[b, 0]])
    sys64 = ck.StateSpace(A, [[0], [b]], [[1, 0]])
    t = np.linspace(0, 10, 201)
    u = np.sin(t)[:, None]
    y63 = ck.simulate(sys63, t, u).y
    y64 = ck.simulate(sys64, t, u).y
    np.testing.assert_allclose(y63, y64, atol=1e-12)


def test_difference_to_ss_fibonacci():
    sys = ck.difference_to_ss([-1.0, -1.0], 0.0)
    assert sys.dt == 1.0
    np.testing.assert_array_equal(sys.A, models.fibonacci().A)
    res = ck.simulate(sys, np.arange(11), x0=[0, 1])
    np.testing.assert_array_equal(res.y[:, 0], [0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55])


@given(st.lists(coef, min_size=1, max_size=4), st.data())
def test_discrete_simulation_equals_the_hand_written_recursion(a, data):
    n = len(a)
    b = data.draw(coef)
    u = np.array(data.draw(st.lists(coef, min_size=12, max_size=12)))
    y_init = data.draw(st.lists(coef, min_size=n, max_size=n))
    sys = ck.difference_to_ss(a, b)
    res = ck.simulate(sys, np.arange(12.0), u=u[:, None], x0=y_init)
    # (1.68): y(t+n) = -a_0 y(t) - ... - a_{n-1} y(t+n-1) + b u(t)
    y = list(y_init)
    for t in range(12 - n):
        y.append(-np.dot(a, y[t:t + n]) + b * u[t])
    scale = max(1.0, np.max(np.abs(y)))
    np.testing.assert_allclose(res.y[:, 0], y[:12], atol=1e-9 * scale)


def test_euler_discretize_state_space_matrices():
    sys = models.mass_spring_damper()
    d = ck.euler_discretize(sys, 0.1)
    np.testing.assert_allclose(d.A, np.eye(2) + 0.1 * sys.A)
    np.testing.assert_allclose(d.B, 0.1 * sys.B)
    np.testing.assert_array_equal(d.C, sys.C)
    assert d.dt == 0.1


def test_euler_discretize_lorenz_is_1_46():
    p, Ts = 10.0, 0.01
    d = ck.euler_discretize(models.lorenz(p=p), Ts)
    x = np.array([1.0, -2.0, 0.5])
    x1, x2, x3 = x
    expected = [x1 + Ts * (-p * x1 + p * x2), x2 + Ts * (-x1 * x3 - x2), x3 + Ts * (x1 * x2 - x3)]
    np.testing.assert_allclose(d.f(x, np.zeros(0)), expected)
    assert d.is_discrete and d.dt == Ts


def test_euler_discretize_nonlinear_keeps_the_output_map():
    d = ck.euler_discretize(models.pendulum(), 0.01)
    np.testing.assert_allclose(d.h(np.array([0.3, 1.0]), np.array([0.0])), [0.3])
    # x(t+1) = x + Ts f(x, u)
    x, u = np.array([0.3, 1.0]), np.array([0.5])
    np.testing.assert_allclose(d.f(x, u), x + 0.01 * models.pendulum().f(x, u))


def test_euler_first_order_closed_form():
    # y' = -3 y: Euler gives y(k) = (1 - 3 Ts)^k y0
    Ts = 0.05
    d = ck.euler_discretize(ck.StateSpace([[-3.0]]), Ts)
    res = ck.simulate(d, np.arange(20) * Ts, x0=[6.0])
    np.testing.assert_allclose(res.x[:, 0], 6 * (1 - 3 * Ts) ** np.arange(20))


def _euler_error(A, x0, Ts, t_end=1.0):
    N = int(round(t_end / Ts))
    d = ck.euler_discretize(ck.StateSpace(A), Ts)
    xk = ck.simulate(d, np.arange(N + 1) * Ts, x0=x0).x[-1]
    return np.linalg.norm(xk - expm(np.asarray(A) * t_end) @ x0)


@given(st.lists(st.floats(-2, 2), min_size=4, max_size=4), st.lists(st.floats(-1, 1), min_size=2, max_size=2))
def test_euler_converges_at_first_order(entries, x0):
    A = np.reshape(entries, (2, 2))
    x0 = np.asarray(x0)
    # the leading error term is (t/2) A^2 e^{At} x0 Ts; skip draws where it (nearly) vanishes
    lead = np.linalg.norm(A @ A @ expm(A) @ x0)
    assume(lead > 0.05)
    e1 = _euler_error(A, x0, 1 / 200)
    e2 = _euler_error(A, x0, 1 / 400)
    assert 1.8 < e1 / e2 < 2.2


def test_euler_unstable_for_too_large_step():
    # |1 + Ts lambda| > 1 for lambda = -3 and Ts > 2/3
    d = ck.euler_discretize(ck.StateSpace([[-3.0]]), 0.8)
    res = ck.simulate(d, np.arange(30) * 0.8, x0=[6.0])
    assert abs(res.x[-1, 0]) > 6
    assert abs(d.A[0, 0]) > 1


@pytest.mark.parametrize("call, match", [
    (lambda: ck.ode_to_ss([], 1.0), "empty|at least"),
    (lambda: ck.ode_to_ss([1.0, 2.0], [1.0]), "b has the wrong length"),
    (lambda: ck.ode_to_ss([1.0, np.nan], 1.0), "a contains NaN"),
    (lambda: ck.ode_to_ss([[1.0, 2.0], [3.0, 4.0]], 1.0), "a must be a vector"),
    (lambda: ck.ode_to_ss([1.0], "x"), "b must contain real numbers"),
    (lambda: ck.difference_to_ss([1.0, 2.0], [1.0, 2.0, 3.0]), "b has the wrong length"),
    (lambda: ck.euler_discretize(ck.StateSpace([[-1.0]]), 0.0), "Ts must be positive"),
    (lambda: ck.euler_discretize(ck.StateSpace([[-1.0]], dt=0.1), 0.1), "already a discrete-time"),
    (lambda: ck.euler_discretize(np.eye(2), 0.1), "sys must be a StateSpace or NonlinearSystem"),
])
def test_bad_input_raises_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
