"""kalman_gain, the Kalman-Bucy filter, the EKF and the noise helpers (section 4.7)."""

import importlib
import math
import re

import control
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck

A = np.array([[0, 1], [-2, -0.5]])      # mass-spring-damper, position measured
B = np.array([[0], [1.0]])
C = np.array([[1, 0.0]])
Q = np.diag([0.0, 0.5])
R = np.array([[0.02]])


def _riccati_exact(A, C, Q, R, P0, t):
    """P(t) of (4.88) in closed form: P = Y X^{-1} with [X; Y]' = [[-A^T, C^T R^-1 C], [Q, A]] [X; Y]."""
    from scipy.linalg import expm
    n = A.shape[0]
    H = np.block([[-A.T, C.T @ np.linalg.solve(R, C)], [Q, A]])
    XY = expm(H * t) @ np.vstack([np.eye(n), P0])
    return np.linalg.solve(XY[:n].T, XY[n:].T).T


def _random_detectable(n, p, seed):
    rng = np.random.default_rng(seed)
    A_, C_ = rng.normal(size=(n, n)), rng.normal(size=(p, n))
    if np.linalg.cond(ck.obsv(A_, C_)) > 1e5:
        return None
    return A_, C_


@given(st.integers(1, 5), st.integers(1, 2), st.integers(0, 10_000))
def test_kalman_gain_matches_lqe_and_solves_the_are(n, p, seed):
    drawn = _random_detectable(n, p, seed)
    if drawn is None:
        return
    A_, C_ = drawn
    rng = np.random.default_rng(seed + 1)
    G = rng.normal(size=(n, n))
    Q_, R_ = G @ G.T + 0.1 * np.eye(n), np.diag(rng.uniform(0.1, 2, size=p))
    L, P = ck.kalman_gain(A_, C_, Q_, R_)
    assert L.shape == (n, p) and P.shape == (n, n)
    residual = A_ @ P + P @ A_.T - P @ C_.T @ np.linalg.solve(R_, C_ @ P) + Q_
    assert np.abs(residual).max() < 1e-7 * max(1.0, np.abs(P).max()) ** 2
    assert np.linalg.eigvalsh(P).min() > 0
    assert np.linalg.eigvals(A_ - L @ C_).real.max() < 0
    L_ref, P_ref, _ = control.lqe(A_, np.eye(n), C_, Q_, R_)   # same sign: observer A - L C
    np.testing.assert_allclose(L, L_ref, rtol=1e-6, atol=1e-8 * np.abs(L_ref).max())
    np.testing.assert_allclose(P, P_ref, rtol=1e-6, atol=1e-8 * np.abs(P_ref).max())


def test_kalman_gain_is_the_dual_of_lqr():
    # LQR for (A^T, C^T) with weights (Q, R) gives K_lqr = R^-1 C P, so L = K_lqr^T
    K_lqr, S, _ = control.lqr(A.T, C.T, Q + 1e-3 * np.eye(2), R)
    L, P = ck.kalman_gain(A, C, Q + 1e-3 * np.eye(2), R)
    np.testing.assert_allclose(P, S, rtol=1e-8)
    np.testing.assert_allclose(L, K_lqr.T, rtol=1e-8)


def test_riccati_ode_follows_the_closed_form_and_tends_to_the_are():
    t = np.linspace(0, 20, 2001)
    sys = ck.StateSpace(A, B, C)
    P0 = np.diag([2.0, 1.0])
    res = ck.kalman_bucy(sys, t, None, np.zeros((t.size, 1)), Q, R, P0, [0, 0], substeps=4)
    for k in (5, 50, 300):
        np.testing.assert_allclose(res.P[k], _riccati_exact(A, C, Q, R, P0, t[k]), rtol=1e-5, atol=1e-7)
    L, P = ck.kalman_gain(A, C, Q, R)
    np.testing.assert_allclose(res.P[-1], P, atol=1e-9)
    np.testing.assert_allclose(res.L[-1], L, atol=1e-8)
    np.testing.assert_allclose(res.P[0], P0)
    assert np.abs(res.P[20] - P).max() > 1e-2          # it really moved


@settings(max_examples=5)
@given(st.integers(1, 3), st.integers(0, 10_000))
def test_riccati_ode_limit_is_the_are_solution_random(n, seed):
    drawn = _random_detectable(n, 1, seed)
    if drawn is None:
        return
    A_, C_ = drawn
    Q_, R_ = np.eye(n), np.array([[0.5]])
    L, P = ck.kalman_gain(A_, C_, Q_, R_)
    rate = -np.linalg.eigvals(A_ - L @ C_).real.max()
    if rate < 0.2:
        return
    t = np.linspace(0, 30 / rate, 1000)
    res = ck.kalman_bucy(ck.StateSpace(A_, np.zeros((n, 1)), C_), t, None, np.zeros((t.size, 1)),
                         Q_, R_, np.eye(n), np.zeros(n), substeps=2)
    np.testing.assert_allclose(res.P[-1], P, rtol=1e-6, atol=1e-7 * max(1.0, np.abs(P).max()))


def test_ekf_on_a_linear_system_reproduces_kalman_bucy():
    t = np.linspace(0, 8, 801)
    sys = ck.StateSpace(A, B, C)
    u = np.sin(t)[:, None]
    data = ck.simulate_with_noise(sys, t, u, x0=[1, 0], Q=Q, R=R, seed=4)
    P0 = np.eye(2)
    kb = ck.kalman_bucy(sys, t, u, data.y, Q, R, P0, [0, 0])
    nl = ck.NonlinearSystem(lambda x, v: A @ x + B @ v, n=2, m=1, h=lambda x, v: C @ x)
    ekf = ck.extended_kalman_filter(nl, t, u, data.y, Q, R, P0, [0, 0])
    np.testing.assert_allclose(ekf.x, kb.x, atol=1e-8)
    np.testing.assert_allclose(ekf.P, kb.P, atol=1e-8)
    given_jac = ck.extended_kalman_filter(nl, t, u, data.y, Q, R, P0, [0, 0],
                                          dfdx=lambda x, v: A, dhdx=lambda x, v: C)
    np.testing.assert_allclose(given_jac.x, kb.x, atol=1e-12)
    # and the estimate does track the true state
    assert np.sqrt(np.mean((kb.x[200:] - data.x[200:]) ** 2)) < 0.5


def test_ekf_pendulum_converges_from_a_wrong_estimate():
    pend = ck.models.pendulum(d_theta=0.2)
    meas = ck.NonlinearSystem(pend.f, n=2, m=1, h=lambda x, u: np.array([np.sin(x[0])]))
    t = np.linspace(0, 10, 1001)
    data = ck.simulate_with_noise(meas, t, None, x0=[1.0, 0.0], Q=np.diag([0, 1e-3]),
                                  R=[[1e-4]], seed=5)
    ekf = ck.extended_kalman_filter(meas, t, None, data.y, np.diag([1e-4, 1e-2]), [[1e-4]],
                                    np.eye(2), [0.3, 1.0])
    assert np.abs(ekf.x[0] - data.x[0]).max() > 0.5
    assert np.abs(ekf.x[-100:] - data.x[-100:]).max() < 0.05
    assert ekf.sigma.shape == (t.size, 2)


def test_noise_units_error_covariance_matches_p():
    """A steady-state Kalman observer on simulated data: its error covariance is P.

    This checks the documented units: samples of covariance intensity / dt.
    """
    dt = 0.01
    t = np.arange(0, 400, dt)
    sys = ck.StateSpace(A, B, C)
    data = ck.simulate_with_noise(sys, t, None, Q=Q, R=R, seed=3)
    L, P = ck.kalman_gain(A, C, Q, R)
    est = ck.simulate(ck.observer_system(sys, L), t, u=np.hstack([data.u, data.y]))
    err = est.x[1000:] - data.x[1000:]
    np.testing.assert_allclose(np.cov(err.T), P, rtol=0.15, atol=0.01)
    # the state itself: stationary covariance from the Lyapunov equation A X + X A^T + Q = 0
    np.testing.assert_allclose(np.cov(data.x[1000:].T), np.diag([0.25, 0.5]), rtol=0.2, atol=0.02)


def test_white_noise_variance_scales_with_one_over_dt():
    for dt in (0.1, 0.01):
        t = np.arange(20000) * dt
        w = ck.white_noise(t, [[0.5]], seed=1)
        assert w.shape == (20000, 1)
        assert abs(w.var() * dt / 0.5 - 1) < 0.05
    w2 = ck.white_noise(np.arange(5000) * 0.1, np.diag([1.0, 4.0]), seed=2)
    np.testing.assert_allclose(np.cov(w2.T), np.diag([10.0, 40.0]), rtol=0.1, atol=1.0)
    np.testing.assert_array_equal(ck.white_noise(t, 1.0, seed=7), ck.white_noise(t, 1.0, seed=7))


def test_simulate_with_noise_is_seeded_and_noise_free_limit():
    t = np.linspace(0, 3, 301)
    sys = ck.StateSpace(A, B, C)
    a = ck.simulate_with_noise(sys, t, np.ones((301, 1)), x0=[1, 0], Q=Q, R=R, seed=11)
    b = ck.simulate_with_noise(sys, t, np.ones((301, 1)), x0=[1, 0], Q=Q, R=R,
                               seed=np.random.default_rng(11))
    np.testing.assert_array_equal(a.y, b.y)
    quiet = ck.simulate_with_noise(sys, t, np.ones((301, 1)), x0=[1, 0], Q=np.zeros((2, 2)),
                                   R=[[0]], seed=0)
    exact = ck.simulate(sys, t, np.ones((301, 1)), x0=[1, 0])
    np.testing.assert_allclose(quiet.x, exact.x, atol=1e-10)
    pend = ck.models.pendulum()
    quiet = ck.simulate_with_noise(pend, t, None, x0=[0.5, 0], Q=np.zeros((2, 2)), R=[[0]])
    np.testing.assert_allclose(quiet.x, ck.simulate(pend, t, x0=[0.5, 0]).x, atol=1e-6)


@pytest.mark.parametrize("kwargs, message", [
    (dict(R=[[0.0]]), r"R must be positive definite"),
    (dict(Q=[[1, 2], [0, 1]]), r"Q must be symmetric"),
    (dict(Q=np.diag([1, -1.0])), r"Q must be positive semidefinite"),
    (dict(Q=np.eye(3)), r"Q has the wrong size: received shape \(3, 3\), expected \(2, 2\)"),
])
def test_kalman_gain_bad_weights(kwargs, message):
    args = dict(A=A, C=C, Q=Q, R=R) | kwargs
    with pytest.raises(ValueError, match=message):
        ck.kalman_gain(**args)


def test_kalman_gain_undetectable():
    with pytest.raises(ValueError, match=r"no stabilizing solution"):
        ck.kalman_gain(np.diag([1.0, -1.0]), [[0, 1]], np.eye(2), [[1]])


def test_filter_bad_inputs():
    t = np.linspace(0, 1, 11)
    sys = ck.StateSpace(A, B, C)
    with pytest.raises(ValueError, match=r"y has the wrong number of rows"):
        ck.kalman_bucy(sys, t, None, np.zeros((10, 1)), Q, R, np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"y has the wrong number of columns: received 2, expected 1"):
        ck.kalman_bucy(sys, t, None, np.zeros((11, 2)), Q, R, np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"P0 must be positive definite"):
        ck.kalman_bucy(sys, t, None, np.zeros((11, 1)), Q, R, np.zeros((2, 2)), [0, 0])
    with pytest.raises(ValueError, match=r"x0 has the wrong length"):
        ck.kalman_bucy(sys, t, None, np.zeros((11, 1)), Q, R, np.eye(2), [0, 0, 0])
    with pytest.raises(ValueError, match=r"sys must be a continuous-time NonlinearSystem"):
        ck.extended_kalman_filter(sys, t, None, np.zeros((11, 1)), Q, R, np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"sys must be a continuous-time StateSpace"):
        ck.kalman_bucy(ck.models.pendulum(), t, None, np.zeros((11, 1)), Q, R, np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"y has the wrong number of columns: received 2, expected 1"):
        ck.extended_kalman_filter(ck.models.pendulum(), t, None, np.zeros((11, 2)), Q,
                                  np.eye(2), np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"substeps must be positive"):
        ck.kalman_bucy(sys, t, None, np.zeros((11, 1)), Q, R, np.eye(2), [0, 0], substeps=0)
    with pytest.raises(ValueError, match=r"dfdx must be a function"):
        ck.extended_kalman_filter(ck.models.pendulum(), t, None, np.zeros((11, 1)), Q, R,
                                  np.eye(2), [0, 0], dfdx=np.eye(2))


def test_noise_bad_inputs():
    with pytest.raises(ValueError, match=r"t must be uniformly spaced"):
        ck.white_noise([0, 1, 3], 1.0)
    with pytest.raises(ValueError, match=r"seed must be an int"):
        ck.white_noise([0, 1, 2], 1.0, seed="x")
    with pytest.raises(ValueError, match=r"R must be positive semidefinite"):
        ck.simulate_with_noise(ck.StateSpace(A, B, C), [0, 1, 2], Q=Q, R=[[-1]])


@settings(max_examples=40)
@given(st.integers(1, 4), st.integers(0, 10_000), st.floats(1e-4, 1.0))
def test_step_length_shortcut_is_the_exact_rule(n, seed, h_max):
    # the RK4 step is min(h_max, 0.5 / rate); the cheap bound may only skip the eigenvalues when
    # they could not shorten the step, so the result must equal the exact rule every time
    from coursekit._filter_ode import _radius_bound, _riccati_rate, _step_length
    rng = np.random.default_rng(seed)
    A_, L_, C_ = rng.normal(size=(n, n)) * 10 ** rng.uniform(-1, 2), rng.normal(size=(n, 1)), rng.normal(size=(1, n))
    M = A_ - L_ @ C_
    assert _radius_bound(M) >= np.abs(np.linalg.eigvals(M)).max()
    exact = min(h_max, 0.5 / max(_riccati_rate(M), 1e-300))
    assert _step_length(M, h_max) == exact


def _ekf_of(sys_, **kw):
    """The linear system as a NonlinearSystem: the EKF then runs (4.86)-(4.88) step by step."""
    return ck.NonlinearSystem(lambda x, v: sys_.A @ x + sys_.B @ v, n=sys_.n, m=sys_.m,
                              h=lambda x, v: sys_.C @ x + sys_.D @ v, **kw)


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 3), st.integers(1, 2), st.integers(0, 2), st.integers(1, 3), st.integers(0, 10_000))
def test_kalman_bucy_two_passes_equal_the_coupled_integration(n, p, m, substeps, seed):
    # kalman_bucy integrates P first, then x̂ through affine RK4 steps; the EKF with the exact
    # Jacobians integrates x̂ and P together, stage by stage. Same RK4, same steps: same numbers.
    # A large P0 and a small R make the first intervals take many short steps; the uneven grid
    # repeats a few step lengths, so settled intervals are reused with the right dt.
    rng = np.random.default_rng(seed)
    sys_ = ck.StateSpace(rng.normal(size=(n, n)) - np.eye(n), rng.normal(size=(n, m)),
                         rng.normal(size=(p, n)), rng.normal(size=(p, m)))
    t = np.concatenate([[0.0], np.cumsum(rng.choice([0.01, 0.02, 0.035], size=200))])
    u = rng.normal(size=(t.size, m)) if m else None
    y = rng.normal(size=(t.size, p))
    G = rng.normal(size=(n, n))
    Q, R = G @ G.T, np.diag(10 ** rng.uniform(-3, -1, size=p))
    P0, x0 = 3 * np.eye(n), rng.normal(size=n)
    kb = ck.kalman_bucy(sys_, t, u, y, Q, R, P0, x0, substeps=substeps)
    ekf = ck.extended_kalman_filter(_ekf_of(sys_), t, u, y, Q, R, P0, x0, substeps=substeps,
                                    dfdx=lambda x, v: sys_.A, dhdx=lambda x, v: sys_.C)
    for a, b in ((kb.x, ekf.x), (kb.P, ekf.P), (kb.L, ekf.L)):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.abs(b).max())


def test_kalman_bucy_long_run_with_settled_riccati():
    # P reaches the ARE within a few seconds; the rest of the 60 s run reuses settled intervals
    rng = np.random.default_rng(2)
    t = np.concatenate([[0.0], np.cumsum(rng.choice([0.005, 0.01, 0.02], size=4000))])
    sys_ = ck.StateSpace(A, B, C)
    u = np.sin(t)[:, None]
    y = rng.normal(size=(t.size, 1))
    kb = ck.kalman_bucy(sys_, t, u, y, Q, R, np.eye(2), [1.0, 0.0])
    ekf = ck.extended_kalman_filter(_ekf_of(sys_), t, u, y, Q, R, np.eye(2), [1.0, 0.0],
                                    dfdx=lambda x, v: A, dhdx=lambda x, v: C)
    np.testing.assert_allclose(kb.x, ekf.x, rtol=1e-10, atol=1e-11)
    np.testing.assert_allclose(kb.P, ekf.P, rtol=1e-10, atol=1e-13)
    _, P = ck.kalman_gain(A, C, Q, R)
    np.testing.assert_allclose(kb.P[-1], P, rtol=1e-9)


def _pendulum_camera(f):
    return ck.NonlinearSystem(f, n=2, m=1, h=lambda x, u: np.array([np.sin(x[0])]))


def _pendulum_one_state_at_a_time(x, u):
    # the damped pendulum of models.pendulum(d_theta=0.3), written with floats: no batches
    theta, omega = float(x[0]), float(x[1])
    return np.array([omega, -0.3 * omega - 9.81 * math.sin(theta) + float(u[0])])


def test_batch_check_accepts_models_and_refuses_what_it_must():
    from coursekit.ekf import _accepts_batches
    x0, u0 = np.array([0.4, -1.3]), np.array([0.2])
    pend = ck.models.pendulum(d_theta=0.3)
    assert _accepts_batches(pend.f, x0, u0) and _accepts_batches(pend.h, x0, u0)
    assert _accepts_batches(_pendulum_camera(pend.f).h, x0, u0)
    assert not _accepts_batches(_pendulum_one_state_at_a_time, x0, u0)           # raises on a batch
    assert not _accepts_batches(lambda x, u: x - x.mean(), x0, u0)                # mixes the columns
    assert not _accepts_batches(lambda x, u: np.ravel(x)[:2], x0, u0)            # wrong shape


@pytest.mark.parametrize("given_jacobian", [None, "dfdx", "dhdx"])
def test_ekf_falls_back_to_one_state_at_a_time(given_jacobian):
    # the same pendulum written for batches (numpy rows) and for one state (floats): the EKF
    # batches the first and calls the second once per perturbed state; the filters must agree
    t = np.linspace(0, 5, 501)
    batch_sys = _pendulum_camera(ck.models.pendulum(d_theta=0.3).f)
    single_sys = _pendulum_camera(_pendulum_one_state_at_a_time)
    data = ck.simulate_with_noise(batch_sys, t, None, x0=[1.0, 0.0], Q=np.diag([0, 1e-3]),
                                  R=[[1e-4]], seed=7)
    jac = {"dfdx": lambda x, u: np.array([[0, 1], [-9.81 * np.cos(x[0]), -0.3]]),
           "dhdx": lambda x, u: np.array([[np.cos(x[0]), 0.0]])}
    kw = {given_jacobian: jac[given_jacobian]} if given_jacobian else {}
    args = (t, None, data.y, np.diag([1e-4, 1e-2]), [[1e-4]], np.eye(2), [0.3, 1.0])
    batched = ck.extended_kalman_filter(batch_sys, *args, **kw)
    single = ck.extended_kalman_filter(single_sys, *args, **kw)
    np.testing.assert_allclose(batched.x, single.x, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(batched.P, single.P, rtol=1e-8, atol=1e-12)
    exact = ck.extended_kalman_filter(batch_sys, *args, **jac)
    np.testing.assert_allclose(batched.x, exact.x, atol=1e-5)        # differences ~ eps^(2/3)
    assert np.abs(batched.x[-100:, 0] - data.x[-100:, 0]).max() < 0.05


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning",
                            "ignore:invalid value encountered:RuntimeWarning")
def test_filters_report_divergence_and_too_many_steps(monkeypatch):
    t = np.linspace(0, 1, 11)
    unseen = ck.StateSpace([[700.0]], [[0.0]], [[0.0]])       # unstable and unobserved: P overflows
    with pytest.raises(RuntimeError, match=r"the filter diverged at t=0.6 \(non-finite estimate or P\)"):
        ck.kalman_bucy(unseen, t, None, np.zeros((11, 1)), [[1.0]], [[1.0]], [[1.0]], [1.0])
    huge_force = ck.StateSpace([[-1.0]], [[1e10]], [[1.0]])     # P stays finite, x̂ overflows
    with pytest.raises(RuntimeError, match=r"the filter diverged at t=0.1 \(non-finite estimate"):
        ck.kalman_bucy(huge_force, t, np.full((11, 1), 1e300), np.zeros((11, 1)), [[1.0]], [[1.0]],
                       [[1.0]], [0.0])
    blow_up = ck.NonlinearSystem(lambda x, u: x**2, n=1, h=lambda x, u: 0 * x)   # x' = x^2 from 1
    with pytest.raises(RuntimeError, match=r"the filter diverged at t=1.1"):
        ck.extended_kalman_filter(blow_up, np.linspace(0, 2, 21), None, np.zeros((21, 1)),
                                  [[0.0]], [[1.0]], [[1.0]], [1.0])
    monkeypatch.setattr(importlib.import_module("coursekit._filter_ode"), "_MAX_STEPS", 50)
    fast = {"Q": np.eye(2), "R": [[1e-8]], "P0": 1e3 * np.eye(2), "x0": [0, 0]}   # rate ~ 1e6 at first
    with pytest.raises(RuntimeError, match=r"needs more than 50 RK4 steps between two samples"):
        ck.kalman_bucy(ck.StateSpace(A, B, C), t, None, np.zeros((11, 1)), **fast)
    with pytest.raises(RuntimeError, match=r"needs more than 50 RK4 steps between two samples"):
        ck.extended_kalman_filter(ck.models.pendulum(), t, None, np.zeros((11, 1)), **fast)


# --- kalman_gain checks itself (issue 14) ------------------------------------------------------

@pytest.mark.parametrize("A_, C_, mode", [
    (np.array([[0, 1], [-1, 0.0]]), C, r"0 ± 1j"),               # undamped oscillator
    (np.array([[0, 1], [0, 0.0]]), C, r"0"),                      # double integrator
])
def test_kalman_gain_refuses_an_undriven_mode_on_the_imaginary_axis(A_, C_, mode):
    # with Q = 0 SciPy returns P = 0, so L = 0 and A - L C = A is not stable: an error, not a gain
    with pytest.raises(ValueError, match=rf"no stabilizing solution \(A - L C would not be stable\): "
                                         rf"the mode λ = {mode} of A .*lies on the imaginary axis and the "
                                         r"process noise Q does not drive it.*Q = q \* np\.eye\(n\)"):
        ck.kalman_gain(A_, C_, np.zeros((2, 2)), R)
    L, _ = ck.kalman_gain(A_, C_, 1e-6 * np.eye(2), R)         # a little Q is enough
    assert np.linalg.eigvals(A_ - L @ C_).real.max() < 0


def test_kalman_gain_accepts_an_undriven_stable_mode_far_from_the_fast_ones():
    # Q = 0 and stable A: P = 0 and L = 0 are right (A - L C = A is stable), even with poles spread
    # over eight decades (the tolerance for "on the axis" scales with the balanced norm of A)
    A_ = -np.diag([1.0, 1e4, 1e8])
    L, P = ck.kalman_gain(A_, np.ones((1, 3)), np.zeros((3, 3)), [[1.0]])
    assert np.all(L == 0) and np.all(P == 0)


def test_kalman_gain_undetectable_names_the_mode():
    with pytest.raises(ValueError, match=r"the mode λ = 1 of A \(eigenvector \[1\. 0\.\]\) is unstable "
                                         r"and not observable through C \(C v = 0\).*change|the mode"):
        ck.kalman_gain(np.diag([1.0, -1.0]), [[0, 1]], np.diag([0.0, 1.0]), [[1]])


@pytest.mark.parametrize("kwargs, message", [
    (dict(C=np.eye(2)), r"R has the wrong size: received shape \(1, 1\), expected \(2, 2\) \(one row and "
                        r"column per output, since C has 2 rows; if the system has another number of "
                        r"outputs, check C\)"),
    (dict(C=[[1, 0, 0]]), r"C has the wrong number of columns"),
    (dict(Q=np.eye(3)), r"Q has the wrong size: received shape \(3, 3\), expected \(2, 2\) \(one row and "
                        r"column per state, since A is 2x2\)"),
    (dict(A=np.eye(3), Q=np.eye(3)), r"C has the wrong number of columns"),
])
def test_kalman_gain_errors_name_the_argument(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ck.kalman_gain(**(dict(A=A, C=C, Q=Q, R=R) | kwargs))


def _perturbed_solver(monkeypatch, change):
    import scipy.linalg
    exact = scipy.linalg.solve_continuous_are
    monkeypatch.setattr(scipy.linalg, "solve_continuous_are", lambda *a: change(exact(*a)))


def test_kalman_gain_warns_about_a_large_residual(monkeypatch):
    # a solver that returns P 1e-4 off: still stabilizing, but the residual is ~1e-4 of its terms
    _perturbed_solver(monkeypatch, lambda P: P * (1 + 1e-4))
    with pytest.warns(ck.AccuracyWarning, match=r"solved only to [0-9.]+e-0[45] of the size of its terms"):
        ck.kalman_gain(A, C, Q + 0.1 * np.eye(2), R)


def test_kalman_gain_warns_about_an_indefinite_p(monkeypatch):
    # P with a negative eigenvalue (the stabilizing solution is always >= 0)
    def indefinite(P):
        # move the smallest eigenvalue of P to -1e-3 of the largest, keep the eigenvectors
        vals, vecs = np.linalg.eigh(P)
        vals[0] = -1e-3 * vals[-1]
        return (vecs * vals) @ vecs.T
    _perturbed_solver(monkeypatch, indefinite)
    with pytest.warns(ck.AccuracyWarning) as record:          # the residual is off as well
        ck.kalman_gain(A, C, Q + 0.1 * np.eye(2), R)
    assert any(re.search(r"P is not positive semidefinite \(eigenvalue -[0-9.e-]+ after scaling",
                         str(w.message)) for w in record)


def test_kalman_gain_residual_check_is_quiet_on_exact_solutions():
    # the explorer's slider range (log10 Q in -4..3, log10 R in -6..0) on the vehicle with GPS: no
    # warning may appear (pytest turns them into errors), and the relative residual is tiny
    from coursekit.kalman import _riccati_residual
    veh = ck.models.vehicle(m=1.0, d=1.0, sensor="gps")
    for q in np.arange(-4, 3.1, 1.0):
        for r in np.arange(-6, 0.1, 1.0):
            Q_, R_ = np.diag([0.0, 10**q]), np.array([[10**r]])
            L, P = ck.kalman_gain(veh.A, veh.C, Q_, R_)
            assert _riccati_residual(veh.A, veh.C, Q_, R_, P, None) < 1e-12


# --- the EKF reports errors of the user's functions with their time -----------------------------

def _scalar_system(f, h=lambda x, u: 0 * x):
    return ck.NonlinearSystem(f, n=1, h=h)


T11, Y0 = np.linspace(0, 1, 11), np.zeros((11, 1))
EKF_ARGS = dict(Q=[[0.0]], R=[[1.0]], P0=[[1.0]])


def test_ekf_wraps_an_exception_of_f_with_its_name_and_time():
    with pytest.raises(ck.UserFunctionError, match=r"f raised ZeroDivisionError at t = 0") as info:
        ck.extended_kalman_filter(_scalar_system(lambda x, u: 1 / 0), T11, None, Y0, x0=[0.0], **EKF_ARGS)
    assert isinstance(info.value.__cause__, ZeroDivisionError)


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")
@pytest.mark.parametrize("batched", [True, False])
def test_ekf_catches_nan_from_f_at_the_time_it_appears(batched):
    # x̂' = -1 from x̂ = 0.45, y carries no information: x̂ and its difference neighbours go below 0
    # (sqrt -> NaN) shortly before t = 0.45. Written for batches or for one state (float) at a time.
    if batched:
        f = lambda x, u: -1 + 0 * np.sqrt(x)
    else:
        f = lambda x, u: np.array([-1 + 0 * np.sqrt(float(x[0]))])
    with pytest.raises(ck.UserFunctionError, match=r"f returned NaN or inf at t = 0\.4"):
        ck.extended_kalman_filter(_scalar_system(f), T11, None, Y0, x0=[0.45], **EKF_ARGS)


def test_ekf_catches_inf_from_h_and_errors_of_the_jacobians():
    # x̂' = -x̂ + L (1 - x̂) from 1 falls below 0.5 (h -> inf) after t = ln 2 = 0.69, before t = 1
    sys_ = _scalar_system(lambda x, u: -x, h=lambda x, u: x / 0.0 if x[0] < 0.5 else x)
    with np.errstate(divide="ignore"), \
            pytest.raises(ck.UserFunctionError, match=r"h returned NaN or inf at t = 0\.[7-9]"):
        ck.extended_kalman_filter(sys_, T11, None, np.ones((11, 1)), x0=[1.0], **EKF_ARGS)
    linear = _scalar_system(lambda x, u: -x, h=lambda x, u: x)
    with pytest.raises(ck.UserFunctionError, match=r"dfdx raised KeyError at t = 0"):
        ck.extended_kalman_filter(linear, T11, None, Y0, x0=[1.0], dfdx=lambda x, u: {}["a"], **EKF_ARGS)
    with pytest.raises(ck.UserFunctionError, match=r"dhdx returned shape \(2,\) at t = 0; expected \(1, 1\)"):
        ck.extended_kalman_filter(linear, T11, None, Y0, x0=[1.0], dhdx=lambda x, u: [1.0, 2.0], **EKF_ARGS)
    # x̂' = -(1 + L) x̂ with 0 < L <= 1 from 1 falls below 0.75 between t = ln(4/3) / 2 and ln(4/3)
    with pytest.raises(ck.UserFunctionError, match=r"dhdx returned NaN or inf at t = 0\.[12]"):
        ck.extended_kalman_filter(linear, T11, None, Y0, x0=[1.0], **EKF_ARGS,
                                  dhdx=lambda x, u: [[np.nan if x[0] < 0.75 else 1.0]])


def test_kalman_bucy_rejects_nan_data_by_name():
    # NaN in the record would propagate into x̂ silently; it is refused before integrating
    t = np.linspace(0, 1, 11)
    y = np.zeros((11, 1))
    y[4] = np.nan
    with pytest.raises(ValueError, match=r"y contains NaN or infinite entries"):
        ck.kalman_bucy(ck.StateSpace(A, B, C), t, None, y, Q, R, np.eye(2), [0, 0])
    with pytest.raises(ValueError, match=r"u contains NaN or infinite entries"):
        ck.kalman_bucy(ck.StateSpace(A, B, C), t, np.full((11, 1), np.inf), np.zeros((11, 1)), Q, R,
                       np.eye(2), [0, 0])


def test_absurd_substeps_are_refused_before_any_work():
    # issue 25: substeps=10**9 made kalman_bucy and the EKF run for hours
    import time
    t = np.linspace(0.0, 1.0, 11)
    sys = ck.StateSpace([[0.0, 1.0], [-2.0, -3.0]], [[0.0], [1.0]], [[1.0, 0.0]])
    args = (t, None, np.zeros((11, 1)), np.eye(2), [[1.0]], np.eye(2), [0.0, 0.0])
    start = time.perf_counter()
    for substeps in (10**9, 1001, 1e300):
        with pytest.raises(ValueError, match=r"substeps must be at most 1000: received .*finer grid t"):
            ck.kalman_bucy(sys, *args, substeps=substeps)
        with pytest.raises(ValueError, match=r"substeps must be at most 1000"):
            ck.extended_kalman_filter(ck.models.pendulum(), *args, substeps=substeps)
    assert time.perf_counter() - start < 2.0
    # the limit itself is allowed, and agrees with the default to RK4's accuracy
    np.testing.assert_allclose(ck.kalman_bucy(sys, *args, substeps=1000).x,
                               ck.kalman_bucy(sys, *args).x, atol=1e-9)


def test_the_no_solution_message_names_each_mode_once_and_rounding_as_zero():
    # issue 25: with Q = 0 the double integrator's Jordan block gave the same paragraph twice,
    # and a rotated mode at 0 was printed as lambda = -1.11e-16
    with pytest.raises(ValueError) as info:
        ck.kalman_gain([[0.0, 1.0], [0.0, 0.0]], [[1.0, 0.0]], np.zeros((2, 2)), [[1.0]])
    text = str(info.value)
    assert text.count("the mode λ = 0 of A (eigenvector [1. 0.])") == 1, text
    assert "-0." not in text
    rng = np.random.default_rng(3)
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    A = rotation @ np.diag([0.0, -1.0, -2.0]) @ rotation.T     # eig: about -1.1e-16, -1, -2
    with pytest.raises(ValueError, match=r"the mode λ = 0 of A \(eigenvector"):
        ck.kalman_gain(A, np.array([[1.0, 0.0, 0.0]]) @ rotation.T, np.zeros((3, 3)), [[1.0]])
