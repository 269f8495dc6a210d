"""kalman_gain in discrete time (dt=...) and discrete_kalman_filter."""

import control
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.linalg import expm

import coursekit as ck

Ts = 0.1
A_c = np.array([[0, 1], [-2, -0.5]])                # mass-spring-damper, position measured
A_d = expm(A_c * Ts)
B_d = np.array([[0.005], [0.1]])
C = np.array([[1, 0.0]])
Q_d = np.diag([1e-4, 5e-2])
R_d = np.array([[0.2]])


def _random_pair(n, p, seed, radius):
    """A (spectral radius `radius`) and C with a well-conditioned observability matrix, or None."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A *= radius / max(np.abs(np.linalg.eigvals(A)).max(), 1e-3)
    C_ = rng.normal(size=(p, n))
    if np.linalg.cond(ck.obsv(A, C_)) > 1e5:
        return None
    G = rng.normal(size=(n, n))
    return A, C_, G @ G.T + 0.1 * np.eye(n), np.diag(rng.uniform(0.1, 2, size=p))


def _dare_residual(A, C, Q, R, P):
    S = C @ P @ C.T + R
    return A @ P @ A.T - A @ P @ C.T @ np.linalg.solve(S, C @ P @ A.T) + Q - P


@given(st.integers(1, 5), st.integers(1, 2), st.floats(0.3, 1.5), st.integers(0, 10_000))
@settings(max_examples=40)
def test_discrete_gain_is_dlqe(n, p, radius, seed):
    drawn = _random_pair(n, p, seed, radius)
    if drawn is None:
        return
    A, C_, Q, R = drawn
    L, P = ck.kalman_gain(A, C_, Q, R, dt=0.01)
    # python-control returns the predictor gain A P C^T (C P C^T + R)^-1, P the prediction covariance
    L_ref, P_ref, E = control.dlqe(A, np.eye(n), C_, Q, R)
    # both solve the same DARE by Schur methods: agreement to ~1e-8 of the largest entry
    np.testing.assert_allclose(P, P_ref, rtol=1e-7, atol=1e-9 * np.abs(P_ref).max())
    np.testing.assert_allclose(L, L_ref, rtol=1e-7, atol=1e-9 * np.abs(L_ref).max())
    assert np.abs(np.linalg.eigvals(A - L @ C_)).max() < 1
    # recomputation: the DARE holds within rounding of its terms (entries of size ~|P|)
    assert np.abs(_dare_residual(A, C_, Q, R, P)).max() < 1e-9 * np.abs(P).max()
    # the filter gain M = P C^T S^-1 and L = A M
    M = P @ C_.T @ np.linalg.inv(C_ @ P @ C_.T + R)
    np.testing.assert_allclose(L, A @ M, rtol=1e-9, atol=1e-12 * np.abs(L).max())


@given(st.integers(1, 4), st.integers(0, 10_000), st.lists(st.floats(-4, 4), min_size=4, max_size=4),
       st.floats(-4, 4), st.booleans())
@settings(max_examples=40)
def test_gain_follows_changes_of_units(n, seed, log_d, log_a, discrete):
    # states in other units, x_s = D x: A_s = D A D^-1, C_s = C D^-1, Q_s = D Q D; then P_s = D P D
    # and L_s = D L. Continuous time in another time unit (A -> a A, intensities Q -> a Q, R -> R / a)
    # leaves P and multiplies L by a. No warning may appear (pytest turns them into errors).
    drawn = _random_pair(n, 1, seed, 0.9)
    if drawn is None:
        return
    A, C_, Q, R = drawn
    if not discrete:
        A = A - 1.2 * np.eye(n)                       # a stable continuous A keeps the pair detectable
    D = 10.0 ** np.array(log_d[:n])
    a = 1.0 if discrete else 10.0 ** log_a
    dt = 0.1 if discrete else None
    L, P = ck.kalman_gain(A, C_, Q, R, dt=dt)
    A_s, C_s, Q_s = a * (D[:, None] * A / D), C_ / D, a * np.outer(D, D) * Q
    L_s, P_s = ck.kalman_gain(A_s, C_s, Q_s, R / a, dt=dt)
    # each entry compared with its own scale: the relative accuracy of the ARE solve (~1e-9 for
    # these well-conditioned pairs) survives the scaling; 1e-6 leaves room for the conditioning
    np.testing.assert_allclose(P_s / np.outer(D, D), P, rtol=1e-6, atol=1e-9 * np.abs(P).max())
    np.testing.assert_allclose(L_s / (a * D[:, None]), L, rtol=1e-6, atol=1e-9 * np.abs(L).max())


def test_discrete_gain_of_a_sampled_system_tends_to_ts_times_the_continuous_gain():
    # R_d = R / Ts and Q_d = Van Loan integral ~ Q Ts: L_d / Ts -> L_c with an error O(Ts)
    Q, R = np.diag([0.0, 0.5]), np.array([[0.02]])
    L_c, P_c = ck.kalman_gain(A_c, C, Q, R)
    errors = []
    for h in (0.1, 0.01, 0.001):
        n = 2
        E = expm(np.block([[-A_c, Q], [np.zeros((n, n)), A_c.T]]) * h)
        Qd = E[n:, n:].T @ E[:n, n:]
        L_d, P_d = ck.kalman_gain(expm(A_c * h), C, (Qd + Qd.T) / 2, R / h, dt=h)
        errors.append(np.abs(L_d / h - L_c).max() / np.abs(L_c).max())
        np.testing.assert_allclose(P_d, P_c, rtol=5 * h, atol=5 * h * np.abs(P_c).max())
    # first order: the error shrinks about tenfold per tenfold smaller Ts (between 5 and 20 times)
    assert errors[2] < 0.01
    for big, small in zip(errors, errors[1:]):
        assert 5 < big / small < 20


@pytest.mark.parametrize("theta, C_, mode", [(0.3, C, "0.9553 ± 0.2955j"), (0.0, np.eye(2), "1")])
def test_discrete_gain_refuses_an_undriven_mode_on_the_unit_circle(theta, C_, mode):
    # rotation by theta (an undamped oscillator sampled), or the identity (two constants, both
    # measured): with Q = 0 the DARE's solution P = 0 gives L = 0, and A - L C keeps the modes on
    # the unit circle
    A = np.array([[np.cos(theta), np.sin(theta)], [-np.sin(theta), np.cos(theta)]])
    R = np.eye(C_.shape[0])
    with pytest.raises(ValueError, match=rf"no stabilizing solution.*the mode λ = {mode} of A.*lies "
                                         r"on the unit circle and the process noise Q does not drive it"):
        ck.kalman_gain(A, C_, np.zeros((2, 2)), R, dt=Ts)
    L, _ = ck.kalman_gain(A, C_, 1e-6 * np.eye(2), R, dt=Ts)     # a little Q is enough
    assert np.abs(np.linalg.eigvals(A - L @ C_)).max() < 1


def test_discrete_gain_names_only_the_mode_at_fault():
    # constants x1 (measured, driven by Q) and x2 (not measured): only x2 is to blame
    with pytest.raises(ValueError, match=r"no stabilizing solution \(A - L C would not be stable\): the "
                                         r"mode λ = 1 of A \(eigenvector \[0\. 1\.\]\) is on the unit circle "
                                         r"and not observable through C \(C v = 0\)[^λ]*$"):
        ck.kalman_gain(np.eye(2), C, 1e-6 * np.eye(2), [[1.0]], dt=Ts)


def test_discrete_gain_refuses_an_undetectable_pair():
    with pytest.raises(ValueError, match=r"the mode λ = 2 of A \(eigenvector \[1\. 0\.\]\) is unstable "
                                         r"and not observable through C"):
        ck.kalman_gain(np.diag([2.0, 0.5]), [[0, 1.0]], np.eye(2), [[1.0]], dt=Ts)


@pytest.mark.parametrize("dt, message", [
    (0.0, r"dt must be positive: received 0\.0"),
    (-0.1, r"dt must be positive"),
    (np.nan, r"dt contains NaN"),
    ([0.1, 0.2], r"dt must be a single number"),
])
def test_discrete_gain_bad_dt(dt, message):
    with pytest.raises(ValueError, match=message):
        ck.kalman_gain(A_d, C, Q_d, R_d, dt=dt)


# --- the filter --------------------------------------------------------------------------------

def _textbook_filter(A, B, C, D, Q, R, P0, x0, y, u):
    """Predict/update written out independently: the update (I - K C) P, not the Joseph form."""
    x, P, out = np.array(x0, float), np.array(P0, float), []
    for k in range(len(y)):
        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        x = x + K @ (y[k] - C @ x - D @ u[k])
        P = (np.eye(len(x)) - K @ C) @ P
        out.append((x.copy(), P.copy(), K))
        x, P = A @ x + B @ u[k], A @ P @ A.T + Q
    return out


@given(st.integers(1, 3), st.integers(1, 2), st.integers(0, 2), st.integers(0, 10_000))
@settings(max_examples=25)
def test_filter_equals_the_textbook_loop(n, p, m, seed):
    rng = np.random.default_rng(seed)
    sys = ck.StateSpace(rng.normal(size=(n, n)) * 0.6, rng.normal(size=(n, m)),
                        rng.normal(size=(p, n)), rng.normal(size=(p, m)), dt=0.05)
    N = 40
    y, u = rng.normal(size=(N, p)), rng.normal(size=(N, m))
    G = rng.normal(size=(n, n))
    Q, R, P0, x0 = G @ G.T, np.diag(rng.uniform(0.1, 1, size=p)), 2 * np.eye(n), rng.normal(size=n)
    res = ck.discrete_kalman_filter(sys, y, u if m else None, Q=Q, R=R, P0=P0, x0=x0)
    ref = _textbook_filter(sys.A, sys.B, sys.C, sys.D, Q, R, P0, x0, y, u)
    # the two P updates are equal in exact arithmetic; rounding differs by a few eps times |P|
    for k, (x_k, P_k, K_k) in enumerate(ref):
        np.testing.assert_allclose(res.x[k], x_k, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(res.P[k], P_k, rtol=1e-9, atol=1e-10)
        np.testing.assert_allclose(res.M[k], K_k, rtol=1e-9, atol=1e-10)
    np.testing.assert_allclose(res.L, sys.A @ res.M, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.t, np.arange(N) * 0.05)


def test_filter_gain_converges_to_the_discrete_steady_state_gain():
    sys = ck.StateSpace(A_d, B_d, C, dt=Ts)
    res = ck.discrete_kalman_filter(sys, np.zeros((300, 1)), Q=Q_d, R=R_d, P0=np.eye(2), x0=[0, 0])
    L, P = ck.kalman_gain(A_d, C, Q_d, R_d, dt=Ts)
    M = P @ C.T @ np.linalg.inv(C @ P @ C.T + R_d)
    # the Riccati recursion converges geometrically (rate |eig(A - L C)|^2 < 0.9): after 300 steps
    # the gap is at rounding level
    np.testing.assert_allclose(res.L[-1], L, rtol=1e-9)
    np.testing.assert_allclose(res.M[-1], M, rtol=1e-9)
    np.testing.assert_allclose(res.P[-1], P - M @ C @ P, rtol=1e-9)      # P(k|k) = P - M C P
    assert np.abs(res.L[1] - L).max() > 1e-2                               # it really moved


def test_filter_is_the_bayesian_posterior_of_a_constant():
    # x(k+1) = x(k) (Q = 0), y(k) = x(k) + v(k): the posterior given y(0..k) has precision
    # 1/P0 + (k+1)/R and mean (x0/P0 + sum y / R) times the variance (conjugate Gaussian prior)
    rng = np.random.default_rng(1)
    y = 3.0 + 0.5 * rng.standard_normal(25)
    P0, x0, R = 4.0, 1.0, 0.25
    res = ck.discrete_kalman_filter(ck.StateSpace([[1.0]], C=[[1.0]], dt=1.0), y, Q=[[0.0]], R=[[R]],
                                    P0=[[P0]], x0=[x0])
    k = np.arange(1, 26)
    variance = 1 / (1 / P0 + k / R)
    mean = variance * (x0 / P0 + np.cumsum(y) / R)
    np.testing.assert_allclose(res.P[:, 0, 0], variance, rtol=1e-12)
    np.testing.assert_allclose(res.x[:, 0], mean, rtol=1e-12)


def test_filter_is_the_gaussian_conditional_mean():
    # a 2-state system with noise: stack x(0..N-1) and y(0..N-1) as one Gaussian vector and condition
    # on y directly (no recursion): E[x(k) | y(0..k)] and its covariance must equal the filter's
    rng = np.random.default_rng(2)
    n, N = 2, 6
    u = rng.normal(size=(N, 1))
    y = rng.normal(size=(N, 1))
    P0, x0 = np.diag([1.0, 2.0]), np.array([0.5, -1.0])
    # x(k) = A^k x(0) + sum_j A^(k-1-j) (B u(j) + w(j)): linear in z = [x(0); w(0..N-2)]
    Z = np.zeros((N, n, n * N))                     # x(k) = Z[k] z + c[k]
    c = np.zeros((N, n))
    Z[0][:, :n], c[0] = np.eye(n), x0
    for k in range(1, N):
        Z[k] = A_d @ Z[k - 1]
        Z[k][:, n * k:n * (k + 1)] += np.eye(n)
        c[k] = A_d @ c[k - 1] + B_d @ u[k - 1]
    cov_z = np.zeros((n * N, n * N))
    cov_z[:n, :n] = P0
    for k in range(1, N):
        cov_z[n * k:n * (k + 1), n * k:n * (k + 1)] = Q_d
    res = ck.discrete_kalman_filter(ck.StateSpace(A_d, B_d, C, dt=Ts), y, u, Q=Q_d, R=R_d, P0=P0, x0=x0)
    for k in range(N):
        H = np.vstack([C @ Z[j] for j in range(k + 1)])          # y(0..k) = H z + C c + v
        S = H @ cov_z @ H.T + np.kron(np.eye(k + 1), R_d)
        cross = Z[k] @ cov_z @ H.T
        innovation = y[:k + 1, 0] - np.array([C @ c[j] for j in range(k + 1)])[:, 0]
        mean = c[k] + cross @ np.linalg.solve(S, innovation)
        cov = Z[k] @ cov_z @ Z[k].T - cross @ np.linalg.solve(S, cross.T)
        # two exact formulas evaluated differently: agreement to ~1e-12 of entries of size ~1
        np.testing.assert_allclose(res.x[k], mean, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.P[k], cov, rtol=1e-10, atol=1e-12)


def _simulate_sampled(A, C, Q, R, N, x0, seed):
    rng = np.random.default_rng(seed)
    n, p = A.shape[0], C.shape[0]
    w = rng.multivariate_normal(np.zeros(n), Q, size=N)
    v = rng.multivariate_normal(np.zeros(p), R, size=N)
    x = np.empty((N, n))
    x[0] = x0
    for k in range(N - 1):
        x[k + 1] = A @ x[k] + w[k]
    return x, x @ C.T + v


def _mean_nees(res, x):
    e = x - res.x
    return float(np.mean(np.einsum("ki,kij,kj->k", e, np.linalg.inv(res.P), e)))


def test_normalized_estimation_error_is_consistent():
    # with the true Q and R, e(k)^T P(k|k)^-1 e(k) is chi-square with n = 2 degrees of freedom; its
    # mean over N = 4000 samples has standard deviation sqrt(2 n / N) = 0.032 for independent
    # samples, a few times more for these correlated ones: the band 2 +- 0.3 (about +-3 sigma) holds
    # for any seed, and fails clearly when the filter is mistuned (last two lines)
    N, x0 = 4000, np.array([0.3, -0.2])
    x, y = _simulate_sampled(A_d, C, Q_d, R_d, N, x0, seed=7)
    sys = ck.StateSpace(A_d, np.zeros((2, 1)), C, dt=Ts)
    kw = dict(P0=np.diag([0.3**2, 0.2**2]) * 4, x0=[0.0, 0.0])
    nees = _mean_nees(ck.discrete_kalman_filter(sys, y, Q=Q_d, R=R_d, **kw), x)
    assert 1.7 < nees < 2.3
    assert _mean_nees(ck.discrete_kalman_filter(sys, y, Q=Q_d / 20, R=R_d, **kw), x) > 3
    assert _mean_nees(ck.discrete_kalman_filter(sys, y, Q=Q_d * 20, R=R_d * 20, **kw), x) < 0.5


def test_filter_bad_inputs():
    sys = ck.StateSpace(A_d, B_d, C, dt=Ts)
    ok = dict(Q=Q_d, R=R_d, P0=np.eye(2), x0=[0, 0])
    y = np.zeros((10, 1))
    cases = [
        ((ck.StateSpace(A_c, B_d, C), y), ok, r"sys must be a discrete-time StateSpace"),
        ((sys, np.zeros((10, 2))), ok, r"y has the wrong number of columns: received shape \(10, 2\), "
                                       r"expected 1 columns \(one column per output, since C has 1 row\)"),
        ((sys, np.full((10, 1), np.nan)), ok, r"y contains NaN or infinite entries"),
        ((sys, y, np.zeros((9, 1))), ok, r"u has the wrong number of rows: received shape \(9, 1\)"),
        ((ck.StateSpace(A_d, C=C, dt=Ts), y, np.zeros((10, 1))), ok, r"u was given, but the system has no input"),
        ((sys, y), ok | dict(Q=np.eye(3)), r"Q has the wrong size: received shape \(3, 3\), expected \(2, 2\) "
                                          r"\(one row and column per state, n = 2"),
        ((sys, y), ok | dict(R=np.eye(2)), r"R has the wrong size.*one row and column per output, p = 1"),
        ((sys, y), ok | dict(R=[[0.0]]), r"R must be positive definite"),
        ((sys, y), ok | dict(P0=-np.eye(2)), r"P0 must be positive semidefinite"),
        ((sys, y), ok | dict(x0=[0, 0, 0]), r"x0 has the wrong length"),
    ]
    for args, kwargs, message in cases:
        with pytest.raises(ValueError, match=message):
            ck.discrete_kalman_filter(*args, **kwargs)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning",
                            "ignore:invalid value encountered:RuntimeWarning")
def test_filter_reports_divergence_with_the_sample():
    # an unstable mode the sensor does not see: P grows by 1e200 per step and overflows at k = 2
    sys = ck.StateSpace([[1e100]], C=[[0.0]], dt=0.5)
    with pytest.raises(RuntimeError, match=r"diverged at sample k = 2 \(t = 1\)"):
        ck.discrete_kalman_filter(sys, np.zeros(6), Q=[[1.0]], R=[[1.0]], P0=[[1.0]], x0=[1.0])


def test_filter_result_repr_and_sigma():
    res = ck.discrete_kalman_filter(ck.StateSpace(A_d, B_d, C, dt=Ts), np.zeros(5), Q=Q_d, R=R_d,
                                    P0=np.eye(2), x0=[0, 0])
    assert "P (5, 2, 2), L (5, 2, 1), M (5, 2, 1)" in repr(res) and res.sigma.shape == (5, 2)
