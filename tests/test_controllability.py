"""ctrb, is_controllable, charpoly, ccf_transform and similarity_transform."""

import numpy as np
import pytest
from hypothesis import given, strategies as st

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
