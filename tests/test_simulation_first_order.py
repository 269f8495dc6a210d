"""The first-order recursion behind simulate's exact LTI path: LAPACK route equals lfilter."""

import io
import subprocess
import sys

import numpy as np
import pytest
from scipy.signal import lfilter

import coursekit as ck
from coursekit.simulation import _first_order_lapack


@pytest.mark.parametrize("a", [0.3, -0.97, 1.0, 1.02, -1.5, 0.9 + 0.3j, 0.5 - 0.8j, 1.01 * np.exp(0.3j)])
@pytest.mark.parametrize("N", [2, 401, 5001])
def test_lapack_recursion_equals_lfilter(a, N):
    rng = np.random.default_rng(N)
    v = rng.normal(size=N) + (1j * rng.normal(size=N) if isinstance(a, complex) else 0.0)
    expected = lfilter([1.0], [1.0, -a], v)
    got = _first_order_lapack(a, v)
    assert got.dtype == expected.dtype
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=0)
    assert got[0] == v[0]                      # y(0) = v(0) exactly


def test_real_coefficient_on_complex_input_gives_complex_output():
    v = np.array([1.0 + 1.0j, 2.0, -1.0j])
    np.testing.assert_allclose(_first_order_lapack(0.5, v), lfilter([1.0], [1.0, -0.5], v), rtol=1e-15)


def test_simulate_without_scipy_signal_matches_with_it():
    # a fresh interpreter where nothing imports scipy.signal takes the LAPACK route
    code = (
        "import sys, numpy as np, coursekit as ck\n"
        "A = np.array([[0, 1, 0], [-2, -0.3, 1], [0, 0, -1.0]]); B = np.array([[0], [1], [1.0]])\n"
        "t = np.linspace(0, 10, 1001); u = np.sin(t)[:, None]\n"
        "x = ck.simulate(ck.StateSpace(A, B), t, u=u, x0=[1, 0, 0.5]).x\n"
        "assert 'scipy.signal' not in sys.modules\n"
        "np.save(sys.stdout.buffer, x)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, check=True)
    x_lapack = np.load(io.BytesIO(out.stdout))
    A = np.array([[0, 1, 0], [-2, -0.3, 1], [0, 0, -1.0]])
    B = np.array([[0], [1], [1.0]])
    t = np.linspace(0, 10, 1001)
    x_lfilter = ck.simulate(ck.StateSpace(A, B), t, u=np.sin(t)[:, None], x0=[1, 0, 0.5]).x
    np.testing.assert_allclose(x_lapack, x_lfilter, rtol=1e-13, atol=1e-14)
