"""is_stable, plot_poles and format_poles (section 3.2)."""

import numpy as np
import pytest
from hypothesis import given, strategies as st

import coursekit as ck


@pytest.mark.parametrize("A, expected", [
    ([[-1]], True),                      # (3.1)
    ([[1]], False),                      # (3.4) without input
    ([[-1, 0], [1, -1]], True),          # (3.14): double eigenvalue -1
    ([[-1, -1], [1, -1]], True),         # (3.16): -1 +- i
    ([[0, 1], [0, 0]], False),           # double integrator: on the boundary
    ([[0, 1], [-1, 0]], False),          # undamped oscillator: +- i
    ([[2, 0, 0], [1, -1, 2], [0, 2, -1]], False),  # (3.22) open loop
])
def test_continuous_examples(A, expected):
    assert ck.is_stable(A) is expected


def test_discrete_uses_the_unit_circle():
    assert ck.is_stable([[0.5, 1], [0, -0.9]], dt=1)
    assert not ck.is_stable([[0, 1], [1, 0]], dt=1)          # (1.15): eigenvalues +-1
    assert ck.is_stable([[-0.5]]) and ck.is_stable([[-0.5]], dt=0.1)
    assert not ck.is_stable([[-1.5]], dt=0.1)
    sys = ck.StateSpace([[1.1]], dt=0.5)
    assert not ck.is_stable(sys)


@given(st.integers(1, 6), st.integers(0, 10_000))
def test_agrees_with_the_eigenvalues(n, seed):
    A = np.random.default_rng(seed).normal(size=(n, n))
    lam = np.linalg.eigvals(A)
    assert ck.is_stable(A) == bool(lam.real.max() < 0)
    # shifting A by more than its spectral abscissa always makes it stable
    assert ck.is_stable(A - (lam.real.max() + 0.1) * np.eye(n))


def test_bad_input():
    with pytest.raises(ValueError, match="A must be square"):
        ck.is_stable([[1, 2, 3], [4, 5, 6]])
    with pytest.raises(ValueError, match="dt must be positive"):
        ck.is_stable([[1]], dt=-1)


def test_plot_poles_shades_and_labels():
    fig, ax = ck.plot_poles({"open loop": [2, 3], "closed loop": [-1, -2]}, title="test")
    assert ax.get_title() == "test"
    assert "real" in ax.get_xlabel() and "imaginary" in ax.get_ylabel()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("stable region") and "closed loop" in labels
    lo, hi = ax.get_xlim()
    assert lo < -2 and hi > 3
    fig, ax = ck.plot_poles([0.5 + 0.5j, 0.5 - 0.5j], dt=1)
    assert "unit" not in ax.get_title() and "discrete" in ax.get_title()
    with pytest.raises(ValueError, match="NaN"):
        ck.plot_poles([np.nan])


@pytest.mark.parametrize("poles, text", [
    ([-1, -0.5 + 2j, -0.5 - 2j], "-1, -0.5 ± 2j"),
    ([-3, -1, -2], "-3, -2, -1"),
    ([1j], "0 + 1j"),
    ([-2 - 1j], "-2 - 1j"),
    (np.array([-1.23456]), "-1.23"),
    ([-17 + 2.38e-7j, -17 - 2.38e-7j], "-17 (double)"),      # a double pole as eig returns it
    ([-2.79999996, -2.80000004], "-2.8 (double)"),
    ([-1, -1, -1, -4], "-4, -1 (triple)"),
    ([-1 + 1e-3j, -1 - 1e-3j], "-1 ± 0.001j"),                # a slow oscillation, not noise
])
def test_format_poles_writes_a_conjugate_pair_once(poles, text):
    assert ck.format_poles(poles) == text
