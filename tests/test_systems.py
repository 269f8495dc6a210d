"""StateSpace and NonlinearSystem: defaults, shapes and validation messages."""

import numpy as np
import pytest

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
    assert sys.output_size(np.zeros(2), np.zeros(0)) == 1
    assert "a=1" in repr(sys)


def test_as_series_makes_a_one_dimensional_signal_a_column():
    from coursekit._validation import as_series
    assert as_series([1.0, 2.0, 3.0], "u", samples=3).shape == (3, 1)
    with pytest.raises(ValueError, match=r"u has the wrong number of rows: received shape \(2, 1\), expected 3"):
        as_series([1.0, 2.0], "u", samples=3)
    with pytest.raises(ValueError, match=r"u has the wrong number of columns: received shape \(3, 1\), expected 2"):
        as_series([1.0, 2.0, 3.0], "u", samples=3, channels=2)
