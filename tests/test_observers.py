"""Observers as systems: plant + copy + correction, output feedback, tracking (4.19-4.27, 4.73, 4.77)."""

import numpy as np
import pytest
from hypothesis import assume, given, strategies as st

import coursekit as ck
from test_placement_checks import checked

A = np.array([[1, 1], [0, -1.0]])       # the notes' example (4.61): unstable
B = np.array([[1], [0.0]])
C = np.array([[1, 0.0]])


def _sys():
    return ck.StateSpace(A, B, C)


def test_copy_of_unstable_plant_drifts_apart():
    t = np.linspace(0, 5, 501)
    res = ck.simulate(ck.plant_with_observer(_sys(), np.zeros((2, 1))), t, x0=[1, 0, 0, 0])
    err = res.x[:, 2:] - res.x[:, :2]
    # (4.24): x̃' = A x̃, so x̃(t) = e^{A t} x̃(0)
    from scipy.linalg import expm
    np.testing.assert_allclose(err[-1], expm(A * 5) @ [-1, 0], rtol=1e-8)
    assert abs(err[-1, 0]) > 100


def test_corrected_observer_error_follows_a_minus_lc():
    from scipy.linalg import expm
    L = ck.place_observer(A, C, [-1, -1])
    t = np.linspace(0, 5, 501)
    u = np.sin(t)[:, None]
    res = ck.simulate(ck.plant_with_observer(_sys(), L), t, u=u, x0=[1, 0.5, 0, 0])
    err = res.x[:, 2:] - res.x[:, :2]
    # (4.27): x̃' = (A - L C) x̃, independent of u
    for k in (100, 300, 500):
        np.testing.assert_allclose(err[k], expm((A - L @ C) * t[k]) @ [-1, -0.5], atol=1e-9)
    np.testing.assert_allclose(res.y[:, 1:], res.x[:, 2:])   # outputs [y; x̂]
    np.testing.assert_allclose(res.y[:, 0], res.x[:, 0])


def test_observer_system_on_recorded_data_matches_the_augmented_system():
    L = ck.place_observer(A, C, [-2, -3])
    t = np.linspace(0, 4, 401)
    u = np.cos(2 * t)[:, None]
    both = ck.simulate(ck.plant_with_observer(_sys(), L), t, u=u, x0=[0.3, -0.2, 0, 0])
    plant = ck.simulate(_sys(), t, u=u, x0=[0.3, -0.2])
    obs = ck.simulate(ck.observer_system(_sys(), L), t, u=np.hstack([u, plant.y]), x0=[0, 0])
    # the recorded y is taken as linear between samples: an O(dt^2) interpolation error
    np.testing.assert_allclose(obs.x, both.x[:, 2:], atol=5e-4)
    assert np.abs(obs.x).max() > 0.1


def test_observer_system_with_feedthrough():
    sys = ck.StateSpace(A, B, C, [[0.5]])
    L = ck.place_observer(A, C, [-2, -3])
    obs = ck.observer_system(sys, L)
    np.testing.assert_allclose(obs.A, A - L @ C)
    np.testing.assert_allclose(obs.B, np.hstack([B - L * 0.5, L]))


@given(st.integers(2, 5), st.integers(0, 10_000))
def test_separation_principle(n, seed):
    rng = np.random.default_rng(seed)
    A_, B_, C_ = rng.normal(size=(n, n)), rng.normal(size=(n, 1)), rng.normal(size=(1, n))
    # The separation principle holds for any K and L. How accurately place meets ill-conditioned
    # requests (nearly uncontrollable/unobservable pairs, clustered poles: it then rightly warns)
    # is tested in test_placement_checks.py, so here the draws are kept well conditioned
    # (cond of ctrb and obsv <= 1e3) and the requested poles 1 apart.
    assume(np.linalg.cond(ck.ctrb(A_, B_)) <= 1e3 and np.linalg.cond(ck.obsv(A_, C_)) <= 1e3)
    poles_K, poles_L = -np.arange(1.0, n + 1), -np.arange(1.0, n + 1) - 0.5
    # `checked` still accepts an AccuracyWarning where rounding explains it and, without one,
    # asserts the documented pole accuracy (1e-6 of the pole scale)
    K, _ = checked(ck.place, A_, B_, poles_K)
    L, _ = checked(ck.place_observer, A_, C_, poles_L, observer=True)
    cl = ck.output_feedback(ck.StateSpace(A_, B_, C_), K, L)
    # in the coordinates [x; e] with e = x - x̂ (T = T^-1 = [[I, 0], [I, -I]]) the closed loop is
    # block triangular [[A + B K, -B K], [0, A - L C]]: its eigenvalues are those of the two blocks,
    # for any K and L, accurate or not. (Comparing eigenvalues of the 2n x 2n matrix directly is
    # ill-conditioned for close poles.) The tolerance: a few eps times the size of the entries
    # (two products of O(1) data with K, L), with margin.
    I, Z = np.eye(n), np.zeros((n, n))
    T = np.block([[I, Z], [I, -I]])
    expected = np.block([[A_ + B_ @ K, -B_ @ K], [Z, A_ - L @ C_]])
    np.testing.assert_allclose(T @ cl.A[:2 * n, :2 * n] @ T, expected, atol=1e-9 * np.abs(expected).max())
    # separation_eigenvalues reports exactly these two spectra (same LAPACK call on the same
    # matrices, so only the evaluation order of the products may differ: 1e-9 relative)
    halves = ck.separation_eigenvalues(ck.StateSpace(A_, B_, C_), K, L)
    for half, block in zip(halves, (A_ + B_ @ K, A_ - L @ C_)):
        assert len(half) == n
        np.testing.assert_allclose(np.poly(half), np.poly(block), rtol=1e-9,
                                   atol=1e-9 * np.abs(np.poly(block)).max())


def test_output_feedback_regulates_and_reports_u():
    K = ck.place(A, B, [-2, -3]) if ck.is_controllable(A, B) else None
    assert K is None                       # (4.69): the notes' example is not controllable
    sys = ck.models.vehicle(1, 1, sensor="gps")
    K = ck.place(sys.A, sys.B, [-1, -2])
    L = ck.place_observer(sys.A, sys.C, [-4, -5])
    t = np.linspace(0, 10, 1001)
    res = ck.simulate(ck.output_feedback(sys, K, L), t, x0=[1, 0, 0, 0])
    assert np.abs(res.x[-1]).max() < 1e-3
    np.testing.assert_allclose(res.y[:, -1], res.x[:, 2:] @ K.ravel())   # u = K x̂ (4.73)


def test_tracking_with_an_observer():
    sys = ck.models.vehicle(1, 1, sensor="gps")
    K = ck.place(sys.A, sys.B, [-2, -3])
    L = ck.place_observer(sys.A, sys.C, [-6, -7])
    t = np.linspace(0, 10, 2001)
    # x_d = [sin t, cos t], u_d from (4.1): u = m (x2' + d/m x2) = -sin t + cos t
    x_d = np.column_stack([np.sin(t), np.cos(t)])
    u_d = (-np.sin(t) + np.cos(t))[:, None]
    v = ck.observer_tracking_input(K, x_d, u_d)
    np.testing.assert_allclose(v, u_d - x_d @ K.T)
    res = ck.simulate(ck.output_feedback(sys, K, L), t, u=v, x0=[0.5, 0, 0, 0])
    assert np.abs(res.x[-200:, :2] - x_d[-200:]).max() < 1e-3
    assert np.abs(res.x[0, :2] - x_d[0]).max() > 0.4


def test_bad_inputs():
    with pytest.raises(ValueError, match=r"L has the wrong number of rows: received shape \(3, 1\), expected 2"):
        ck.plant_with_observer(_sys(), np.zeros((3, 1)))
    with pytest.raises(ValueError, match=r"K has the wrong number of columns"):
        ck.output_feedback(_sys(), [[1, 2, 3]], [[1], [1]])
    with pytest.raises(ValueError, match=r"sys must be a continuous-time StateSpace"):
        ck.observer_system(ck.models.pendulum(), [[1], [1]])
    with pytest.raises(ValueError, match=r"x_d has the wrong number of columns"):
        ck.observer_tracking_input([[1, 2]], np.zeros((5, 3)), np.zeros((5, 1)))
    with pytest.raises(ValueError, match=r"u_d has the wrong number of rows"):
        ck.observer_tracking_input([[1, 2]], np.zeros((5, 2)), np.zeros((4, 1)))
