"""Equilibria numerically and symbolically (section 3.4.1)."""

import numpy as np
import pytest
import sympy as sp

import coursekit as ck


def test_pendulum_without_torque_has_down_and_up_3_51():
    guesses = [[-0.5, 0], [0.5, 0.1], [2.5, 0], [3.5, -0.2]]
    X = ck.find_equilibria(ck.models.pendulum(), [0], guesses)
    np.testing.assert_allclose(X, [[0, 0], [np.pi, 0]], atol=1e-9)


def test_default_random_guesses_find_all_multiples_of_pi_in_the_box():
    X = ck.find_equilibria(ck.models.pendulum(), [0], bounds=(-4, 4), count=60)
    assert np.all(np.abs(X[:, 1]) < 1e-9)
    k = X[:, 0] / np.pi
    np.testing.assert_allclose(k, np.round(k), atol=1e-9)
    assert {-1, 0, 1} <= set(np.round(k).astype(int))


def test_constant_torque_moves_the_equilibrium_3_57():
    m, l, g = 2.0, 0.5, 9.81
    P = ck.models.pendulum(m=m, l=l, g=g)
    u = m * g * l * np.sin(np.pi / 4)
    X = ck.find_equilibria(P, [u], [[0.5, 0]])
    np.testing.assert_allclose(X, [[np.pi / 4, 0]], atol=1e-9)
    np.testing.assert_allclose(ck.equilibrium_input(P, [np.pi / 4, 0]), [u], rtol=1e-9)   # (3.59)


def test_bare_function_and_discrete_time():
    X = ck.find_equilibria(lambda x, u: x**2 - 4 + u, [0], n=1, bounds=(-5, 5))
    np.testing.assert_allclose(X, [[-2], [2]], atol=1e-9)
    # x(t+1) = x(t)^2 has fixed points 0 and 1 (3.53)
    X = ck.find_equilibria(lambda x, u: x**2, None, [[-0.2], [0.9], [1.3]], dt=1)
    np.testing.assert_allclose(X, [[0], [1]], atol=1e-6)


def test_linear_system_0_eq_Ax_plus_Bu_3_94():
    sys = ck.StateSpace([[0, 1], [-2, -3]], [[0], [1]])
    X = ck.find_equilibria(sys, [4.0], [[0, 0], [5, 5]])
    np.testing.assert_allclose(X, [[2, 0]], atol=1e-9)


def test_unreachable_equilibrium_and_bad_input():
    with pytest.raises(ValueError, match="not an equilibrium for any constant input"):
        ck.equilibrium_input(ck.models.pendulum(), [0.3, 1.0])
    with pytest.raises(ValueError, match="guesses has the wrong number of columns"):
        ck.find_equilibria(ck.models.pendulum(), [0], [[0, 0, 0]])
    with pytest.raises(ValueError, match="n is missing"):
        ck.find_equilibria(lambda x, u: x, None)
    with pytest.raises(ValueError, match="u_eq has the wrong length"):
        ck.find_equilibria(ck.models.pendulum(), [0, 1], [[0, 0]])


def test_symbolic_pendulum_3_52_and_3_59():
    x1, x2, u = sp.symbols("x1 x2 u", real=True)
    g, l, m = sp.symbols("g l m", positive=True)
    sols = ck.symbolic_equilibria([x2, -g / l * sp.sin(x1)], [x1, x2])
    assert sols == [{x1: 0, x2: 0}, {x1: sp.pi, x2: 0}]
    sols = ck.symbolic_equilibria([x2, -g / l * sp.sin(x1) + u / (m * l**2)], [x2, u])
    assert sols == [{x2: 0, u: g * l * m * sp.sin(x1)}]
    assert ck.symbolic_equilibria([x1**2], [x1], discrete=True) == [{x1: 0}, {x1: 1}]
    with pytest.raises(ValueError, match="unknowns must be a non-empty list"):
        ck.symbolic_equilibria([x1], [])


def test_exceptions_of_f_are_wrapped_with_the_function_name():
    # issue 14: find_equilibria and equilibrium_input let the user's exception through bare
    def broken_model(x, u):
        raise KeyError("mass")

    with pytest.raises(ck.UserFunctionError, match=r"f \(broken_model\) raised KeyError at x = "
                                                   r"\[0.5, 0.0\].*find_equilibria, searching from"):
        ck.find_equilibria(broken_model, [0.0], [[0.5, 0.0]])
    with pytest.raises(ck.UserFunctionError, match=r"broken_model\) raised KeyError .*equilibrium_input"):
        ck.equilibrium_input(ck.NonlinearSystem(broken_model, n=2, m=1), [0.5, 0.0])


def test_nan_residuals_never_make_an_equilibrium():
    def nan_torque(x, u):  # NaN whatever the input
        return np.array([x[1], np.nan * (1 + u[0])])

    # the old comparison `residual > tol` was False for NaN and accepted it
    with pytest.raises(ck.UserFunctionError, match=r"f \(nan_torque\) returned NaN or inf at x = "
                                                   r"\[0.3, 0.0\], u = \[0.0\]"):
        ck.equilibrium_input(nan_torque, [0.3, 0.0], m=1)
    # NaN at every starting point leaves nothing to search from: an error, not an empty result
    with pytest.raises(ck.UserFunctionError, match=r"f \(nan_torque\) returned NaN or inf at every "
                                                   r"one of the 2 starting points"):
        ck.find_equilibria(nan_torque, [0.0], [[0.3, 0.0], [1.0, 0.0]])

    def nan_at_root(x, u):  # finite at the guess, NaN where the solver lands (x = 1)
        return np.where(np.abs(x - 1.0) < 0.1, np.nan, x - 1.0)

    assert ck.find_equilibria(nan_at_root, None, [[3.0]]).shape == (0, 1)


def test_bare_function_sizes_are_checked_before_solving():
    # n is read off the guesses' columns: a mismatch with f names both
    with pytest.raises(ValueError, match=r"returned 1 numbers .* expected 2.*guesses has one column"):
        ck.find_equilibria(lambda x, u: x[:1], None, [[0.5, 0.0]])
    with pytest.raises(ValueError, match=r"returned 3 numbers at x_eq = \[0.0, 0.0\]; expected 2"):
        ck.equilibrium_input(lambda x, u: np.zeros(3), [0.0, 0.0], m=1)
    # without m, the length of u_guess gives the number of inputs: u* = 9.81 sin(0.3) holds 0.3 rad
    u = ck.equilibrium_input(lambda x, u: np.array([x[1], -9.81 * np.sin(x[0]) + u[0]]),
                             [0.3, 0.0], u_guess=[1.0])
    np.testing.assert_allclose(u, [9.81 * np.sin(0.3)], rtol=1e-12)  # f is linear in u: the solver lands to rounding


def test_a_model_undefined_at_some_guesses_still_finds_the_others():
    # sqrt is NaN for x < 0: the guess -2 fails quietly, the guess 3 finds x* = 4 (sqrt(x) = 2)
    X = ck.find_equilibria(lambda x, u: np.sqrt(x) - 2.0, None, [[-2.0], [3.0]])
    np.testing.assert_allclose(X, [[4.0]], atol=1e-9)


@pytest.mark.parametrize("f, discrete, equation", [
    (lambda x: -x + 10 * sp.sin(x), False, r"f = 0 \(3\.52\)"),
    (lambda x: -x - sp.sin(x), True, r"x = f\(x\) \(3\.53\)"),
])
def test_an_equation_without_closed_form_points_to_find_equilibria(f, discrete, equation):
    # issue 35: sympy's NotImplementedError reached the student; the solutions exist (x = 0 and
    # about +-2.85 for the first) but only numerically
    x = sp.Symbol("x", real=True)
    with pytest.raises(ValueError, match=rf"^f: sympy finds no closed-form solution of {equation} for \[x\]"
                                         r"(?s:.*)find_equilibria\(f, n=\.\.\.\)"):
        ck.symbolic_equilibria([f(x)], [x], discrete=discrete)
