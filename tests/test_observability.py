"""obsv, is_observable, ocf_transform and place_observer (sections 4.2-4.5, 4.7.1)."""

import control
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck
from conftest import sorted_eig
from test_placement_checks import checked


def _random_observable(n, p, seed):
    """A random (A, C), or None when Wo is too ill-conditioned to test at tight tolerances."""
    rng = np.random.default_rng(seed)
    A, C = rng.normal(size=(n, n)), rng.normal(size=(p, n))
    if np.linalg.cond(ck.obsv(A, C)) > 1e6:
        return None
    return A, C


def test_worked_example_4_61_to_4_71():
    A, C = np.array([[1, 1], [0, -1.0]]), np.array([[1, 0.0]])
    np.testing.assert_allclose(ck.obsv(A, C), [[1, 0], [1, 1]])                     # (4.62)
    d = ck.place_observer_details(A, C, [-1, -1])
    np.testing.assert_allclose(d.V, [[0, 1], [1, -1]], atol=1e-14)                 # (4.65)
    np.testing.assert_allclose(d.T, [[1, 1], [1, 0]], atol=1e-14)
    np.testing.assert_allclose(d.A_ocf, [[0, 1], [1, 0]], atol=1e-14)              # (4.66)
    np.testing.assert_allclose(d.T @ [[1], [0]], [[1], [1]])                        # (4.67)
    np.testing.assert_allclose(d.C_ocf, [[0, 1]], atol=1e-14)                      # (4.68)
    np.testing.assert_allclose(d.L_ocf, [[2], [2]], atol=1e-14)                    # (4.70)
    np.testing.assert_allclose(d.L, [[2], [0]], atol=1e-14)                        # (4.71)
    np.testing.assert_allclose(ck.place_observer(A, C, [-1, -1]), [[2], [0]], atol=1e-14)


def test_vehicle_gps_observable_speedometer_not():
    gps, speedo = ck.models.vehicle(1, 1, sensor="gps"), ck.models.vehicle(1, 1, sensor="speedometer")
    assert ck.is_observable(gps.A, gps.C)
    assert not ck.is_observable(speedo.A, speedo.C)
    np.testing.assert_allclose(ck.obsv(speedo.A, speedo.C), [[0, 1], [0, -1]])     # (4.17)
    assert ck.obsv_singular_values(speedo.A, speedo.C)[-1] < 1e-12                  # (4.18)


def test_obsv_is_the_transpose_of_the_dual_ctrb():
    rng = np.random.default_rng(0)
    A, C = rng.normal(size=(4, 4)), rng.normal(size=(2, 4))
    Wo = ck.obsv(A, C)
    assert Wo.shape == (8, 4)
    np.testing.assert_allclose(Wo, ck.ctrb(A.T, C.T).T)
    np.testing.assert_allclose(Wo[2:4], C @ A)
    np.testing.assert_allclose(Wo[6:8], C @ np.linalg.matrix_power(A, 3))


@given(st.integers(2, 6), st.integers(0, 10_000))
def test_ocf_transform_gives_the_ocf(n, seed):
    drawn = _random_observable(n, 1, seed)
    if drawn is None:
        return
    A, C = drawn
    T = ck.ocf_transform(A, C)
    V = np.linalg.inv(T)
    A_ocf, C_ocf = T @ A @ V, C @ V
    a = ck.charpoly(A)
    expected = np.eye(n, k=-1)
    expected[:, -1] = -a                                   # (4.31): last column -a
    scale = max(1.0, np.abs(a).max())
    np.testing.assert_allclose(A_ocf, expected, atol=1e-7 * scale)
    np.testing.assert_allclose(C_ocf, np.eye(1, n, n - 1), atol=1e-8)   # (4.32): C = e_n^T


@given(st.integers(2, 6), st.integers(0, 10_000))
def test_ocf_is_the_transpose_of_the_dual_ccf(n, seed):
    drawn = _random_observable(n, 1, seed)
    if drawn is None:
        return
    A, C = drawn
    # duality: T_ocf = (T_ccf of (A^T, C^T))^{-T}
    T_dual = ck.ccf_transform(A.T, C.T)
    np.testing.assert_allclose(ck.ocf_transform(A, C), np.linalg.inv(T_dual).T, rtol=1e-6,
                               atol=1e-8 * np.abs(np.linalg.inv(T_dual)).max())


@given(st.integers(2, 6), st.integers(0, 10_000))
def test_single_output_poles_and_python_control(n, seed):
    drawn = _random_observable(n, 1, seed)
    if drawn is None:
        return
    A, C = drawn
    poles = -np.linspace(1, 2.5, n)
    L, _ = checked(ck.place_observer, A, C, poles, observer=True)   # may warn: see the next comment
    assert L.shape == (n, 1)
    # six poles 0.3 apart of a non-normal A - L C: the eigenvalues themselves are ill-conditioned,
    # so check the characteristic polynomial, as test_placement does for A + B K
    p = ck.poly_from_roots(poles)
    np.testing.assert_allclose(ck.charpoly(A - L @ C), p, rtol=1e-6, atol=1e-6 * np.abs(p).max())
    # (4.84): L = place(A^T, C^T, P)^T in MATLAB's sign; acker is the single-output oracle
    L_ref = np.atleast_2d(control.acker(A.T, C.T, poles)).T
    np.testing.assert_allclose(L, L_ref, rtol=1e-6, atol=1e-8 * np.abs(L_ref).max())
    # duality with the course's state-feedback place (u = K x): L = -K^T
    np.testing.assert_allclose(L, -checked(ck.place, A.T, C.T, poles)[0].T, rtol=1e-6,
                               atol=1e-8 * np.abs(L_ref).max())


@given(st.integers(3, 6), st.integers(0, 10_000))
def test_several_outputs_by_duality(n, seed):
    drawn = _random_observable(n, 2, seed)
    if drawn is None:
        return
    A, C = drawn
    poles = -np.linspace(1, 3, n)
    L = ck.place_observer(A, C, poles)
    assert L.shape == (n, 2)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A - L @ C)), sorted_eig(poles), atol=1e-5)
    L_ref = control.place(A.T, C.T, poles).T       # python-control uses A - B K
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A - L_ref @ C)), sorted_eig(poles), atol=1e-5)


def test_repeated_and_complex_observer_poles():
    A, C = np.eye(3, k=1), np.array([[1.0, 0, 0]])
    L = ck.place_observer(A, C, [-2, -2, -2])
    np.testing.assert_allclose(L, [[6], [12], [8]], atol=1e-12)   # s^3 + 6 s^2 + 12 s + 8
    poles = [-1 + 2j, -1 - 2j, -3]
    L = ck.place_observer(A, C, poles)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A - L @ C)), sorted_eig(poles), atol=1e-9)


@pytest.mark.parametrize("poles, message", [
    ([-1, -2], r"poles has the wrong length: received 2 poles, expected 3"),
    ([-1 + 1j, -1 + 1j, -2], r"without its conjugate"),
    ([-1, np.nan, -2], r"poles contains NaN"),
])
def test_bad_poles(poles, message):
    with pytest.raises(ValueError, match=message):
        ck.place_observer(np.eye(3, k=1), [[1, 0, 0]], poles)


def test_bad_shapes():
    with pytest.raises(ValueError, match=r"C has the wrong number of columns: received shape \(1, 3\), expected 2"):
        ck.obsv([[0, 1], [0, 0]], [[1, 0, 0]])
    with pytest.raises(ValueError, match=r"A must be square"):
        ck.is_observable([[0, 1, 2], [0, 0, 1]], [[1, 0, 0]])
    with pytest.raises(ValueError, match=r"C must have a single row for the OCF"):
        ck.ocf_transform(np.eye(2, k=1), np.eye(2))
    with pytest.raises(ValueError, match=r"A contains NaN"):
        ck.place_observer([[np.nan, 1], [0, 0]], [[1, 0]], [-1, -2])


def test_unobservable_raises_not_observable_error():
    speedo = ck.models.vehicle(1, 1, sensor="speedometer")
    with pytest.raises(ck.NotObservableError, match=r"rank 1 < n = 2"):
        ck.ocf_transform(speedo.A, speedo.C)
    with pytest.raises(ck.NotObservableError, match=r"not observable"):
        ck.place_observer(speedo.A, speedo.C, [-1, -2])
    A = np.diag([-1.0, -2.0, -3.0])
    with pytest.raises(ck.NotObservableError):
        ck.place_observer(A, [[1, 0, 0], [0, 1, 0]], [-4, -5, -6])
    assert issubclass(ck.NotObservableError, ValueError)


def test_repeated_more_than_rank_c():
    A = np.array([[0, 1, 0], [0, 0, 1], [1, 2, 3.0]])
    C = np.array([[1, 0, 0], [0, 1, 0.0]])
    # more than rank(C) times: no refusal (duality); the gain makes one Jordan chain, whose triple
    # eigenvalue scatters by ~(eps ||A - L C||)^(1/3) ~ 1e-4 when computed, while two outputs allow
    # chains of length 2: an AccuracyWarning says so (issue 35)
    with pytest.warns(ck.AccuracyWarning, match=r"requested 3 times with 2 independent inputs \(outputs\)"):
        L = ck.place_observer(A, C, [-2, -2, -2])
    np.testing.assert_allclose(np.linalg.eigvals(A - L @ C), [-2, -2, -2], atol=1e-3)
    np.testing.assert_allclose(np.poly(A - L @ C), [1, 6, 12, 8], atol=1e-9 * np.abs(L).max() ** 3)


@pytest.mark.parametrize("units", [dict(), dict(time=1e-3), dict(milli=True)])
def test_ocf_transform_and_observer_of_the_badly_scaled_dc_motor(units):
    from si_systems import dc_motor, in_units
    A, _, C = in_units(dc_motor(), **units)
    assert ck.is_observable(A, C)
    T = ck.ocf_transform(A, C)
    # T has cond ~1e16 here, so T A T^-1 cannot be formed in double precision; check the
    # defining equations without inverting T: T A = A_ocf T and C = e_n^T T (4.31)-(4.32)
    # det(sI - A) = s (s^2 + (b/J + R/L) s + (b R + K^2) / (J L)), ascending, in these units
    J, b, K, R, L = 3.2284e-6, 3.5077e-6, 0.0274, 4.0, 2.75e-6
    time = units.get("time", 1.0)
    a = np.array([0.0, (b * R + K**2) / (J * L), b / J + R / L]) * time ** np.array([3, 2, 1])
    A_ocf = np.eye(3, k=-1)
    A_ocf[:, -1] = -a
    # entry by entry against the sizes of the terms: T = V^-1 with cond(V) ~ 1e16 in SI units
    # carries ~5e-12 relative error in its entries (measured); 1e-10 leaves a margin of 20
    residual = np.abs(T @ A - A_ocf @ T)
    np.testing.assert_array_less(residual, 1e-10 * (np.abs(T) @ np.abs(A) + np.abs(A_ocf) @ np.abs(T))
                                 + 1e-300)
    np.testing.assert_allclose(T[-1:], C, rtol=1e-14)                 # C V = e_n^T
    poles = np.array([-1e3, -2e3, -3e3]) * units.get("time", 1.0)
    L = ck.place_observer(A, C, poles)
    # moving the 1.45e6 rad/s pole to 3e3 needs gains up to 4e14: the closed-loop poles are
    # ill-conditioned (SciPy's place_poles misses them by 3%, acker by 6e-7; coursekit ~1e-5)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(A - L @ C).real), np.sort(poles), rtol=1e-4)


@settings(max_examples=30)
@given(st.integers(1, 30), st.integers(1, 3), st.integers(0, 2**32 - 1))
def test_observability_is_controllability_of_the_dual(n, p, seed):
    # (4.15): Wo(A, C) = Wc(A^T, C^T)^T, so both verdicts agree, also for unobservable pairs
    rng = np.random.default_rng(seed)
    A, C = rng.normal(size=(n, n)), rng.normal(size=(p, n))
    hidden = n > 1 and rng.random() < 0.5
    if hidden:
        r = int(rng.integers(1, n))
        A[:r, r:] = 0.0            # the last n - r states never reach the first r ...
        C[:, r:] = 0.0             # ... nor are they measured: exactly unobservable
    assert ck.is_observable(A, C) == ck.is_controllable(A.T, C.T) == (not hidden)
