"""place: single input by the CCF method, several inputs by SciPy, with checks."""

import control
import numpy as np
import pytest
from hypothesis import example, given, strategies as st

import coursekit as ck
from conftest import sorted_eig
from test_placement_checks import checked


def test_example_2_66_placed_at_minus_one_and_minus_two():
    A, B = np.array([[0, 2], [1, -3]]), np.array([[1], [0]])
    K = ck.place(A, B, [-1, -2])
    np.testing.assert_allclose(K, [[0, -4]], atol=1e-12)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A + B @ K)), [-2, -1], atol=1e-12)


def test_details_show_each_step():
    d = ck.place_details([[0, 2], [1, -3]], [[1], [0]], [-1, -2])
    np.testing.assert_allclose(d.a, [-2, 3])      # s^2 + 3 s - 2
    np.testing.assert_allclose(d.p, [2, 3])       # s^2 + 3 s + 2
    np.testing.assert_allclose(d.K, d.K_ccf @ d.T)


@given(st.integers(2, 8), st.integers(0, 10_000))
@example(7, 8955)       # eig(A + B K) 0.028 from the poles for a K within 6e-13 of the exact one
def test_single_input_matches_python_control_with_flipped_sign(n, seed):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    poles = -np.linspace(1, 2.5, n)
    K, _ = checked(ck.place, A, B, poles)     # may warn: see the next comment
    # poles 0.2 apart at n = 8 are sensitive: eig(A + B K) moves by ~1e-4 even for a K exact to
    # 1e-14 (checked against a 60-digit oracle), so check the characteristic polynomial instead
    p = ck.poly_from_roots(poles)
    np.testing.assert_allclose(ck.charpoly(A + B @ K), p, rtol=1e-6, atol=1e-6 * np.abs(p).max())
    _assert_poles_to_rounding(A, B, K, poles)
    K_ref = -np.atleast_2d(control.acker(A, B, poles))
    np.testing.assert_allclose(K, K_ref, rtol=1e-6, atol=1e-8 * np.abs(K_ref).max())


def test_repeated_and_complex_poles_single_input():
    A, B = np.zeros((3, 3)) + np.eye(3, k=1), np.array([[0], [0], [1.0]])
    K = ck.place(A, B, [-2, -2, -2])
    np.testing.assert_allclose(K, [[-8, -12, -6]], atol=1e-12)
    K = ck.place(A, B, [-1 + 2j, -1 - 2j, -3])
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A + B @ K)), sorted_eig([-1 + 2j, -1 - 2j, -3]), atol=1e-9)


def test_two_inputs_use_the_robust_method():
    A = np.array([[0, 1, 0], [0, 0, 1], [1, 2, 3.0]])
    B = np.array([[0, 1], [1, 0], [0, 1.0]])
    K = ck.place(A, B, [-1, -2, -3])
    assert K.shape == (2, 3)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A + B @ K)), [-3, -2, -1], atol=1e-9)
    K = ck.place(A, B, [-2, -2, -3])
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A + B @ K)), [-3, -2, -2], atol=1e-6)


@pytest.mark.parametrize("poles, message", [
    ([-1, -2], r"poles has the wrong length: received 2 poles, expected 3"),
    ([-1 + 1j, -1 + 1j, -2], r"without its conjugate"),
    ([-1, np.nan, -2], r"poles contains NaN"),
])
def test_bad_poles(poles, message):
    with pytest.raises(ValueError, match=message):
        ck.place(np.eye(3, k=1), [[0], [0], [1]], poles)


def test_repeated_more_than_rank_b_and_uncontrollable():
    A = np.array([[0, 1, 0], [0, 0, 1], [1, 2, 3.0]])
    B = np.array([[0, 1], [1, 0], [0, 1.0]])
    # more than rank(B) times: Heymann's lemma, no refusal; its gain makes one Jordan chain, whose
    # triple eigenvalue scatters by ~(eps ||A + B K||)^(1/3) ~ 1e-4 when computed, while two inputs
    # allow chains of length 2 (scatter ~1e-8): an AccuracyWarning says so (issue 35)
    with pytest.warns(ck.AccuracyWarning, match=r"requested 3 times with 2 independent inputs .* one Jordan chain"):
        K = ck.place(A, B, [-2, -2, -2])
    np.testing.assert_allclose(np.linalg.eigvals(A + B @ K), [-2, -2, -2], atol=1e-3)
    np.testing.assert_allclose(np.poly(A + B @ K), [1, 6, 12, 8], atol=1e-9 * np.abs(K).max() ** 3)
    with pytest.raises(ck.NotControllableError, match=r"not controllable"):
        ck.place([[-1, 0], [0, -2]], [[1], [0]], [-3, -4])


def _random_pair(n, m, seed, max_cond):
    """A random (A, B), or None when Wc is too ill-conditioned to be a fair test."""
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, m))
    return None if np.linalg.cond(ck.ctrb(A, B)) > max_cond else (A, B)


def _assert_poles_to_rounding(A, B, K, poles):
    """eig(A + B K) are `poles` to what rounding leaves of them (Bauer-Fike: the condition number of
    the eigenvectors times the rounding of A + B K; up to 2e10 in the draws of the flipped-sign test,
    where the exact K rounded to floats moves them by 2e-3, and 5e6 for n = 3, seed = 5236 of the
    oracle's, by 9e-5), at 1e-6 at least."""
    eigenvalues, vectors = np.linalg.eig(A + B @ K)
    rounding = np.linalg.cond(vectors) * 10 * np.finfo(float).eps * (np.linalg.norm(A, 2) + np.linalg.norm(B @ K, 2))
    np.testing.assert_allclose(sorted_eig(eigenvalues), sorted_eig(poles), atol=max(1e-6, rounding))


def _high_precision_gain(A, B, poles, digits=40):
    """Independent oracle: Ackermann's formula K = -e_n^T Wc^-1 p(A) in 40-digit arithmetic."""
    import mpmath as mp
    with mp.workdps(digits):
        n = A.shape[0]
        Am, col = mp.matrix(A.tolist()), mp.matrix(B.tolist())
        W = mp.matrix(n, n)
        for j in range(n):
            for i in range(n):
                W[i, j] = col[i]
            col = Am * col
        e_n = mp.matrix(n, 1)
        e_n[n - 1] = 1
        T1 = mp.lu_solve(W.T, e_n).T
        P, power = mp.zeros(n, n), mp.eye(n)
        for c in np.poly(poles).real[::-1]:       # p(A) = sum p_i A^i, exact for these poles
            P += mp.mpf(float(c)) * power
            power = power * Am
        K = -(T1 * P)
        return np.array([[float(K[0, j]) for j in range(n)]])


@given(st.integers(2, 10), st.integers(0, 10_000))
@example(3, 5236)     # found in CI: K within 5e-12 of the oracle's, its poles 3e-4 off (condition 5e6)
def test_single_input_up_to_n_10_agrees_with_a_high_precision_oracle_to_1e_6(n, seed):
    # the accuracy requirement: random systems, n <= 10, well-separated poles
    pair = _random_pair(n, 1, seed, max_cond=1e8)
    if pair is None:
        return
    A, B = pair
    poles = -np.arange(1, n + 1) * 0.5
    K, _ = checked(ck.place, A, B, poles)     # warns where even the exact K misses by > 1e-6
    K_ref = _high_precision_gain(A, B, poles)
    np.testing.assert_allclose(K, K_ref, rtol=1e-6, atol=1e-6 * np.abs(K_ref).max())
    if n <= 4:   # small n: the closed-loop eigenvalues are mostly well conditioned
        _assert_poles_to_rounding(A, B, K, poles)


@given(st.integers(2, 5), st.integers(0, 10_000), st.floats(-4, -0.5))
def test_repeated_pole_single_input(n, seed, pole):
    pair = _random_pair(n, 1, seed, max_cond=1e5)
    if pair is None:
        return
    A, B = pair
    K = ck.place(A, B, [pole] * n)
    # a pole of multiplicity n is sensitive (computed eigenvalues scatter by ~eps^(1/n)), so
    # compare K with the oracle and the characteristic polynomial with a loose tolerance
    K_ref = _high_precision_gain(A, B, [pole] * n)
    np.testing.assert_allclose(K, K_ref, rtol=1e-6, atol=1e-6 * np.abs(K_ref).max())
    p = np.poly([pole] * n)[::-1][:-1]
    np.testing.assert_allclose(ck.charpoly(A + B @ K), p, rtol=1e-4, atol=1e-4 * np.abs(p).max())


@given(st.integers(2, 5), st.integers(2, 3), st.integers(0, 10_000))
def test_mimo_places_the_poles_and_matches_scipy_with_flipped_sign(n, m, seed):
    from scipy.signal import place_poles
    pair = _random_pair(n, m, seed, max_cond=1e6)
    if pair is None or np.linalg.matrix_rank(pair[1]) < m:
        return
    A, B = pair
    poles = np.array([-1, -1.5 + 1j, -1.5 - 1j, -2, -3][:n] if n != 2 else [-1, -2])
    K = ck.place(A, B, poles)
    assert K.shape == (m, n)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A + B @ K)), sorted_eig(poles), atol=1e-6)
    np.testing.assert_allclose(K, -place_poles(A, B, poles).gain_matrix, atol=1e-9)
