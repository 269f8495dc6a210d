"""Controllability and observability verdicts do not depend on units (issue 14).

Changing units never changes whether a system is controllable or observable:
time t = a t' gives (a A, a B); states x' = D x (D diagonal) give
(D A D^-1, D B, C D^-1); any invertible change of coordinates keeps an exactly
uncontrollable system uncontrollable. The old verdict (the rank of Wc)
failed all of these; the tests below check the new one on random systems,
exactly uncontrollable ones and textbook systems in SI units (si_systems).
"""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck
from si_systems import in_units, si_systems

# unit changes over 1e-4..1e4, both directions
log_scale = st.floats(-4, 4)
seeds = st.integers(0, 2**32 - 1)


def _units(rng, n):
    """A random time scale a and diagonal state scaling d, each factor in 1e-4..1e4."""
    return 10 ** rng.uniform(-4, 4), 10 ** rng.uniform(-4, 4, n)


def _rescale(A, B, C, a, d):
    """(a D A D^-1, a D B, C D^-1) with D = diag(d), formed entry by entry (no inverse)."""
    return a * d[:, None] * A / d[None, :], a * d[:, None] * B, C / d[None, :]


def _kalman_form(rng, n, r, m):
    """An exactly uncontrollable pair in Kalman form [[A11, A12], [0, A22]], [B1; 0], r < n."""
    A = rng.normal(size=(n, n))
    A[r:, :r] = 0.0
    B = np.zeros((n, m))
    B[:r] = rng.normal(size=(r, m))
    return A, B


def _disguise(rng, A, B):
    """The pair in coordinates z = D Q x (Q random orthogonal, D diagonal 1e-4..1e4), time a.

    Formed as a student would, with np.linalg.inv(T): the rounding of that inverse is
    part of what the verdict must tolerate.
    """
    n = A.shape[0]
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    a, d = _units(rng, n)
    T = d[:, None] * Q
    return a * T @ A @ np.linalg.inv(T), a * T @ B


@settings(max_examples=40)
@given(st.integers(1, 30), st.integers(1, 3), seeds)
def test_random_systems_are_controllable_and_observable_in_any_units(n, m, seed):
    rng = np.random.default_rng(seed)
    A, B, C = rng.normal(size=(n, n)), rng.normal(size=(n, m)), rng.normal(size=(m, n))
    a, d = _units(rng, n)
    As, Bs, Cs = _rescale(A, B, C, a, d)
    # N(0, 1) systems are controllable with probability 1 and far from the boundary
    assert ck.is_controllable(A, B) and ck.is_controllable(As, Bs)
    assert ck.is_observable(A, C) and ck.is_observable(As, Cs)
    # and back: from the badly scaled system to its well-scaled form
    A2, B2, C2 = _rescale(As, Bs, Cs, 1 / a, 1 / d)
    assert ck.is_controllable(A2, B2) and ck.is_observable(A2, C2)


@settings(max_examples=10)
@given(st.integers(20, 30), seeds)
def test_random_systems_of_order_20_to_30_are_controllable(n, seed):
    # the rank of Wc called some of these uncontrollable at n = 20 and all at n >= 25
    rng = np.random.default_rng(seed)
    A, B, C = rng.normal(size=(n, n)), rng.normal(size=(n, 1)), rng.normal(size=(1, n))
    assert ck.is_controllable(A, B)
    assert ck.is_observable(A, C)


@settings(max_examples=40)
@given(st.integers(2, 30), st.integers(1, 3), seeds, st.data())
def test_exactly_uncontrollable_systems_are_refused_however_disguised(n, m, seed, data):
    r = data.draw(st.integers(1, n - 1), label="r")
    rng = np.random.default_rng(seed)
    A, B = _kalman_form(rng, n, r, m)
    A2, B2 = _disguise(rng, A, B)
    assert not ck.is_controllable(A2, B2)
    with pytest.raises(ck.NotControllableError, match=rf"rank {r} < n = {n}"):
        ck.place(A2, B2, -np.arange(1.0, n + 1))
    # the dual pair (A^T, B^T) is exactly unobservable
    assert not ck.is_observable(A2.T, B2.T)


@settings(max_examples=30)
@given(st.integers(2, 12), seeds)
def test_exactly_unobservable_single_output_refused_by_ocf_transform(n, seed):
    rng = np.random.default_rng(seed)
    r = int(rng.integers(1, n))
    A, B = _kalman_form(rng, n, r, 1)
    A2, B2 = _disguise(rng, A, B)
    with pytest.raises(ck.NotObservableError, match=rf"rank {r} < n = {n}"):
        ck.ocf_transform(A2.T, B2.T)
    with pytest.raises(ck.NotControllableError, match=rf"rank {r} < n = {n}"):
        ck.ccf_transform(A2, B2)


SYSTEMS = si_systems()
UNITS = {"SI": dict(), "ms": dict(time=1e-3), "mm, mrad": dict(milli=True),
         "minutes, mm, mrad": dict(time=60.0, milli=True)}


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("sys", SYSTEMS, ids=[s.name for s in SYSTEMS])
def test_si_systems_give_the_physical_verdicts_in_any_units(sys, units):
    A, B, C = in_units(sys, **UNITS[units])
    assert ck.is_controllable(A, B) == sys.controllable
    assert ck.is_observable(A, C) == sys.observable


@settings(max_examples=30)
@given(st.sampled_from(SYSTEMS), log_scale, st.lists(log_scale, min_size=4, max_size=4))
def test_si_systems_keep_their_verdicts_under_random_units(sys, log_a, log_d):
    n = sys.A.shape[0]
    A, B, C = _rescale(sys.A, sys.B, sys.C, 10**log_a, 10 ** np.array(log_d[:n]))
    assert ck.is_controllable(A, B) == sys.controllable
    assert ck.is_observable(A, C) == sys.observable


def test_issue_14_examples():
    motor = SYSTEMS[0]
    assert motor.name == "dc_motor"
    for units in UNITS.values():
        A, B, C = in_units(motor, **units)
        assert ck.is_controllable(A, B)
        poles = np.array([-100.0, -200.0, -300.0]) * units.get("time", 1.0)
        K = ck.place(A, B, poles)
        # the poles are well conditioned here; 1e-6 relative leaves room for the spread
        # of the motor's entries (1 to 1e6 rad/s)
        np.testing.assert_allclose(np.sort(np.linalg.eigvals(A + B @ K).real), np.sort(poles),
                                   rtol=1e-6)
    assert ck.is_controllable(-np.diag([1.0, 1e4, 1e8]), np.ones((3, 1)))
    # the same with the states in units that spread B over 8 orders of magnitude
    assert ck.is_controllable(-np.diag([1.0, 1e4, 1e8]), [[1e-4], [1.0], [1e4]])


def test_a_nearly_uncontrollable_pair_says_the_decision_is_marginal():
    # two tanks whose time constants differ by 1e-14 relative: the difference of the levels
    # is reached only through that 1e-14, below the default tolerance (100 n^2 eps = 9e-14)
    A, B = np.diag([-1.0, -1.0 - 1e-14]), np.ones((2, 1))
    assert not ck.is_controllable(A, B)
    with pytest.raises(ck.NotControllableError, match=r"marginal.*tol="):
        ck.place(A, B, [-1, -2])
    # a smaller tol counts the 1e-14 difference as a coupling
    assert ck.is_controllable(A, B, tol=1e-16)
    assert ck.is_observable(A, B.T, tol=1e-16)
    # a clear-cut refusal does not call itself marginal
    with pytest.raises(ck.NotControllableError) as caught:
        ck.place(np.diag([-1.0, -1.0]), B, [-1, -2])
    assert "marginal" not in str(caught.value)


def test_error_messages_say_what_to_do():
    tanks = SYSTEMS[[s.name for s in SYSTEMS].index("parallel_tanks")]
    with pytest.raises(ck.NotControllableError,
                       match=r"rank 1 < n = 2.*1 direction\(s\).*add an actuator"):
        ck.ccf_transform(tanks.A, tanks.B)
    cart = SYSTEMS[[s.name for s in SYSTEMS].index("cart_pendulum_angle_only")]
    with pytest.raises(ck.NotObservableError,
                       match=r"rank 3 < n = 4.*1 direction\(s\).*add a row to C"):
        ck.ocf_transform(cart.A, cart.C)


@pytest.mark.parametrize("tol", [0, -1e-3, 1.5, np.nan, "small"])
def test_bad_tol(tol):
    with pytest.raises(ValueError, match=r"tol must be a number between 0 and 1"):
        ck.is_controllable(np.eye(2), np.ones((2, 1)), tol=tol)
    with pytest.raises(ValueError, match=r"tol must be a number between 0 and 1"):
        ck.is_observable(np.eye(2), np.ones((1, 2)), tol=tol)


@settings(max_examples=40)
@given(st.sampled_from([s for s in SYSTEMS if s.controllable]), log_scale,
       st.lists(log_scale, min_size=4, max_size=4))
def test_ccf_transform_of_si_systems_in_random_units(sys, log_a, log_d):
    # no AccuracyWarning (pytest makes it an error), and T B = e_n row by row. Measured in the
    # SI coordinates the system was given in: with x = D x_si and time scaled by a, row T_i acts
    # on x_si as u_i = T_i D, and T_i B = a u_i B_si, so the miss relative to a ||u_i|| ||B_si||
    # is the same number in any units. The transform is computed in unit-free coordinates, so
    # the miss is rounding amplified by the conditioning of the CCF: the largest seen over 2700
    # random unit changes of these systems was 1.1e-12 (aircraft pitch); 1e-10 leaves a margin
    # of 100 and still catches a transform that is wrong in its tenth digit
    n = sys.A.shape[0]
    a, d = 10.0**log_a, 10 ** np.array(log_d[:n])
    A, B, _ = _rescale(sys.A, sys.B, sys.C, a, d)
    T = ck.ccf_transform(A, B)
    scale = a * np.linalg.norm(T * d[None, :], axis=1) * np.linalg.norm(sys.B)
    miss = np.abs(T @ B[:, 0] - np.eye(n)[-1]) / scale
    assert miss.max() < 1e-10
