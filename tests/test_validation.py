"""The shared input checks of coursekit._validation on the inputs that used to escape them."""

import pytest

from coursekit import _validation as v


@pytest.mark.parametrize("samples", [10**6 + 1, 10**12, 1e300, 10**400])
def test_time_grid_refuses_huge_samples_before_allocating(samples):
    # issue 25: MemoryError (10**12) or numpy's "Maximum allowed size exceeded" (1e300)
    with pytest.raises(ValueError, match=r"^samples must be|^samples must contain real numbers"):
        v.time_grid(1.0, samples)


def test_time_grid_refuses_a_span_beyond_a_million_and_names_the_argument():
    with pytest.raises(ValueError, match=r"^T is too large: a time span of 1e\+300 exceeds 1e\+06"):
        v.time_grid(1e300, 100, t_end_name="T")
    assert v.time_grid(1e300, 3, max_span=None)[-1] == 1e300     # a plan's horizon: no bound
    assert v.time_grid(1e6, 10**6).size == 10**6                 # both limits themselves pass


def test_huge_integers_are_a_value_error_naming_the_argument():
    # OverflowError: int too large to convert to float
    with pytest.raises(ValueError, match=r"^seed must contain real numbers"):
        v.as_integer(10**400, "seed")


@pytest.mark.parametrize("call", [
    lambda: __import__("coursekit").StateSpace([[-1.0]], [[1.0]], dt=0),
    lambda: __import__("coursekit").NonlinearSystem(lambda x, u: -x, n=1, dt=0.0),
    lambda: __import__("coursekit").is_stable([[-1.0]], dt=0),
    lambda: __import__("coursekit").kalman_gain([[-1.0]], [[1.0]], [[1.0]], [[1.0]], dt=0),
    lambda: __import__("coursekit").linearize(lambda x, u: -x, [0.0], dt=0),
])
def test_dt_zero_points_to_dt_none(call):
    # issue 25: dt=0 (python-control's continuous time) was refused without the way out
    with pytest.raises(ValueError, match=r"^dt must be positive: received 0\.0(?s:.*)pass dt=None"):
        call()


def test_poles_too_large_for_a_float_are_named():
    with pytest.raises(ValueError, match=r"^poles must be a list of numbers"):
        v.as_poles([10**400, -1.0], count=2)
