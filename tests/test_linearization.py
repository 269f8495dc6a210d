"""linearize (numerical) and the symbolic Jacobian (section 3.4.2)."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, strategies as st

import coursekit as ck

G, L, M = 9.81, 0.7, 1.3


def test_pendulum_down_and_up_match_3_73_and_3_74():
    P = ck.models.pendulum(m=M, l=L, g=G)
    A, B = ck.linearize(P, [0, 0], [0])
    np.testing.assert_allclose(A, [[0, 1], [-G / L, 0]], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(B, [[0], [1 / (M * L**2)]], rtol=1e-9)
    A, _ = ck.linearize(P, [np.pi, 0], [0])
    np.testing.assert_allclose(A, [[0, 1], [G / L, 0]], rtol=1e-9, atol=1e-9)


def test_robot_elbow_at_pi_over_4_matches_3_87():
    P = ck.models.pendulum(m=M, l=L, g=G)
    u_eq = M * G * L * np.sin(np.pi / 4)           # (3.57)
    A, B = ck.linearize(P, [np.pi / 4, 0], [u_eq])
    np.testing.assert_allclose(A, [[0, 1], [-np.sqrt(2) * G / (2 * L), 0]], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(B, [[0], [1 / (M * L**2)]], rtol=1e-9)


@given(st.integers(1, 5), st.integers(1, 3), st.integers(0, 10_000))
def test_against_analytic_jacobian_of_a_random_smooth_field(n, m, seed):
    rng = np.random.default_rng(seed)
    A0, B0, W = rng.normal(size=(n, n)), rng.normal(size=(n, m)), rng.normal(size=(n, n))
    x, u = rng.normal(size=n), rng.normal(size=m)

    def f(x, u):  # f = A0 x + B0 tanh(u) + sin(W x) * x
        return A0 @ x + B0 @ np.tanh(u) + np.sin(W @ x) * x

    A_true = A0 + np.diag(np.sin(W @ x)) + (np.cos(W @ x) * x)[:, None] * W
    B_true = B0 * (1 - np.tanh(u) ** 2)[None, :]
    A, B = ck.linearize(f, x, u, check_equilibrium=False)
    np.testing.assert_allclose(A, A_true, rtol=1e-6, atol=1e-8 * np.abs(A_true).max())
    np.testing.assert_allclose(B, B_true, rtol=1e-6, atol=1e-8 * np.abs(B_true).max())


def test_linear_system_returns_its_own_matrices():
    sys = ck.StateSpace([[0, 1], [-2, -3]], [[0], [1]])
    A, B = ck.linearize(sys, [0, 0], [0])
    np.testing.assert_allclose(A, sys.A, atol=1e-12)
    np.testing.assert_allclose(B, sys.B, atol=1e-12)


def test_without_input_and_discrete_time():
    A, B = ck.linearize(ck.models.lorenz(), [0, 0, 0])
    np.testing.assert_allclose(A, [[-10, 10, 0], [0, -1, 0], [0, 0, -1]], atol=1e-9)
    assert B.shape == (3, 0)
    # discrete logistic map x+ = 3 x (1 - x): fixed point 2/3, slope 3 - 6x = -1
    A, _ = ck.linearize(lambda x, u: 3 * x * (1 - x), [2 / 3], dt=1)
    np.testing.assert_allclose(A, [[-1]], atol=1e-9)


def test_not_an_equilibrium_is_explained():
    with pytest.raises(ValueError, match=r"not an equilibrium.*equilibrium_input"):
        ck.linearize(ck.models.pendulum(), [np.pi / 4, 0], [0])
    with pytest.raises(ValueError, match="x_eq has the wrong length"):
        ck.linearize(ck.models.pendulum(), [0, 0, 0], [0])
    with pytest.raises(ValueError, match="f must be a NonlinearSystem or a function"):
        ck.linearize(42, [0], [0])


def test_symbolic_jacobian_3_69_and_3_83():
    x1, x2, u = sp.symbols("x1 x2 u", real=True)
    g, l, m = sp.symbols("g l m", positive=True)
    f = [x2, -g / l * sp.sin(x1) + u / (m * l**2)]
    J = ck.symbolic_jacobian(f, [x1, x2])
    assert sp.simplify(J - sp.Matrix([[0, 1], [-g / l * sp.cos(x1), 0]])) == sp.zeros(2, 2)
    A, B = ck.linearize_symbolic(f, [x1, x2], [u], [sp.pi / 2, 0], [m * g * l])
    assert A == sp.Matrix([[0, 1], [0, 0]])                      # (3.84)
    assert B == sp.Matrix([[0], [1 / (m * l**2)]])                # (3.85)
    A, _ = ck.linearize_symbolic(f, [x1, x2], [u], [sp.pi, 0], [0])
    assert A == sp.Matrix([[0, 1], [g / l, 0]])                   # (3.74)
    with pytest.raises(ValueError, match="variables must be sympy symbols"):
        ck.symbolic_jacobian(f, [1, 2])
    with pytest.raises(ValueError, match="x_eq has the wrong length"):
        ck.linearize_symbolic(f, [x1, x2], [u], [0], [0])


@given(st.integers(1, 5), st.integers(1, 3), st.integers(0, 10_000))
def test_batched_central_differences_are_the_column_by_column_ones(n, q, seed):
    # the EKF evaluates g once on the batch of _perturbed(z); _quotients must then give the
    # numbers _jacobian(refine=False) gets from 2n separate calls, and the last column is z
    from coursekit.linearization import _jacobian, _perturbed, _quotients
    rng = np.random.default_rng(seed)
    z = rng.normal(size=n) * 10 ** rng.uniform(-2, 1.5, size=n)
    a, i, j = rng.normal(size=q), rng.integers(0, n, size=q), rng.integers(0, n, size=q)

    def g(x):  # polynomial rows: the same arithmetic on one state (n,) or on columns (n, k)
        return np.array([a[r] * x[i[r]] * x[j[r]] + x[j[r]] ** 3 - 2 * x[i[r]] for r in range(q)])

    Z, h = _perturbed(z)
    assert Z.shape == (n, 2 * n + 1)
    np.testing.assert_array_equal(Z[:, -1], z)
    for k in range(n):
        plus, minus = z.copy(), z.copy()
        plus[k], minus[k] = z[k] + h[k], z[k] - h[k]
        np.testing.assert_array_equal(Z[:, k], plus)
        np.testing.assert_array_equal(Z[:, n + k], minus)
    G = g(Z)
    J = _quotients(G, h)
    # g on a batch may round differently from g on one state (numpy picks other loops for
    # 2-D arrays): each value may differ by a few ulps, which the quotient divides by 2 h_k
    ulps = 8 * np.finfo(float).eps * np.abs(G).max(axis=1, keepdims=True)
    np.testing.assert_array_less(np.abs(J - _jacobian(g, z, refine=False)), ulps / h + 1e-300)
    exact = np.zeros((q, n))
    for r in range(q):
        exact[r, i[r]] += a[r] * z[j[r]] - 2
        exact[r, j[r]] += a[r] * z[i[r]] + 3 * z[j[r]] ** 2
    np.testing.assert_allclose(J, exact, rtol=1e-6, atol=1e-8 * max(1.0, np.abs(exact).max()))
