"""simulate: exact LTI path, discrete recursion, ODE path, and input checks."""

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy.linalg import expm
from scipy.signal import lsim

import coursekit as ck

DOUBLE_INTEGRATOR = ck.StateSpace([[0, 1], [0, 0]], [[0], [1]], [[1, 0]])


def test_double_integrator_unit_step_is_t_squared_over_two():
    # non-diagonalizable A: x1 = t^2 / 2, x2 = t for u = 1
    t = np.linspace(0, 3, 31)
    res = ck.simulate(DOUBLE_INTEGRATOR, t, np.ones_like(t), x0=[0, 0])
    np.testing.assert_allclose(res.x[:, 0], t**2 / 2, atol=1e-12)
    np.testing.assert_allclose(res.x[:, 1], t, atol=1e-12)
    np.testing.assert_allclose(res.y[:, 0], t**2 / 2, atol=1e-12)


def test_double_integrator_ramp_input_is_exact_for_piecewise_linear_input():
    # u = t gives x1 = t^3 / 6 exactly (the input is linear between samples)
    t = np.linspace(0, 2, 9)
    res = ck.simulate(DOUBLE_INTEGRATOR, t, t)
    np.testing.assert_allclose(res.x[:, 0], t**3 / 6, atol=1e-12)


def test_free_response_matches_matrix_exponential_on_a_jordan_block():
    A = np.array([[-1.0, 1, 0], [0, -1, 1], [0, 0, -1]])
    sys = ck.StateSpace(A, np.zeros((3, 1)))
    t = np.linspace(0, 4, 41)
    x0 = np.array([1.0, -2, 3])
    res = ck.simulate(sys, t, x0=x0)
    expected = np.array([expm(A * tk) @ x0 for tk in t])
    np.testing.assert_allclose(res.x, expected, atol=1e-9)


def test_non_uniform_grid_gives_the_same_samples_as_a_uniform_one():
    sys = ck.StateSpace([[0, 1], [-2, -0.5]], [[0], [1]])
    t = np.linspace(0, 5, 51)
    u = np.sin(t)
    fine = ck.simulate(sys, t, u, x0=[1, 0])
    keep = np.r_[0, 1, 2, 5, 9, 10, 20, 33, 50]
    coarse = ck.simulate(sys, t[keep], u[keep], x0=[1, 0])
    # piecewise-linear input between the kept samples differs from sin, so compare a linear input
    lin = ck.simulate(sys, t, 0.3 * t, x0=[1, 0])
    lin_coarse = ck.simulate(sys, t[keep], 0.3 * t[keep], x0=[1, 0])
    np.testing.assert_allclose(lin_coarse.x, lin.x[keep], atol=1e-10)
    assert coarse.x.shape == (keep.size, 2) and fine.x.shape == (51, 2)


@given(st.integers(1, 5), st.integers(1, 3), st.integers(0, 10_000))
def test_exact_path_agrees_with_scipy_lsim(n, m, seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) - 1.5 * np.eye(n)
    B, C, D = rng.normal(size=(n, m)), rng.normal(size=(2, n)), rng.normal(size=(2, m))
    t = np.linspace(0, 3, 301)
    u = rng.normal(size=(t.size, m))
    x0 = rng.normal(size=n)
    res = ck.simulate(ck.StateSpace(A, B, C, D), t, u, x0=x0)
    _, y_ref, x_ref = lsim((A, B, C, D), u, t, X0=x0, interp=True)
    scale = 1 + np.abs(x_ref).max()
    np.testing.assert_allclose(res.x, x_ref.reshape(res.x.shape), atol=1e-9 * scale)
    np.testing.assert_allclose(res.y, y_ref.reshape(res.y.shape), atol=1e-9 * scale * (1 + np.abs(C).max()))


def test_callable_state_feedback_agrees_with_closed_loop_matrix():
    sys = ck.StateSpace([[0, 1], [2, -1]], [[0], [1]])
    K = np.array([[-6.0, -3.0]])
    t = np.linspace(0, 4, 81)
    res = ck.simulate(sys, t, lambda tk, x: K @ x, x0=[1, 0])
    closed = ck.simulate(ck.StateSpace(sys.A + sys.B @ K), t, x0=[1, 0])
    np.testing.assert_allclose(res.x, closed.x, atol=1e-8)
    np.testing.assert_allclose(res.u[:, 0], res.x @ K[0], atol=1e-12)


def test_nonlinear_pendulum_conserves_energy():
    g, l = 9.81, 1.0
    pend = ck.NonlinearSystem(lambda x, u: [x[1], -g / l * np.sin(x[0])], n=2)
    t = np.linspace(0, 10, 1001)
    res = ck.simulate(pend, t, x0=[2.0, 0.0])
    energy = 0.5 * res.x[:, 1] ** 2 - g / l * np.cos(res.x[:, 0])
    assert np.ptp(energy) < 1e-7


def test_nonlinear_system_with_array_input_is_interpolated():
    integrator = ck.NonlinearSystem(lambda x, u: u, n=1, m=1)
    t = np.linspace(0, 2, 5)
    res = ck.simulate(integrator, t, 2 * t)   # x = t^2
    np.testing.assert_allclose(res.x[:, 0], t**2, atol=1e-8)


@given(st.integers(1, 4), st.integers(0, 10_000))
def test_discrete_lti_equals_hand_written_recursion(n, seed):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)) / n, rng.normal(size=(n, 1))
    u = rng.normal(size=(20, 1))
    x0 = rng.normal(size=n)
    res = ck.simulate(ck.StateSpace(A, B, dt=0.5), 0.5 * np.arange(20), u, x0=x0)
    x = x0.copy()
    for k in range(20):
        np.testing.assert_allclose(res.x[k], x, atol=1e-12)
        x = A @ x + B @ u[k]


def test_discrete_nonlinear_map_and_callable_input():
    logistic = ck.NonlinearSystem(lambda x, u: 3.2 * x * (1 - x) + u, n=1, m=1, dt=1)
    res = ck.simulate(logistic, np.arange(6), lambda k, x: [0.0], x0=[0.3])
    x = 0.3
    for k in range(6):
        assert res.x[k, 0] == pytest.approx(x)
        x = 3.2 * x * (1 - x)


@pytest.mark.parametrize("kwargs, message", [
    (dict(t=[0, 1, 1, 2]), r"t must be strictly increasing"),
    (dict(t=[0, 1, np.nan]), r"t contains NaN"),
    (dict(t=[0.0]), r"t has too few points"),
    (dict(u=np.ones((5, 2))), r"u has the wrong number of columns: received shape \(5, 2\)"),
    (dict(u=np.ones((4, 1))), r"u has the wrong number of rows"),
    (dict(x0=[1, 2, 3]), r"x0 has the wrong length: received 3 entries, expected 2"),
    (dict(u=lambda t, x: [1.0, 2.0]), r"u returned shape \(2,\); expected 1 numbers"),
])
def test_bad_arguments_name_the_argument(kwargs, message):
    args = dict(t=np.linspace(0, 1, 5), u=None, x0=None) | kwargs
    with pytest.raises(ValueError, match=message):
        ck.simulate(DOUBLE_INTEGRATOR, **args)


def test_bad_vector_field_is_explained_before_integrating():
    bad = ck.NonlinearSystem(lambda x, u: [x[1]], n=2)
    with pytest.raises(ValueError, match=r"f returned shape \(1,\); expected 2 numbers \(dx/dt"):
        ck.simulate(bad, np.linspace(0, 1, 3), x0=[0, 1])
    forgot = ck.NonlinearSystem(lambda x, u: None, n=2)
    with pytest.raises(ValueError, match=r"forget to return"):
        ck.simulate(forgot, np.linspace(0, 1, 3))


def test_discrete_grid_must_step_by_dt():
    with pytest.raises(ValueError, match=r"t must step by the system's sampling period dt=1"):
        ck.simulate(ck.StateSpace([[1.03]], [[1]], dt=1), np.linspace(0, 1, 5))


def test_not_a_system_is_rejected():
    with pytest.raises(ValueError, match=r"sys must be a StateSpace or NonlinearSystem"):
        ck.simulate([[0, 1], [0, 0]], np.linspace(0, 1, 3))


def test_batch_matches_one_at_a_time_for_the_pendulum_under_feedback():
    pend = ck.models.pendulum(d_theta=0.2)
    K = np.array([[-20.0, -5.0]])
    t = np.linspace(0, 3, 61)
    x0s = np.array([[0.5, 0], [1.5, 0], [-2.5, 1.0]])
    batch = ck.simulate_batch(pend, t, x0s, u=lambda tk, X: K @ X)
    assert batch.shape == (61, 3, 2)
    for j, x0 in enumerate(x0s):
        single = ck.simulate(pend, t, lambda tk, x: K @ x, x0=x0)
        np.testing.assert_allclose(batch[:, j], single.x, atol=1e-7)


def test_batch_rejects_a_vector_field_that_cannot_take_a_batch():
    scalar_only = ck.NonlinearSystem(lambda x, u: [float(x[1]), -float(x[0])], n=2)
    with pytest.raises(ValueError, match=r"f cannot be evaluated on a batch"):
        ck.simulate_batch(scalar_only, np.linspace(0, 1, 3), [[1, 0], [0, 1]])


@pytest.mark.parametrize("A", [
    [[0.0, 1.0], [-4.0, -0.2]],                    # a complex pair: one complex filter
    [[-1.0, 1.0], [-1e-12, -1.0]],                 # a nearly repeated pair: complex Schur fallback
    [[-1.0, 1.0, 0, 0], [0, -1.0, 1.0, 0], [0, 0, -1.0, 0], [0, 0, 0, 0.5]],  # Jordan block
])
def test_exact_path_matches_the_solution_formula_for_every_block_type(A):
    A = np.array(A)
    n = A.shape[0]
    B = np.ones((n, 1))
    t = np.linspace(0, 3, 61)
    u = np.cos(2 * t)
    x0 = np.arange(1.0, n + 1)
    res = ck.simulate(ck.StateSpace(A, B), t, u, x0=x0)
    # reference: the same piecewise-linear input, stepped with the one-step matrices
    Ad, B0, B1 = ck.lti_step_matrices(A, B, t[1] - t[0])
    x = x0.copy()
    for k in range(t.size):
        np.testing.assert_allclose(res.x[k], x, rtol=1e-10, atol=1e-10)
        if k + 1 < t.size:
            x = Ad @ x + B0[:, 0] * u[k] + B1[:, 0] * u[k + 1]


@given(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.booleans(), st.integers(0, 10_000))
def test_first_order_recursion_is_the_filter_it_replaces(re, im, complex_pole, seed):
    from scipy.signal import lfilter
    from coursekit.simulation import _first_order
    a = complex(re, im) if complex_pole else re
    v = np.random.default_rng(seed).normal(size=50)
    expected = lfilter([1.0], [1.0, -a], v)
    np.testing.assert_allclose(_first_order(a, v.copy()), expected, rtol=1e-12, atol=1e-12)


def test_exact_simulation_does_not_need_scipy_signal():
    import subprocess
    import sys
    code = ("import sys, numpy as np, coursekit as ck; "
            "ck.simulate(ck.StateSpace([[0, 1], [-4, -0.2]], [[0], [1]]), np.linspace(0, 1, 11), np.ones(11)); "
            "print('scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
