"""Systems and expected facts from the test suites of SciPy and python-control, run through
coursekit (issue 14).

Only the numbers and the facts are taken over (matrices, requested poles, expected verdicts,
Gramians, gains, canonical forms); the checks are our own. Each case names its origin:
"SciPy TestPlacePoles.<test>" is scipy/signal/tests/test_ltisys.py, "python-control
<test>" is control/tests/statefbk_test.py, stochsys_test.py or canonical_test.py.

Sign: coursekit's K is minus SciPy's ``gain_matrix`` and python-control's ``place``/``acker``
gain (u = K x, closed loop A + B K). Where coursekit legitimately differs from those
libraries (poles repeated more often than rank(B), which SciPy and python-control refuse),
the test asserts coursekit's documented behaviour instead and says so.

Every call below runs with CoursekitWarning turned into an error (pyproject filterwarnings),
so each case also asserts that no AccuracyWarning is raised for these well-posed problems.
"""

import contextlib

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings, strategies as st

import control
import coursekit as ck
from test_placement_checks import assert_poles_met
from test_unit_free_verdicts import _rescale, _units

seeds = st.integers(0, 2**32 - 1)

# ------------------------------------------------------------------------------------------
# Data

# SciPy TestPlacePoles.test_real (example 1 of Kautsky-Nichols-Van Dooren), also
# python-control testPlace ("matrices stolen from scipy example code")
A_KNV = np.array([[1.380, -0.2077, 6.715, -5.676],
                  [-0.5814, -4.290, 0, 0.6750],
                  [1.067, 4.273, -6.654, 5.893],
                  [0.0480, 4.273, 1.343, -2.104]])
B_KNV = np.array([[0, 5.679], [1.136, 1.136], [0, 0], [-3.146, 0]])

# SciPy TestPlacePoles.test_tricky_B: a square B of full rank (4 inputs)
B_SQUARE = np.array([[0, 5.679, 1.136, 1.136], [0, 0, -3.146, 0],
                     [1, 2, 3, 4], [5, 6, 7, 8]], dtype=float)

# SciPy TestPlacePoles.test_complex (and test_errors): linearized car model
A_CAR = np.array([[0, 7, 0, 0], [0, 0, 0, 7 / 3], [0, 0, 0, 0], [0, 0, 0, 0]])
B_CAR = np.array([[0, 0], [0, 0], [1, 0], [0, 1]], dtype=float)

# SciPy TestPlacePoles.test_complex: 6 states, 5 inputs ("found via Monte Carlo")
A_MC = np.array([[-2148, -2902, -2267, -598, -1722, -1829],
                 [-165, -283, -2546, -167, -754, -2285],
                 [-543, -1700, -584, -2978, -925, -1300],
                 [-1583, -984, -386, -2650, -764, -897],
                 [-517, -1598, 2, -1709, -291, -338],
                 [-153, -1804, -1106, -1168, -867, -2297]], dtype=float)
B_MC = np.array([[-108, -374, -524, -1285, -1232],
                 [-161, -1204, -672, -637, -15],
                 [-483, -23, -931, -780, -1245],
                 [-1129, -1290, -1502, -952, -1374],
                 [-62, -964, -930, -939, -792],
                 [-756, -1437, -491, -1543, -686]], dtype=float)


def big_pair():
    """SciPy TestPlacePoles.test_complex: 11 states, 10 inputs, with A_MC, B_MC in the corner."""
    A = np.ones((11, 11)) - np.eye(11)
    B = np.ones((11, 10)) - np.diag([1] * 10, 1)[:, 1:]
    A[:6, :6], B[:6, :5] = A_MC, B_MC
    return A, B


# SciPy TestPlacePoles.test_complex: 5 states, 2 inputs
A_FIVE = np.array([[0, 7, 0, 0, 0], [0, 0, 7 / 3, 0, 0], [0, 0, 0, 0, 0],
                   [0, 0, 0, 0, 5], [0, 0, 0, 0, 9]])
B_FIVE = np.array([[0, 0], [0, 0], [1, 0], [0, 1], [2, 3]], dtype=float)

# python-control testCtrbSISO / testObsvSISO / testCtrbMIMO / testObsvMIMO
A_2 = np.array([[1.0, 2.0], [3.0, 4.0]])

# python-control testPlace_varga_continuous
A_VARGA = np.array([[1.0, -2.0], [3.0, -4.0]])

# python-control canonical_test test_unreachable_system / test_unobservable_system
A_UNREACHABLE = np.array([[1.0, 2.0, 2.0], [4.0, 5.0, 5.0], [7.0, 8.0, 8.0]])
ONES_3 = np.ones((3, 1))

# python-control canonical_test test_reachable_form / test_observable_form: the transform
# applied to the canonical forms of s^4 + 4 s^3 + 3 s^2 + 2 s + 1
T_CANONICAL = np.array([[-0.27144004, -0.39933167, 0.75634684, 0.44135471],
                        [-0.74855725, -0.39136285, -0.18142339, -0.50356997],
                        [-0.40688007, 0.81416369, 0.38002113, -0.16483334],
                        [-0.44769516, 0.15654653, -0.50060858, 0.72419146]])
CHARPOLY_CANONICAL = np.array([1.0, 2.0, 3.0, 4.0, 1.0])    # ascending, as in DESIGN.md


# (origin, A, B, poles): each is placed by SciPy's or python-control's own test
PLACEMENTS = [
    ("SciPy TestPlacePoles.test_real", A_KNV, B_KNV, [-0.2, -0.5, -5.0566, -8.6659]),
    ("SciPy TestPlacePoles.test_real: poles (2, 2, 3, 3)", A_KNV, B_KNV, [2, 2, 3, 3]),
    ("python-control testPlace", A_KNV, B_KNV, [-0.5 + 1j, -0.5 - 1j, -5.0566, -8.6659]),
    ("SciPy TestPlacePoles.test_tricky_B: square B", A_KNV, B_SQUARE, [-0.2, -0.5, -5.0566, -8.6659]),
    ("SciPy TestPlacePoles.test_tricky_B: square B, complex", A_KNV, B_SQUARE, [-2 + 1j, -2 - 1j, -3, -2]),
    ("SciPy TestPlacePoles.test_tricky_B: one column", A_KNV, B_SQUARE[:, :1], [-2 + 1j, -2 - 1j, -3, -2]),
    ("SciPy TestPlacePoles.test_complex: car", A_CAR, B_CAR, [-3, -1, -2 - 1j, -2 + 1j]),
    ("SciPy TestPlacePoles.test_complex: car, near-equal pair", A_CAR, B_CAR, [-1e-6j, 1e-6j, -10, 10]),
    ("SciPy TestPlacePoles.test_complex: Monte Carlo 6x5", A_MC, B_MC,
     [-25 - 29j, -25 + 29j, 31 - 42j, 31 + 42j, 33 - 41j, 33 + 41j]),
    ("SciPy TestPlacePoles.test_complex: 11 states", *big_pair(),
     [-10, -20, -30, 40, 50, 60, 70, -20 - 5j, -20 + 5j, 5 + 3j, 5 - 3j]),
    ("SciPy TestPlacePoles.test_complex: 10 states, real", big_pair()[0][:-1, :-1], big_pair()[1][:-1, :-1],
     [-10, -20, -30, -40, -50, -60, -70, -80, -90, -100]),
    ("SciPy TestPlacePoles.test_complex: 10 states, complex", big_pair()[0][:-1, :-1], big_pair()[1][:-1, :-1],
     [-10 + 10j, -20 + 20j, -30 + 30j, -40 + 40j, -50 + 50j, -10 - 10j, -20 - 20j, -30 - 30j, -40 - 40j,
      -50 - 50j]),
    ("SciPy TestPlacePoles.test_complex: 5 states, one real pole", A_FIVE, B_FIVE,
     [-2, -3 + 1j, -3 - 1j, -1 + 1j, -1 - 1j]),
    ("SciPy TestPlacePoles.test_complex: 5 states, odd real poles", A_FIVE, B_FIVE,
     [-2, -3, -4, -1 + 1j, -1 - 1j]),
    # SciPy and python-control refuse a pole repeated more often than rank(B) (their
    # test_errors "rank(B) is two" and testPlace "too many poles in the same location");
    # coursekit's place documents that it places these through Heymann's lemma instead
    ("SciPy TestPlacePoles.test_errors: (-2, -2, -2, -2), rank(B) = 2", A_CAR, B_CAR, [-2, -2, -2, -2]),
    ("python-control testPlace: P_repeated, rank(B) = 2", A_KNV, B_KNV, [-0.5, -0.5, -0.5, -8.6659]),
    # python-control testPlace_varga_continuous: a double pole with one input (SciPy's
    # place_poles refuses it for the same reason; python-control's place_varga accepts it)
    ("python-control testPlace_varga_continuous", A_VARGA, np.array([[5.0], [7.0]]),
     [-2, -2]),
    ("python-control testPlace_varga_continuous: bug #177", np.array([[0.0, 1.0], [100.0, 0.0]]),
     np.array([[0.0], [1.0]]), [-20 + 10j, -20 - 10j]),
    ("python-control testPlace_varga_discrete", np.diag([1.0, 0.5]), np.array([[5.0], [7.0]]), [0.5, 0.5]),
]
IDS = [case[0] for case in PLACEMENTS]


# ------------------------------------------------------------------------------------------
# Controllability and observability verdicts

@pytest.mark.parametrize("origin, A, B, poles", PLACEMENTS, ids=IDS)
def test_every_placed_system_is_controllable_and_its_dual_observable(origin, A, B, poles):
    # both libraries place these poles, so the pairs are controllable
    assert ck.is_controllable(A, B), origin
    assert ck.is_observable(A.T, B.T), origin


@settings(max_examples=20)
@given(seeds)
def test_verdicts_on_the_ported_systems_survive_changes_of_units(seed):
    rng = np.random.default_rng(seed)
    for _, A, B, _ in PLACEMENTS:
        a, d = _units(rng, A.shape[0])
        As, Bs, _ = _rescale(A, B, B.T, a, d)
        assert ck.is_controllable(As, Bs)
        assert ck.is_observable(As.T, Bs.T)          # the dual pair


@settings(max_examples=20)
@given(seeds)
def test_uncontrollable_ported_systems_stay_uncontrollable_in_any_units(seed):
    rng = np.random.default_rng(seed)
    # SciPy TestPlacePoles.test_errors: "uncontrollable system", ones((4, 4)), ones((4, 2));
    # python-control canonical_test: the unreachable and unobservable 3-state system
    for A, B in [(np.ones((4, 4)), np.ones((4, 2))), (A_UNREACHABLE, ONES_3)]:
        a, d = _units(rng, A.shape[0])
        As, Bs, Cs = _rescale(A, B, B.T, a, d)
        assert not ck.is_controllable(A, B) and not ck.is_controllable(As, Bs)
        assert not ck.is_observable(A, B.T) and not ck.is_observable(As, Cs)


def test_uncontrollable_systems_are_refused_by_every_design():
    # SciPy TestPlacePoles.test_errors: place_poles(ones((4, 4)), ones((4, 2)), (1, 2, 3, 4)) raises
    with pytest.raises(ck.NotControllableError, match="not controllable"):
        ck.place(np.ones((4, 4)), np.ones((4, 2)), [1, 2, 3, 4])
    with pytest.raises(ck.NotObservableError, match="not observable"):
        ck.place_observer(np.ones((4, 4)), np.ones((2, 4)), [1, 2, 3, 4])
    # python-control test_unreachable_system / test_unobservable_system: no canonical form
    with pytest.raises(ck.NotControllableError):
        ck.ccf_transform(A_UNREACHABLE, ONES_3)
    with pytest.raises(ck.NotObservableError):
        ck.ocf_transform(A_UNREACHABLE, ONES_3.T)


@pytest.mark.parametrize("B, Wc", [
    # python-control testCtrbSISO, testCtrbMIMO
    (np.array([[5.0], [7.0]]), [[5, 19], [7, 43]]),
    (np.array([[5.0, 6.0], [7.0, 8.0]]), [[5, 6, 19, 22], [7, 8, 43, 50]]),
])
def test_controllability_matrix(B, Wc):
    # small integers: every entry is exact in double precision
    np.testing.assert_array_equal(ck.ctrb(A_2, B), Wc)
    assert ck.is_controllable(A_2, B)


@pytest.mark.parametrize("C, Wo", [
    # python-control testObsvSISO, testObsvMIMO
    (np.array([[5.0, 7.0]]), [[5, 7], [26, 38]]),
    (np.array([[5.0, 6.0], [7.0, 8.0]]), [[5, 6], [7, 8], [23, 34], [31, 46]]),
])
def test_observability_matrix(C, Wo):
    np.testing.assert_array_equal(ck.obsv(A_2, C), Wo)     # exact, as above
    assert ck.is_observable(A_2, C)


def test_ctrb_obsv_duality():
    # python-control testCtrbObsvDuality: Wc(A, B) = Wo(A^T, B^T)^T
    A = np.array([[1.2, -2.3], [3.4, -4.5]])
    B = np.array([[5.8, 6.9], [8.0, 9.1]])
    # the same products in the same order, transposed: equal up to one rounding each
    np.testing.assert_allclose(ck.ctrb(A, B), ck.obsv(A.T, B.T).T, rtol=1e-14)
    assert ck.is_controllable(A, B) and ck.is_observable(A.T, B.T)


# ------------------------------------------------------------------------------------------
# Placement

def _one_chain(B, poles):
    """A context that expects the AccuracyWarning of a pole requested more often than B has
    independent inputs (several of them): Heymann's gain makes it one Jordan chain, whose
    eigenvalues eig scatters beyond the 1e-6 a gain with shorter chains keeps (issue 35);
    for any other case no warning (it would be an error here)."""
    rank = np.linalg.matrix_rank(B)
    repeats = max(list(poles).count(p) for p in poles)
    if rank > 1 and repeats > rank:
        return pytest.warns(ck.AccuracyWarning, match=rf"requested {repeats} times with {rank} independent inputs")
    return contextlib.nullcontext()


@pytest.mark.parametrize("origin, A, B, poles", PLACEMENTS, ids=IDS)
def test_place_meets_the_ported_poles(origin, A, B, poles):
    with _one_chain(B, poles):
        K = ck.place(A, B, poles)
    assert K.shape == (B.shape[1], A.shape[0])
    assert_poles_met(A + B @ K, poles, A)


@pytest.mark.parametrize("origin, A, B, poles", PLACEMENTS, ids=IDS)
def test_place_observer_meets_the_ported_poles_by_duality(origin, A, B, poles):
    # the transposed data as an observer problem: eig(A^T - L B^T) = poles
    with _one_chain(B, poles):
        L = ck.place_observer(A.T, B.T, poles)
    assert L.shape == (A.shape[0], B.shape[1])
    assert_poles_met(A.T - L @ B.T, poles, A)
    if B.shape[1] == 1:
        # one input: the gain is unique and the observer gain is the dual one, L = -K^T;
        # both come from the same well-conditioned method, so they agree to near rounding
        np.testing.assert_allclose(L, -ck.place(A, B, poles).T, rtol=1e-10, atol=1e-12 * np.abs(L).max())


# single-input cases with simple poles, where SciPy's gain is unique and SciPy computes it
SINGLE_INPUT = [case for case in PLACEMENTS if case[2].shape[1] == 1 and len(set(case[3])) == len(case[3])]


@pytest.mark.parametrize("origin, A, B, poles", SINGLE_INPUT, ids=[c[0] for c in SINGLE_INPUT])
def test_single_input_gain_is_minus_scipys(origin, A, B, poles):
    K = ck.place(A, B, poles)
    G = scipy.signal.place_poles(A, B, poles).gain_matrix
    # these systems are small and well conditioned: SciPy's gain is accurate to ~1e-12 here
    np.testing.assert_allclose(K, -G, rtol=1e-9, atol=1e-12 * np.abs(G).max())


@pytest.mark.parametrize("A, B, poles, K_exact", [
    # python-control testPlace_varga_continuous: A + B K = [[1 + 5 k1, -2 + 5 k2], [3 + 7 k1, -4 + 7 k2]]
    # has trace -4 and determinant 4 (double pole -2) for K = [-3, 2], solved by hand
    (A_VARGA, np.array([[5.0], [7.0]]), [-2, -2], [[-3.0, 2.0]]),
    # python-control testPlace_varga_continuous, bug #177: s^2 - k2 s - (100 + k1) = s^2 + 40 s + 500
    (np.array([[0.0, 1.0], [100.0, 0.0]]), np.array([[0.0], [1.0]]), [-20 + 10j, -20 - 10j], [[-600.0, -40.0]]),
    # python-control testPlace_varga_discrete: trace 1 and determinant 1/4 give K = [-0.1, 0]
    (np.diag([1.0, 0.5]), np.array([[5.0], [7.0]]), [0.5, 0.5], [[-0.1, 0.0]]),
])
def test_single_input_gain_in_closed_form(A, B, poles, K_exact):
    # a backward-stable gain of a 2-state problem with integer data: a few roundings off
    np.testing.assert_allclose(ck.place(A, B, poles), K_exact, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ck.place_observer(A.T, B.T, poles), -np.transpose(K_exact),
                               rtol=1e-12, atol=1e-12)


@settings(max_examples=20)
@given(seeds)
def test_single_input_gains_transform_with_the_units(seed):
    # units: x' = D x, t' = t / a give (a D A D^-1, a D B) and poles a p; then K' = K D^-1
    rng = np.random.default_rng(seed)
    for _, A, B, poles in SINGLE_INPUT:
        a, d = _units(rng, A.shape[0])
        As, Bs, _ = _rescale(A, B, B.T, a, d)
        K = ck.place(A, B, poles)
        Ks = ck.place(As, Bs, a * np.asarray(poles))
        # the documented accuracy of the single-input method is 2e-14 relative per gain;
        # 1e-9 leaves room for the rounding of the rescaled data themselves
        np.testing.assert_allclose(Ks * d, K, rtol=1e-9, atol=1e-9 * np.abs(K).max())


def test_square_b_places_the_poles_as_scipys_gain_does():
    # SciPy TestPlacePoles.test_tricky_B: B square and invertible, so any closed-loop matrix
    # M with these eigenvalues is reached (K = B^-1 (M - A)) and the gains differ; both
    # coursekit's K and minus SciPy's gain must give the poles
    for poles in ([-0.2, -0.5, -5.0566, -8.6659], [-2 + 1j, -2 - 1j, -3, -2]):
        K = ck.place(A_KNV, B_SQUARE, poles)
        G = scipy.signal.place_poles(A_KNV, B_SQUARE, poles).gain_matrix
        assert_poles_met(A_KNV + B_SQUARE @ K, poles, A_KNV)
        assert_poles_met(A_KNV + B_SQUARE @ -G, poles, A_KNV)


@pytest.mark.parametrize("poles", [
    [-0.2, -0.5, -5.0566, -8.6659],
    [-0.5 + 1j, -0.5 - 1j, -5.0566, -8.6659],
])
def test_multi_input_gain_may_differ_from_python_controls_but_places_the_same_poles(poles):
    # python-control testPlace (and SciPy test_real): for two inputs K is not unique; both
    # coursekit's K and minus python-control's gain must give the requested poles
    K = ck.place(A_KNV, B_KNV, poles)
    G = control.place(A_KNV, B_KNV, poles)
    assert_poles_met(A_KNV + B_KNV @ K, poles, A_KNV)
    assert_poles_met(A_KNV - B_KNV @ G, poles, A_KNV)


# ------------------------------------------------------------------------------------------
# Canonical forms

def test_reachable_form_data_gives_the_ccf():
    # python-control test_reachable_form: A = T^-1 A_r T, B = T^-1 e_1 with A_r the reachable
    # form of s^4 + 4 s^3 + 3 s^2 + 2 s + 1; coursekit's CCF (2.16) orders the states the other
    # way (ones on the superdiagonal, last row -[a_0 ... a_3], T B = e_n)
    A_r = np.fliplr(np.rot90(np.polynomial.polynomial.polycompanion(CHARPOLY_CANONICAL)))
    A = np.linalg.solve(T_CANONICAL, A_r) @ T_CANONICAL
    B = np.linalg.solve(T_CANONICAL, [[1.0], [0.0], [0.0], [0.0]])
    np.testing.assert_allclose(ck.charpoly(A), CHARPOLY_CANONICAL[:-1], atol=1e-12)   # T is orthogonal (cond 1)
    T = ck.ccf_transform(A, B)
    A_ccf = T @ A @ np.linalg.inv(T)
    expected = np.diag(np.ones(3), 1)
    expected[-1] = -CHARPOLY_CANONICAL[:-1]
    # T is orthogonal and the entries are O(1): 1e-12 is a few hundred roundings
    np.testing.assert_allclose(A_ccf, expected, atol=1e-12)
    np.testing.assert_allclose(T @ B, [[0], [0], [0], [1]], atol=1e-12)


def test_observable_form_data_gives_the_ocf():
    # python-control test_observable_form: A = T^-1 A_o T, C = e_1^T T with A_o the observable
    # form of the same polynomial; coursekit's OCF (4.31) has ones on the subdiagonal, last
    # column -[a_0 ... a_3] and C T^-1 = e_n^T
    A_o = np.fliplr(np.flipud(np.polynomial.polynomial.polycompanion(CHARPOLY_CANONICAL)))
    A = np.linalg.solve(T_CANONICAL, A_o) @ T_CANONICAL
    C = np.array([[1.0, 0.0, 0.0, 0.0]]) @ T_CANONICAL
    np.testing.assert_allclose(ck.charpoly(A), CHARPOLY_CANONICAL[:-1], atol=1e-12)   # as above
    T = ck.ocf_transform(A, C)
    V = np.linalg.inv(T)
    expected = np.diag(np.ones(3), -1)
    expected[:, -1] = -CHARPOLY_CANONICAL[:-1]
    np.testing.assert_allclose(T @ A @ V, expected, atol=1e-12)     # as for the CCF
    np.testing.assert_allclose(C @ V, [[0, 0, 0, 1]], atol=1e-12)


# ------------------------------------------------------------------------------------------
# Kalman gains

# python-control stochsys_test test_LQE / test_DLQE: A = 0, G = 0.1, C = 1, QN = 10, RN = 2;
# coursekit has no G, so the process noise is Q = G QN G^T = 0.1
A_LQE, C_LQE, Q_LQE, R_LQE = np.zeros((1, 1)), np.ones((1, 1)), np.array([[0.1]]), np.array([[2.0]])


def test_continuous_kalman_gain_of_a_driven_integrator():
    # python-control check_LQE: P = sqrt(G QN G RN), L = P / RN, pole -L
    L, P = ck.kalman_gain(A_LQE, C_LQE, Q_LQE, R_LQE)
    # a scalar Riccati equation solved by a backward-stable method: rounding level
    np.testing.assert_allclose(P, np.sqrt(0.1 * 2.0), rtol=1e-12)
    np.testing.assert_allclose(L, np.sqrt(0.2) / 2.0, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.eigvals(A_LQE - L @ C_LQE), -np.sqrt(0.2) / 2.0, rtol=1e-12)


def test_discrete_kalman_gain_with_a_zero_state_matrix():
    # python-control check_DLQE: P = G QN G, L = 0 (the predictor gain A P C^T (...)^-1 with A = 0)
    L, P = ck.kalman_gain(A_LQE, C_LQE, Q_LQE, R_LQE, dt=0.1)
    np.testing.assert_allclose(P, 0.1, rtol=1e-12)       # as above
    np.testing.assert_array_equal(L, 0.0)                # A = 0 makes L exactly zero


def test_discrete_kalman_gain_matches_dlqe_on_the_ctrb_data():
    # the python-control testObsvSISO pair, with python-control's dlqe as the oracle (same L, P)
    C = np.array([[5.0, 7.0]])
    Q, R = np.eye(2), np.array([[2.0]])
    L, P = ck.kalman_gain(A_2, C, Q, R, dt=0.5)
    L_ref, P_ref, _ = control.dlqe(A_2, np.eye(2), C, Q, R)
    # both solve the same DARE with SciPy's solver: agreement to near rounding
    np.testing.assert_allclose(P, P_ref, rtol=1e-9)
    np.testing.assert_allclose(L, L_ref, rtol=1e-9)
    L_c, P_c = ck.kalman_gain(A_2, C, Q, R)
    L_c_ref, P_c_ref, _ = control.lqe(A_2, np.eye(2), C, Q, R)
    np.testing.assert_allclose(P_c, P_c_ref, rtol=1e-9)        # as above
    np.testing.assert_allclose(L_c, L_c_ref, rtol=1e-9)
