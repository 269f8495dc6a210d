"""place and place_observer check their own result (issue 14): achieved poles, unit changes,
rank-deficient B and C, poles repeated more often than there are inputs, SI-unit systems."""

import importlib
import re
import warnings

import control
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import linear_sum_assignment

import coursekit as ck

placement = importlib.import_module("coursekit.placement")
observability = importlib.import_module("coursekit.observability")
_pole_placement = importlib.import_module("coursekit._pole_placement")
EPS = np.finfo(float).eps


# ------------------------------------------------------------------------------------------
# An independent statement of the documented contract

def matched(M, poles, A=None):
    """eig(M) matched to `poles` by an optimal assignment, and the pole scale: the largest
    requested or achieved pole, or the spectral radius of the open loop A if larger, as in
    place's docstring."""
    poles = np.asarray(poles, dtype=complex)
    eig = np.linalg.eigvals(M)
    rows, cols = linear_sum_assignment(np.abs(eig[:, None] - poles[None, :]))
    got = np.empty_like(poles)
    got[cols] = eig[rows]
    radius = 0.0 if A is None else np.abs(np.linalg.eigvals(A)).max()
    return got, max(np.abs(poles).max(), np.abs(got).max(), radius)


def assert_poles_met(M, poles, A=None):
    """The docstrings' promise when no warning is issued: a pole requested k times has its k
    eigenvalues averaging to it within 1e-6 of the scale, each within 1e-6^(1/k) of it."""
    poles = np.asarray(poles, dtype=complex)
    got, scale = matched(M, poles, A)
    for value in np.unique(poles):          # repeated poles in these tests are exact copies
        group = poles == value
        k = group.sum()
        # the factor 1 + 1e-9 only absorbs the rounding of the comparison itself
        assert abs(got[group].mean() - value) <= 1e-6 * scale * (1 + 1e-9), (value, got[group])
        assert np.abs(got[group] - value).max() <= 1e-6 ** (1 / k) * scale * (1 + 1e-9), (value, got[group])


def rounding_bound(A, B, K, M, scale):
    """First-order pole error that rounding alone causes, relative to the scale: a backward
    stable gain is exact for data perturbed by eps (||A|| + ||B|| ||K||), and eigenvalues move
    by that times the eigenvector condition number cond(V) of the closed loop."""
    _, V = np.linalg.eig(M)
    n = M.shape[0]
    size = np.linalg.norm(A, 2) + np.linalg.norm(B, 2) * np.linalg.norm(K, 2)
    return n * EPS * size * np.linalg.cond(V) / scale


def checked(design, A, B, poles, *, observer=False):
    """Run `design`; its AccuracyWarning is allowed only where conditioning explains it.

    Without a warning the contract of assert_poles_met must hold. A warning is accepted only
    when the rounding bound exceeds 1e-9: the warning threshold is 1e-6, so a method that
    warns where rounding accounts for less than a thousandth of that is inaccurate itself.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ck.AccuracyWarning)
        G = design(A, B, poles)
    M = A - G @ B if observer else A + B @ G
    accuracy = [w for w in caught if issubclass(w.category, ck.AccuracyWarning)]
    if accuracy:
        _, scale = matched(M, poles, A)
        # dual roles for the observer: (A^T, C^T, L^T) is the feedback problem
        pair = (A.T, B.T, G.T) if observer else (A, B, G)
        bound = rounding_bound(*pair, M, scale)
        assert bound > 1e-9, f"warned although rounding explains only {bound:.1e}: {accuracy[0].message}"
    else:
        assert_poles_met(M, poles, A)
    return G, bool(accuracy)


# ------------------------------------------------------------------------------------------
# Strategies: random controllable systems, pole sets with repeats, changes of units

def pole_set(rng, n, max_repeat):
    """n poles closed under conjugation with magnitudes 0.5..5, some of them repeated."""
    poles = []
    while len(poles) < n:
        k = int(rng.integers(1, max_repeat + 1))
        if n - len(poles) >= 2 and rng.random() < 0.3:
            p = complex(-rng.uniform(0.5, 3), rng.uniform(0.5, 3))
            poles += [p, p.conjugate()]
        else:
            poles += [-rng.uniform(0.5, 5)] * min(k, n - len(poles))
    return np.array(poles[:n], dtype=complex)


def random_pair(rng, n, m, r):
    """(A, B) with A ~ N(0, 1) and B = B0 R of rank r (r < m: rank-deficient B)."""
    A = rng.normal(size=(n, n))
    B = rng.normal(size=(n, r)) @ rng.normal(size=(r, m))
    return A, B


units = st.tuples(st.lists(st.floats(-4, 4), min_size=6, max_size=6), st.floats(-4, 4))


def change_units(A, B, logs, log_a):
    """x -> D x with D = diag(10^logs) and time t -> t / a: (a D A D^-1, a D B)."""
    D = 10.0 ** np.asarray(logs[:A.shape[0]])
    a = 10.0 ** log_a
    return a * D[:, None] * A / D[None, :], a * D[:, None] * B, D, a


# ------------------------------------------------------------------------------------------
# The warning and its tolerance

def test_twenty_poles_minus_one_to_minus_twenty_warn_for_feedback_and_observer():
    # even the exact gain, rounded to double, misses these poles by orders of magnitude
    # (the closed loop is similar to the companion matrix of Wilkinson's polynomial)
    rng = np.random.default_rng(0)
    A, B = rng.normal(size=(20, 20)), rng.normal(size=(20, 1))
    poles = -np.arange(1.0, 21.0)
    with pytest.warns(ck.AccuracyWarning, match=r"closed-loop poles eig\(A \+ B K\).*largest error is "
                      r".*relative to the pole scale.*eigenvector condition number is .*less clustered"):
        K = ck.place(A, B, poles)
    got, scale = matched(A + B @ K, poles)
    assert np.abs(got - poles).max() > 1e-3 * scale      # the warning is real, not a false alarm
    with pytest.warns(ck.AccuracyWarning, match=r"observer poles eig\(A - L C\) of the estimation error"):
        ck.place_observer(A.T, B.T, poles)
    # the notes' route through the canonical form: its transform is no canonical form at n = 20
    # (a miss of 8e3) and says so too (issue 35)
    # one recorder per call (pytest 7 lets an inner pytest.warns swallow what an outer one waits for)
    for details, said in ((lambda: ck.place_details(A, B, poles),
                           [r"closed-loop poles", r"controllability canonical form .* cannot be computed"]),
                          (lambda: ck.place_observer_details(A.T, B.T, poles),
                           [r"observer poles", r"observability canonical form .* cannot be computed"])):
        with pytest.warns(ck.AccuracyWarning) as record:
            details()
        messages = [str(w.message) for w in record]
        for pattern in said:
            assert any(re.search(pattern, m) for m in messages), (pattern, messages)


@pytest.mark.parametrize("relative_error, warns", [(1e-4, True), (1e-10, False)])
def test_the_check_catches_a_wrong_gain_and_only_a_wrong_one(monkeypatch, relative_error, warns):
    # a deliberately wrong K (poles moved by about relative_error) must warn; a K wrong only
    # at rounding level must not (the check is neither too lax nor too strict)
    right = _pole_placement.place_gain

    def wrong(A, B, poles):
        K, _ = right(A, B, poles)
        K = K * (1 + relative_error)
        return K, _pole_placement.PoleMatch(A + B @ K, poles)

    monkeypatch.setattr(placement, "place_gain", wrong)
    monkeypatch.setattr(observability, "place_gain", wrong)
    A, B = np.array([[0, 1.0], [-2, -3]]), np.array([[0], [1.0]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ck.AccuracyWarning)
        ck.place(A, B, [-4, -5])
        ck.place_observer(A.T, B.T, [-4, -5])
    assert len(caught) == (2 if warns else 0)


def test_a_triple_pole_is_not_a_false_alarm():
    # eig scatters a triple pole by ~eps^(1/3) ~ 1e-5, above 1e-6: the cluster rule must not warn
    A, B = np.eye(3, k=1), np.array([[0], [0], [1.0]])
    K = ck.place(A, B, [-2, -2, -2])
    got, _ = matched(A + B @ K, [-2, -2, -2])
    assert np.abs(got + 2).max() > 1e-6                  # the scatter the rule has to allow
    np.testing.assert_allclose(K, [[-8, -12, -6]], atol=1e-12)


# ------------------------------------------------------------------------------------------
# No false refusals: rank-deficient B and C, repeated poles with several inputs

def test_rank_deficient_b_and_equal_rows_of_c():
    A = np.array([[0, 1.0], [-2, -3]])
    B = np.array([[0, 0], [1, 1.0]])
    for poles in ([-3, -4], [-1, -2], [-2, -2], [-1 + 1j, -1 - 1j]):
        K, warned = checked(ck.place, A, B, poles)
        assert not warned and K.shape == (2, 2)
        L, warned = checked(ck.place_observer, A, B.T, poles, observer=True)
        assert not warned and L.shape == (2, 2)
    # the same gain as one input through b = B g with the minimum-norm split over the columns
    K = ck.place(A, B, [-3, -4])
    np.testing.assert_allclose(K[0], K[1], atol=1e-12)
    np.testing.assert_allclose(2 * K[0], -control.acker(A, B[:, :1], [-3, -4]).ravel(), atol=1e-12)


def test_a_pole_repeated_more_often_than_there_are_inputs():
    A = np.array([[0, 1, 0], [0, 0, 1], [1, 2, 3.0]])
    B = np.array([[0, 1], [1, 0], [0, 1.0]])
    # Heymann's gain makes the triple pole one Jordan chain: eig scatters it by ~1e-5, while two
    # inputs (outputs) allow chains of length 2 (scatter ~1e-8); both designs say so (issue 35)
    for design, pair in ((ck.place, (A, B)), (ck.place_observer, (A, B.T))):
        with pytest.warns(ck.AccuracyWarning, match=r"requested 3 times with 2 independent inputs"):
            design(*pair, [-2, -2, -2])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ck.AccuracyWarning)
        L, K_dual = ck.place_observer(A, B.T, [-2, -2, -2]), ck.place(A.T, B, [-2, -2, -2])
    np.testing.assert_allclose(L, -K_dual.T, atol=1e-12)
    # three inputs, all poles equal: K = -2 I is the obvious answer and the robust one
    K = ck.place(np.zeros((3, 3)), np.eye(3), [-2, -2, -2])
    np.testing.assert_allclose(K, -2 * np.eye(3), atol=1e-12)


# ------------------------------------------------------------------------------------------
# Oracles

@given(st.integers(2, 8), st.integers(0, 10_000))
@settings(max_examples=30)
def test_single_input_is_minus_python_controls_acker(n, seed):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    poles = pole_set(rng, n, 1)
    K, _ = checked(ck.place, A, B, poles)
    # K is unique for one input; acker (Ackermann's formula, u = -K x) is exact up to its Wc
    # solve, which loses cond(Wc) * eps <= 1e-10 relative: 1e-8 leaves a factor 100
    K_ref = -np.atleast_2d(control.acker(A, B, poles))
    np.testing.assert_allclose(K, K_ref, rtol=1e-8, atol=1e-8 * np.abs(K_ref).max())


@given(st.integers(2, 5), st.integers(2, 3), st.integers(0, 10_000))
@settings(max_examples=30)
def test_full_rank_inputs_are_minus_python_controls_place(n, m, seed):
    rng = np.random.default_rng(seed)
    A, B = random_pair(rng, n, m, m)
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    poles = pole_set(rng, n, 1)
    K, warned = checked(ck.place, A, B, poles)
    if not warned:
        # the same Tits-Yang iteration on the same data; its converged eigenvectors agree to
        # ~1e-12 and K = B^+ (...) inherits cond(B) of that, hence 1e-7 relative
        K_ref = -control.place(A, B, poles)
        np.testing.assert_allclose(K, K_ref, rtol=1e-7, atol=1e-7 * np.abs(K_ref).max())


# ------------------------------------------------------------------------------------------
# Random systems in random units

@given(st.integers(2, 6), st.integers(0, 10_000), units)
@settings(max_examples=40)
def test_single_input_gain_transforms_with_the_units(n, seed, unit_change):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    poles = pole_set(rng, n, 2)
    K, _ = checked(ck.place, A, B, poles)
    A_u, B_u, D, a = change_units(A, B, *unit_change)
    # a (A + B K) has poles a * poles, and in x_u = D x the same feedback reads K D^-1
    K_u, _ = checked(ck.place, A_u, B_u, a * poles)
    # K is unique, and both are computed in balanced coordinates, which undo D up to powers
    # of 2; what is left is rounding amplified by the conditioning of the gain: at most
    # 4e-13 relative over 300 random draws with cond(Wc) <= 1e6, so 1e-9 leaves a factor 1000
    np.testing.assert_allclose(K_u * D, K, rtol=1e-9, atol=1e-9 * np.abs(K).max())


@given(st.integers(2, 6), st.integers(2, 3), st.integers(0, 10_000), units)
@settings(max_examples=40)
def test_several_inputs_rank_deficient_or_repeated_in_any_units(n, m, seed, unit_change):
    rng = np.random.default_rng(seed)
    r = int(rng.integers(1, m + 1))
    A, B = random_pair(rng, n, m, r)
    if np.linalg.cond(ck.ctrb(A, B)) > 1e6:
        return
    poles = pole_set(rng, n, 3)                          # repeats up to 3 > rank(B) = r
    A_u, B_u, _, a = change_units(A, B, *unit_change)
    C_u = B_u.T                                           # the dual: an observer with these outputs
    K, _ = checked(ck.place, A_u, B_u, a * poles)
    L, _ = checked(ck.place_observer, A_u.T, C_u, a * poles, observer=True)
    assert K.shape == (m, n) and L.shape == (n, m)


# ------------------------------------------------------------------------------------------
# Systems in SI units

def dc_motor():
    J, b, K, R, L = 3.2284e-6, 3.5077e-6, 0.0274, 4.0, 2.75e-6
    A = np.array([[0, 1, 0], [0, -b / J, K / J], [0, -K / L, -R / L]])
    B = np.array([[0], [0], [1 / L]])
    return A, B


def test_dc_motor_in_si_units():
    # the naive rank of Wc called this motor uncontrollable (issue 14); place must design for it
    A, B = dc_motor()
    poles = np.array([-100, -200, -300], dtype=complex)
    K, warned = checked(ck.place, A, B, poles)
    assert not warned
    assert_poles_met(A + B @ K, poles, A)
    # independent oracle: the closed-loop characteristic polynomial (3.43) by coefficients,
    # each entry of A + B K is exact to ~eps * |R/L| = 3e-10, far below these coefficients
    np.testing.assert_allclose(np.poly(A + B @ K), np.poly(poles).real, rtol=1e-8)
    # the same motor with time in ms and current in mA: the same feedback law in new units
    D, a = np.diag([1.0, 1.0, 1e3]), 1e-3
    K_u, _ = checked(ck.place, a * D @ A @ np.linalg.inv(D), a * D @ B, a * poles)
    np.testing.assert_allclose(K_u @ D, K, rtol=1e-9)


def test_cart_pole_in_si_units():
    M, m, l, g = 0.5, 0.2, 0.3, 9.81                     # kg, kg, m, m/s^2
    A = np.array([[0, 1, 0, 0], [0, 0, -m * g / M, 0], [0, 0, 0, 1], [0, 0, (M + m) * g / (M * l), 0]])
    B = np.array([[0], [1 / M], [0], [-1 / (M * l)]])
    poles = [-2, -3, -4 + 1j, -4 - 1j]
    K, warned = checked(ck.place, A, B, poles)
    assert not warned
    # oracle in python-control's sign (u = -K x)
    np.testing.assert_allclose(K, -np.atleast_2d(control.acker(A, B, poles)), rtol=1e-10)
    C = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0]])          # cart position and angle
    L, warned = checked(ck.place_observer, A, C, [-10, -11, -12, -12], observer=True)
    assert not warned


# ------------------------------------------------------------------------------------------
# poly_from_roots validates its input

@pytest.mark.parametrize("poles, message", [
    ([-1, np.nan], r"poles contains NaN or infinite"),
    ([-1, np.inf], r"poles contains NaN or infinite"),
    ([-1 + 1j, -2], r"without its conjugate"),
    ("ab", r"poles must be a list of numbers"),
    ([], r"poles is empty"),
])
def test_poly_from_roots_rejects_bad_poles(poles, message):
    with pytest.raises(ValueError, match=message):
        ck.poly_from_roots(poles)


def test_poly_from_roots_values():
    np.testing.assert_allclose(ck.poly_from_roots([-1 + 2j, -1 - 2j]), [5, 2])   # s^2 + 2 s + 5
    np.testing.assert_allclose(ck.poly_from_roots(-2), [2])
    # any number of roots: the degree is their count (s + 1)(s + 2)(s + 3) = s^3 + 6 s^2 + 11 s + 6
    np.testing.assert_allclose(ck.poly_from_roots([-1, -2, -3]), [6, 11, 6])


# ------------------------------------------------------------------------------------------
# Edge cases of the check: deadbeat designs, overflow

def test_discrete_time_deadbeat_is_not_a_false_alarm():
    # all poles at 0 (deadbeat, x(t+3) = 0) for a sampled triple integrator: the computed
    # eigenvalues of the nilpotent A + B K scatter by ~eps^(1/3) ~ 1e-5, which the check judges
    # against A's own speed (spectral radius 1), not against the requested 0
    A = np.array([[1, 1, 0.5], [0, 1, 1], [0, 0, 1.0]])
    B = np.array([[1 / 6], [0.5], [1.0]])
    K = ck.place(A, B, [0, 0, 0])
    np.testing.assert_allclose(np.linalg.matrix_power(A + B @ K, 3), 0, atol=1e-12)
    L = ck.place_observer(A, [[1.0, 0, 0]], [0, 0, 0])
    np.testing.assert_allclose(np.linalg.matrix_power(A - L @ np.array([[1.0, 0, 0]]), 3), 0, atol=1e-12)


def test_an_overflowing_gain_is_an_error_not_a_nan():
    with pytest.raises(ValueError, match=r"the gain K overflows double precision.*ctrb_singular"):
        ck.place([[0, 1], [0, 0]], [[0], [1]], [-1e200, -1e200])
    with pytest.raises(ValueError, match=r"the gain L overflows double precision.*obsv_singular"):
        ck.place_observer([[0, 1], [0, 0]], [[1, 0]], [-1e200, -1e200])


def test_several_inputs_above_a_hundred_states_are_refused_before_any_work():
    # issue 25: a 200-state, 3-input place ran for minutes (Tits-Yang's iteration, then Heymann)
    import time
    rng = np.random.default_rng(0)
    A = rng.standard_normal((200, 200))
    start = time.perf_counter()
    with pytest.raises(ValueError, match=r"A has 200 states: pole placement with several channels "
                                         r"\(B has 3 columns\) is limited to 100 states"):
        ck.place(A, rng.standard_normal((200, 3)), -np.linspace(1, 20, 200))
    with pytest.raises(ValueError, match=r"\(C has 3 rows\) is limited to 100 states(?s:.*)kalman_gain"):
        ck.place_observer(A, rng.standard_normal((3, 200)), -np.linspace(1, 20, 200))
    assert time.perf_counter() - start < 1.0
    # one input is cheap (one Hessenberg reduction) and stays allowed
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ck.AccuracyWarning)
        assert ck.place(A, rng.standard_normal((200, 1)), -np.linspace(1, 20, 200)).shape == (1, 200)


def test_poles_far_below_the_scale_of_a_warn():
    # issue 25: for A scaled by 1e200 the closed loop's poles came out near 4e193, not at -1 and
    # -2, and the check passed them, measuring the error against A's own size
    A = np.array([[0.0, 1.0], [-2.0, -3.0]]) * 1e200
    # the error itself depends on the LAPACK build (3.9e193 and 4.3e193 seen): its size is what counts
    with pytest.warns(ck.AccuracyWarning, match=r"largest error is \d(\.\d+)?e\+19[0-9] at the requested pole"):
        ck.place(A, [[0.0], [1.0]], [-1.0, -2.0])
    with pytest.warns(ck.AccuracyWarning, match=r"estimation error|requested pole"):
        ck.place_observer(A, [[1.0, 0.0]], [-1.0, -2.0])
    # the same request at a scale double precision can hold is met without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        K = ck.place(np.array([[0.0, 1.0], [-2.0, -3.0]]) * 1e6, [[0.0], [1.0]], [-1.0, -2.0])
    # det(sI - A - B K) = s^2 - (A22 + k2) s - A12 (A21 + k1) = s^2 + 3 s + 2
    np.testing.assert_allclose(K, [[2e6 - 2e-6, 3e6 - 3.0]], rtol=1e-14)
