"""StateSpace and NonlinearSystem: defaults, shapes and validation messages."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck


def test_defaults_no_input_identity_output():
    sys = ck.StateSpace([[0, 1], [-1, 0]])
    assert (sys.n, sys.m, sys.p) == (2, 0, 2)
    np.testing.assert_array_equal(sys.C, np.eye(2))
    assert sys.D.shape == (2, 0) and not sys.is_discrete


def test_one_dimensional_b_and_c_become_column_and_row():
    sys = ck.StateSpace([[0, 1], [-2, -3]], [0, 1], [1, 0], dt=0.1)
    assert sys.B.shape == (2, 1) and sys.C.shape == (1, 2) and sys.D.shape == (1, 1)
    assert sys.is_discrete and sys.dt == 0.1


@pytest.mark.parametrize("args, message", [
    (dict(A=[[1, 2, 3], [4, 5, 6]]), r"A must be square: received shape \(2, 3\)"),
    (dict(A=[[0, 1], [0, np.nan]]), r"A contains NaN or infinite entries"),
    (dict(A=np.eye(2), B=np.ones((3, 1))), r"B has the wrong number of rows: received shape \(3, 1\), expected 2 rows \(one per state, since A is 2x2\)"),
    (dict(A=np.eye(2), B=np.ones((2, 1)), C=np.ones((1, 3))), r"C has the wrong number of columns"),
    (dict(A=np.eye(2), B=np.ones((2, 1)), C=np.ones((1, 2)), D=np.ones((2, 1))), r"D has the wrong number of rows"),
    (dict(A=np.eye(2), dt=0), r"dt must be positive"),
    (dict(A="abc"), r"A must contain real numbers"),
])
def test_bad_matrices_are_named(args, message):
    with pytest.raises(ValueError, match=message):
        ck.StateSpace(**args)


def test_repr_shows_matrices():
    text = repr(ck.StateSpace([[0, 1], [-2, -3]], [[0], [1]], name="msd"))
    assert "StateSpace 'msd': n=2, m=1, p=2 (continuous)" in text and "A = [[ 0.  1.]" in text


def test_nonlinear_system_checks_its_arguments():
    with pytest.raises(ValueError, match=r"f must be a function"):
        ck.NonlinearSystem(3, n=2)
    with pytest.raises(ValueError, match=r"n must be positive"):
        ck.NonlinearSystem(lambda x, u: x, n=0)
    sys = ck.NonlinearSystem(lambda x, u: -x, n=2, h=lambda x, u: x[0], params={"a": 1.0})
    assert sys.h(np.zeros(2), np.zeros(0)).size == 1
    assert "a=1" in repr(sys)


def test_as_series_makes_a_one_dimensional_signal_a_column():
    from coursekit._validation import as_series
    assert as_series([1.0, 2.0, 3.0], "u", samples=3).shape == (3, 1)
    with pytest.raises(ValueError, match=r"u has the wrong number of rows: received shape \(2, 1\), expected 3"):
        as_series([1.0, 2.0], "u", samples=3)
    with pytest.raises(ValueError, match=r"u has the wrong number of columns: received shape \(3, 1\), expected 2"):
        as_series([1.0, 2.0, 3.0], "u", samples=3, channels=2)


# ---------------------------------------------------------------- shapes of x and u in f and h

PLANT = ck.StateSpace([[0, 1], [-2, -0.5]], [[0], [1]], [[1, 0]], [[0.5]])
PEND = ck.models.pendulum()


@pytest.mark.parametrize("sys", [PLANT, PEND], ids=["StateSpace", "NonlinearSystem"])
@pytest.mark.parametrize("method", ["f", "h"])
def test_a_column_state_with_a_flat_input_is_refused_not_broadcast(sys, method):
    # x (2, 1) against u (1,) used to give an (2, 2) answer from A @ x + B @ u
    with pytest.raises(ValueError, match=r"u has shape \(1,\): expected \(1, 1\) for x of shape \(2, 1\)"):
        getattr(sys, method)(np.ones((2, 1)), np.ones(1))


@pytest.mark.parametrize("sys", [PLANT, PEND], ids=["StateSpace", "NonlinearSystem"])
@pytest.mark.parametrize("x, u, message", [
    (np.ones(3), [0.0], r"x has shape \(3,\): expected \(2,\), one entry per state, or \(2, k\)"),
    (np.ones((1, 2)), [0.0], r"x has shape \(1, 2\)"),
    (np.ones(()), [0.0], r"x has shape \(\)"),
    (np.ones(2), [0.0, 1.0], r"u has shape \(2,\): expected \(1,\)"),
    (np.ones((2, 3)), np.ones((1, 2)), r"u has shape \(1, 2\): expected \(1, 3\)"),
    (np.ones(2) * 1j, [0.0], r"x must contain real numbers"),
    (["a", "b"], [0.0], r"x must be an array of real numbers"),
])
def test_f_and_h_name_the_misshaped_argument(sys, x, u, message):
    for method in (sys.f, sys.h):
        with pytest.raises(ValueError, match=message):
            method(x, u)


@settings(max_examples=25)
@given(st.integers(1, 4), st.integers(0, 3), st.integers(1, 5), st.integers(0, 10_000))
def test_statespace_f_and_h_on_a_batch_are_the_column_by_column_answers(n, m, k, seed):
    rng = np.random.default_rng(seed)
    sys = ck.StateSpace(rng.normal(size=(n, n)), rng.normal(size=(n, m)), rng.normal(size=(2, n)),
                        rng.normal(size=(2, m)))
    X, U = rng.normal(size=(n, k)), rng.normal(size=(m, k))
    for method in (sys.f, sys.h):
        batch = method(X, U)
        single = np.column_stack([method(X[:, j], U[:, j]) for j in range(k)])
        # the same sums of products in another grouping: equal to rounding
        np.testing.assert_allclose(batch, single, rtol=1e-12, atol=1e-12)
        # a grid of states (n, k, 2), as the explorers pass them: still column by column
        grid = method(np.stack([X, 2 * X], axis=-1), np.stack([U, 2 * U], axis=-1))
        np.testing.assert_allclose(grid[..., 1], 2 * batch, rtol=1e-12, atol=1e-12)


def test_no_input_may_be_none_or_empty():
    sys = ck.StateSpace([[0, 1], [-1, 0]])
    for u in (None, [], np.zeros(0)):
        np.testing.assert_array_equal(sys.f([1.0, 2.0], u), [2.0, -1.0])
    assert sys.f(np.ones((2, 3)), None).shape == (2, 3)
    lorenz = ck.models.lorenz()
    np.testing.assert_allclose(lorenz.f([1.0, 2.0, 3.0], []), [10.0, -5.0, -1.0])   # (1.9) by hand


def test_check_names_where_f_or_h_fail():
    sys = ck.NonlinearSystem(lambda x, u: -np.sqrt(x), n=1, h=lambda x, u: 1 / float(x[0]))
    with np.errstate(invalid="ignore"):
        with pytest.raises(ck.UserFunctionError, match=r"f returned NaN or inf at x0"):
            sys.check(np.array([-1.0]), np.zeros(0), where="at x0")
    with pytest.raises(ck.UserFunctionError, match=r"h raised ZeroDivisionError at x0"):
        sys.check(np.array([0.0]), np.zeros(0), where="at x0")


@pytest.mark.parametrize("sys", [PLANT, PEND], ids=["StateSpace", "NonlinearSystem"])
@pytest.mark.parametrize("x, u, message", [
    ([np.nan, 0.0], [0.0], r"x contains NaN or inf"),
    ([0.0, np.inf], [0.0], r"x contains NaN or inf"),
    ([0.0, 0.0], [np.nan], r"u contains NaN or inf"),
    ([0.0, 0.0], None, r"u is None: expected an array of real numbers"),
])
def test_f_and_h_refuse_nan_states_and_a_missing_input(sys, x, u, message):
    # NaN used to pass through A x + B u, and u = None became NaN
    for method in (sys.f, sys.h):
        with pytest.raises(ValueError, match=message):
            method(x, u)


def _raises(x, u):
    raise ZeroDivisionError("student's bug")


@pytest.mark.parametrize("bad, message", [
    (_raises, r"raised ZeroDivisionError at x = \[1\. 2\.\], u = \[0\.5\].*student's bug"),
    (lambda x, u: None, r"returned None at x = \[1\. 2\.\], u = \[0\.5\]"),
    (lambda x, u: x + 1j, r"returned complex numbers at x = \[1\. 2\.\]"),
    (lambda x, u: x / 0.0, r"returned NaN or inf at x = \[1\. 2\.\]"),
    (lambda x, u: ["a", "b"], r"returned list.*not an array of real numbers"),
])
def test_f_and_h_name_the_user_function_that_fails_and_the_point(bad, message):
    good = lambda x, u: np.array([x[1], u[0]])                                   # noqa: E731
    x, u = np.array([1.0, 2.0]), np.array([0.5])
    with np.errstate(divide="ignore"):
        with pytest.raises(ck.UserFunctionError, match="f " + message):
            ck.NonlinearSystem(bad, n=2, m=1, h=good).f(x, u)
        with pytest.raises(ck.UserFunctionError, match="h " + message):
            ck.NonlinearSystem(good, n=2, m=1, h=bad).h(x, u)


def test_nonlinear_f_and_h_keep_batches_and_plain_lists():
    # a batch (n, k, 5) as the chapter 2 explorer passes it: rows in, rows out, unchanged
    sys = ck.NonlinearSystem(lambda x, u: [x[1], -x[0] + u[0]], n=2, m=1, h=lambda x, u: x[0] * 2)
    X = np.arange(30.0).reshape(2, 3, 5)
    U = np.ones((1, 3, 5))
    np.testing.assert_array_equal(sys.f(X, U), np.stack([X[1], -X[0] + 1.0]))   # exact: one operation
    np.testing.assert_array_equal(sys.h(X, U), 2 * X[0])
    assert sys.f([1.0, 2.0], [0.0]).dtype == float
    with np.errstate(all="ignore"), pytest.raises(
            ck.UserFunctionError, match=r"f returned NaN or inf on the batch of states x of shape \(2, 3, 5\)"):
        ck.NonlinearSystem(lambda x, u: x / 0.0, n=2, m=1).f(X, U)


@pytest.mark.parametrize("args, message", [
    (([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], [[1.0], [1.0]], 0.1), r"A must be square"),
    ((np.eye(2), np.ones((3, 1)), 0.1), r"B has the wrong number of rows: received shape \(3, 1\), expected 2"),
    ((np.eye(2), np.ones((2, 1)), 0.0), r"h must be positive"),
    ((np.eye(2), np.ones((2, 1)), -0.1), r"h must be positive"),
    ((np.eye(2), np.ones((2, 1)), np.nan), r"h contains NaN"),
    ((np.eye(2), np.ones((2, 1)), np.inf), r"h contains NaN or infinite"),
    ((np.eye(2), np.ones((2, 1)), [0.1, 0.2]), r"h must be a single number"),
    (([[np.nan, 0], [0, 1]], np.ones((2, 1)), 0.1), r"A contains NaN"),
])
def test_lti_step_matrices_validates_its_arguments(args, message):
    with pytest.raises(ValueError, match=message):
        ck.lti_step_matrices(*args)


def test_lti_step_matrices_accept_a_flat_b_and_match_the_exponential():
    from scipy.linalg import expm
    A = np.array([[0.0, 1.0], [-2.0, -0.5]])
    Ad, B0, B1 = ck.lti_step_matrices(A, [0.0, 1.0], 0.1)
    np.testing.assert_allclose(Ad, expm(0.1 * A), rtol=1e-14, atol=1e-15)   # the same expm, sliced
    # a constant input: B0 + B1 is the zero-order-hold integral A^-1 (e^(A h) - I) B
    np.testing.assert_allclose(B0 + B1, np.linalg.solve(A, expm(0.1 * A) - np.eye(2)) @ [[0.0], [1.0]],
                               rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("sys", [PLANT, PEND, ck.NonlinearSystem(lambda x, u: -x, n=2, m=1)],
                         ids=["StateSpace", "NonlinearSystem", "default h"])
def test_raw_field_and_output_are_f_and_h_without_the_wrapping(sys):
    x, u = np.array([0.3, -0.2]), np.array([0.5])
    # the same operations on the same numbers: equal to rounding; no h given means y = x
    h = sys.raw_output() or (lambda x, u: x)
    np.testing.assert_allclose(sys.raw_field()(x, u), sys.f(x, u), rtol=1e-15, atol=0)
    np.testing.assert_allclose(np.ravel(h(x, u)), sys.h(x, u), rtol=1e-15, atol=0)


def test_raw_field_lets_the_users_own_exception_through():
    with pytest.raises(ZeroDivisionError):
        ck.NonlinearSystem(_raises, n=2, m=1).raw_field()(np.zeros(2), np.zeros(1))
