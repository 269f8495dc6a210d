"""ctrb, is_controllable, charpoly, ccf_transform and similarity_transform."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck


def test_third_order_example_2_14_is_not_controllable():
    A = [[-1, 1, 0], [1, -1, 1], [0, 1, -1]]
    B = [[0], [1], [0]]
    np.testing.assert_allclose(ck.ctrb(A, B), [[0, 1, -2], [1, -1, 3], [0, 1, -2]])
    assert not ck.is_controllable(A, B)


def test_example_2_66_gives_the_transform_2_71_and_ccf_2_72():
    A, B = np.array([[0, 2], [1, -3]]), np.array([[1], [0]])
    T = ck.ccf_transform(A, B)
    np.testing.assert_allclose(T, [[0, 1], [1, -3]])
    ccf = ck.similarity_transform(ck.StateSpace(A, B), T)
    np.testing.assert_allclose(ccf.A, [[0, 1], [2, -3]], atol=1e-12)
    np.testing.assert_allclose(ccf.B, [[0], [1]], atol=1e-12)


def test_charpoly_is_ascending():
    # (s + 1)(s + 2)(s + 3) = s^3 + 6 s^2 + 11 s + 6
    np.testing.assert_allclose(ck.charpoly(np.diag([-1.0, -2, -3])), [6, 11, 6])


@given(st.integers(2, 6), st.integers(0, 10_000))
def test_ccf_transform_gives_the_ccf(n, seed):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e8:
        return
    T = ck.ccf_transform(A, B)
    ccf = ck.similarity_transform(ck.StateSpace(A, B), T)
    expected = np.eye(n, k=1)
    expected[-1] = -ck.charpoly(A)
    scale = 1 + np.abs(expected).max()
    np.testing.assert_allclose(ccf.A, expected, atol=1e-7 * scale)
    np.testing.assert_allclose(ccf.B[:, 0], np.eye(n)[-1], atol=1e-8)


def test_uncontrollable_and_multi_input_errors():
    with pytest.raises(ck.NotControllableError, match=r"has rank 2 < n = 3"):
        ck.ccf_transform([[-1, 1, 0], [1, -1, 1], [0, 1, -1]], [[0], [1], [0]])
    assert issubclass(ck.NotControllableError, ValueError)
    with pytest.raises(ValueError, match=r"B must have a single column"):
        ck.ccf_transform(np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match=r"T is singular"):
        ck.similarity_transform(ck.StateSpace(np.eye(2)), np.ones((2, 2)))


def _dc_motor_coefficients():
    # det(sI - A) of the DC motor = s (s^2 + (b/J + R/L) s + (b R + K^2) / (J L)), ascending
    J, b, K, R, L = 3.2284e-6, 3.5077e-6, 0.0274, 4.0, 2.75e-6
    return np.array([0.0, (b * R + K**2) / (J * L), b / J + R / L])


@pytest.mark.parametrize("units", [dict(), dict(time=1e-3), dict(milli=True)])
def test_ccf_transform_of_the_badly_scaled_dc_motor(units):
    from si_systems import dc_motor, in_units
    A, B, _ = in_units(dc_motor(), **units)
    T = ck.ccf_transform(A, B)
    a_s = _dc_motor_coefficients() * units.get("time", 1.0) ** np.array([3, 2, 1])
    Ac = T @ A @ np.linalg.inv(T)
    expected = np.eye(3, k=1)
    expected[-1] = -a_s
    # each row against its own size: the rows of the CCF span 12 orders of magnitude in SI;
    # 1e-9 is rounding (1e-16) amplified by cond(T) (about 1e6 here)
    scale = np.abs(expected).max(axis=1, keepdims=True)
    np.testing.assert_allclose(Ac / scale, expected / scale, atol=1e-9)
    np.testing.assert_allclose(T @ B, [[0], [0], [1]], atol=1e-12)   # T B = e_n, entries ~1


@settings(max_examples=40)
@given(st.integers(2, 8), st.integers(0, 10_000), st.floats(-4, 4),
       st.lists(st.floats(-4, 4), min_size=8, max_size=8))
def test_ccf_transform_follows_a_change_of_units(n, seed, log_a, log_d):
    # time t = a t', states x' = D x: T' = diag(a^(i-1-n)) T D^-1, from T_1' A'^k b' = delta_k,n-1
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e8:
        return
    a, d = 10.0**log_a, 10.0 ** np.array(log_d[:n])
    T = ck.ccf_transform(A, B)
    T2 = ck.ccf_transform(a * d[:, None] * A / d[None, :], a * d[:, None] * B)
    back = T2 * d[None, :] * a ** (n + 1 - np.arange(1, n + 1))[:, None]
    # row by row against the row's size: cond(Wc) <= 1e8 bounds the error of each row by ~1e-8
    rows = np.linalg.norm(T, axis=1, keepdims=True)
    np.testing.assert_allclose(back / rows, T / rows, atol=1e-7)


def test_ccf_transform_warns_when_its_result_misses_the_ccf(monkeypatch):
    # a deliberate mistake: perturb T_1 by 1e-6 after it has been computed
    import coursekit._pairs as cm
    rows = cm._ccf_rows
    monkeypatch.setattr(cm, "_ccf_rows", lambda v: rows(v) * (1 + 1e-6 * np.eye(len(v.Q))[0][:, None]))
    with pytest.warns(ck.AccuracyWarning,
                      match=r"misses its defining equations .* by [0-9.]+e-0[67] \(relative\)"):
        ck.ccf_transform([[0, 1], [-2, -3]], [[0], [1]])
    with pytest.warns(ck.AccuracyWarning, match=r"observability canonical form \(4.31\) misses"):
        ck.ocf_transform([[0, 1], [-2, -3]], [[1, 0]])


def test_a_nearly_singular_t_warns_and_a_well_conditioned_one_does_not():
    # issue 25: T of condition 1e15 passed without a word
    import warnings
    sys = ck.StateSpace([[0.0, 1.0], [-2.0, -3.0]], [[0.0], [1.0]], [[1.0, 0.0]])
    with pytest.warns(ck.AccuracyWarning, match=r"T is nearly singular \(condition number 3\.2e\+15\)"):
        ck.similarity_transform(sys, [[1.0, 1.0], [1.0, 1.0 + 1e-15]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ck.similarity_transform(sys, [[1.0, 1.0], [0.0, 1e-4]])   # condition 2e4
