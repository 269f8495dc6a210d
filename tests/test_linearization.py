"""linearize (numerical) and the symbolic Jacobian (section 3.4.2)."""

import zlib

import numpy as np
import pytest
import sympy as sp
from hypothesis import example, given, settings, strategies as st

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
    # a complex equilibrium used to be substituted into A (a real system has real equilibria)
    with pytest.raises(ValueError, match="x_eq must contain real values"):
        ck.linearize_symbolic(f, [x1, x2], [u], [1j, 0], [0])
    with pytest.raises(ValueError, match="u_eq must contain real values"):
        ck.linearize_symbolic(f, [x1, x2], [u], [0, 0], [sp.I])
    with pytest.raises(ValueError, match="f must be a list of sympy expressions: received the text"):
        ck.linearize_symbolic("x2", [x1, x2], x_eq=[0, 0])


def test_linearize_checks_tol():
    # tol = NaN made every equilibrium check fail with a misleading "not an equilibrium"
    for tol in (np.nan, -1.0, "1e-8"):
        with pytest.raises(ValueError, match=r"\btol\b"):
            ck.linearize(lambda x, u: -x, [0.0], tol=tol)


@example(n=4, q=1, seed=1704)
@given(n=st.integers(1, 5), q=st.integers(1, 3), seed=st.integers(0, 10_000))
def test_batched_central_differences_are_the_column_by_column_ones(n, q, seed):
    # the EKF evaluates g once on the batch of perturbed_states(z); difference_quotients must then give the
    # numbers numerical_jacobian(refine=False) gets from 2n separate calls, and the last column is z
    from coursekit._derivatives import difference_quotients, numerical_jacobian, perturbed_states
    rng = np.random.default_rng(seed)
    z = rng.normal(size=n) * 10 ** rng.uniform(-2, 1.5, size=n)
    a, i, j = rng.normal(size=q), rng.integers(0, n, size=q), rng.integers(0, n, size=q)

    def g(x):  # polynomial rows: the same arithmetic on one state (n,) or on columns (n, k)
        return np.array([a[r] * x[i[r]] * x[j[r]] + x[j[r]] ** 3 - 2 * x[i[r]] for r in range(q)])

    Z, h = perturbed_states(z)
    assert Z.shape == (n, 2 * n + 1)
    np.testing.assert_array_equal(Z[:, -1], z)
    for k in range(n):
        plus, minus = z.copy(), z.copy()
        plus[k], minus[k] = z[k] + h[k], z[k] - h[k]
        np.testing.assert_array_equal(Z[:, k], plus)
        np.testing.assert_array_equal(Z[:, n + k], minus)
    G = g(Z)
    J = difference_quotients(G, h)
    # g on a batch may round differently from g on one state (numpy picks other loops for
    # 2-D arrays): each value may differ by a few ulps of its largest term (which may exceed the
    # value itself: seed 1704 cancels), and the quotient divides that by 2 h_k
    terms = np.array([np.abs(a[r] * Z[i[r]] * Z[j[r]]) + np.abs(Z[j[r]]) ** 3 + 2 * np.abs(Z[i[r]])
                      for r in range(q)])
    ulps = 8 * np.finfo(float).eps * terms.max(axis=1, keepdims=True)
    np.testing.assert_array_less(np.abs(J - numerical_jacobian(g, z, refine=False)), ulps / h + 1e-300)
    exact = np.zeros((q, n))
    for r in range(q):
        exact[r, i[r]] += a[r] * z[j[r]] - 2
        exact[r, j[r]] += a[r] * z[i[r]] + 3 * z[j[r]] ** 2
    np.testing.assert_allclose(J, exact, rtol=1e-6, atol=1e-8 * max(1.0, np.abs(exact).max()))


# ---- accuracy far from the origin, checks and wrapped errors (issue 14) ---------------------

@pytest.mark.parametrize("turns", [0, 100, 1000])
def test_pendulum_after_many_turns_matches_the_closed_form(turns):
    # issue 14: with a step growing with |x_eq| the pendulum at 100 turns got A off by 3e-4 and
    # at 1000 turns completely wrong; (3.67) at theta* = 2 pi turns + pi/4 with u* = m g l sin(theta*)
    m, l, d = 1.3, 0.7, 0.2
    P = ck.models.pendulum(m=m, l=l, g=G, d_theta=d)
    theta = 2 * np.pi * turns + np.pi / 4
    A, B = ck.linearize(P, [theta, 0.0], [m * G * l * np.sin(theta)])
    A_true = [[0, 1], [-G / l * np.cos(theta), -d / m]]
    # documented: ~1e-10 relative to each column, wherever x* lies; 1e-9 leaves a margin of 10
    np.testing.assert_allclose(A, A_true, rtol=1e-9, atol=1e-9 * G / l)
    np.testing.assert_allclose(B, [[0], [1 / (m * l**2)]], rtol=1e-9)


ALIASED = 2 * np.pi * 2400 / 0.25


@pytest.mark.parametrize("fun, dfun, x", [
    (np.sin, np.cos, 2 * np.pi * 1000),                # curvature scale 1 at a large argument
    (np.exp, np.exp, 100.0),                           # exponential of a large argument
    (lambda x: x**10, lambda x: 10 * x**9, 1e6),      # polynomial: a step relative to |x| is right
    (lambda x: np.exp(x / 1000), lambda x: np.exp(x / 1000) / 1000, 1e5),
    (lambda x: np.sin(1e4 * x), lambda x: 1e4 * np.cos(1e4 * x), 0.3),   # tiny curvature scale
    (np.log, lambda x: 1 / x, 1e-6),                   # the large steps leave the domain
    # a period (0.25 / 2400) that divides the largest steps of both ladders as they were (from
    # 0.25 and 0.15): those steps saw a flat line and agreed on the derivative 0, unwarned
    (lambda x: np.sin(ALIASED * x), lambda x: ALIASED * np.cos(ALIASED * x), 0.3),
])
def test_derivatives_of_functions_with_every_scale(fun, dfun, x):
    A, _ = ck.linearize(lambda z, u: fun(z), [x], check_equilibrium=False)
    # documented accuracy ~1e-10 relative; 1e-9 leaves a margin
    np.testing.assert_allclose(A, [[dfun(x)]], rtol=1e-9)


@settings(max_examples=30)
# seed 397 draws W = 0.60320 ~ 2 pi 24 / 250: in units of 1000 or 10000 the largest steps were
# near multiples of the sine's period, and linearize warned (1000) or returned A0 (10000)
@example(n=1, seed=397, time_unit=0.0, state_units=[3.0, 0.0, 0.0, 0.0], offset=0.0)
@example(n=1, seed=397, time_unit=0.0, state_units=[4.0, 0.0, 0.0, 0.0], offset=0.0)
@given(n=st.integers(1, 4), seed=st.integers(0, 10_000), time_unit=st.floats(-4, 4),
       state_units=st.lists(st.floats(-4, 4), min_size=4, max_size=4),
       offset=st.floats(0, 4))
def test_linearization_follows_changes_of_units_and_of_the_origin(n, seed, time_unit, state_units, offset):
    # in new units x = D x~, time t = a t~ and with the equilibrium moved to |x*| ~ 10^offset, the
    # Jacobian of f~(x~) = a D^-1 f(D x~) is a D^-1 A D: every column must follow
    rng = np.random.default_rng(seed)
    W, A0 = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    c = rng.normal(size=n) * 10**offset   # where the equilibrium lies in the original units

    def f(x, u):  # smooth, with curvature scale ~1 in the original units wherever x lies
        return A0 @ (x - c) + np.sin(W @ (x - c))

    a, D = 10.0**time_unit, 10.0 ** np.array(state_units[:n])
    A, _ = ck.linearize(f, c)
    A_new, _ = ck.linearize(lambda x, u: a * f(D * x, u) / D, c / D)
    A_true = A0 + W                                    # d/dx [A0 (x - c) + sin(W (x - c))] at x = c
    np.testing.assert_allclose(A, A_true, rtol=1e-9, atol=1e-9 * np.abs(A_true).max())
    expected = a * A_true * D[None, :] / D[:, None]
    # per column (the columns' sizes differ by up to 1e16 across units): 1e-8 of each column
    scale = np.abs(expected).max(axis=0)
    assert np.all(np.abs(A_new - expected) <= 1e-8 * scale[None, :])


def test_nan_at_the_equilibrium_is_rejected_naming_the_function():
    # issue 14: a NaN residual was accepted as an equilibrium (NaN > tol is False)
    def leaky(x, u):
        return np.array([np.nan * x[0], x[1]])

    with pytest.raises(ck.UserFunctionError, match=r"f \(leaky\) returned NaN or inf at x_eq"):
        ck.linearize(leaky, [0.0, 0.0])
    with pytest.raises(ck.UserFunctionError, match=r"returned NaN or inf at x_eq"):
        ck.linearize(ck.NonlinearSystem(leaky, n=2), [0.0, 0.0], check_equilibrium=False)


def test_a_jacobian_without_usable_steps_raises():
    # sqrt at 0: every left step is outside the domain, so no central difference exists
    with pytest.raises(ValueError, match=r"no derivative with respect to x1 .* column 1 of A"):
        ck.linearize(lambda x, u: np.sqrt(x), [0.0], check_equilibrium=False)


def test_exceptions_of_f_are_wrapped_with_the_function_name():
    def exploding_pendulum(x, u):
        raise ZeroDivisionError("boom")

    with pytest.raises(ck.UserFunctionError,
                       match=r"f \(exploding_pendulum\) raised ZeroDivisionError at x_eq = \[0.5, 0.0\]"):
        ck.linearize(exploding_pendulum, [0.5, 0.0], [0.0])
    with pytest.raises(ck.UserFunctionError, match=r"exploding_pendulum\) raised ZeroDivisionError"):
        ck.linearize(ck.NonlinearSystem(exploding_pendulum, n=2, m=1), [0.5, 0.0], [0.0])


def test_a_model_that_raises_outside_its_domain_is_still_linearized():
    import math
    # math.log raises for x <= 0: the ladder's large steps (x - 1/4) are skipped, not reported
    A, _ = ck.linearize(lambda x, u: [math.log(x[0])], [1e-3], check_equilibrium=False)
    np.testing.assert_allclose(A, [[1e3]], rtol=1e-9)


def test_a_jump_or_noise_in_f_gives_an_accuracy_warning():
    with pytest.warns(ck.AccuracyWarning, match=r"column 1 of A \(d f / d x1\) is uncertain"):
        ck.linearize(lambda x, u: np.sign(x), [0.0], check_equilibrium=False)

    def noisy(x, u):  # 1e-6 of noise on a smooth function, the same in every process
        rng = np.random.default_rng(zlib.crc32(x.tobytes()))
        return np.sin(x) + 1e-6 * rng.normal(size=1)

    with pytest.warns(ck.AccuracyWarning, match=r"error estimate .* exceeds 1e-07 of the column's size"):
        ck.linearize(noisy, [0.3], check_equilibrium=False)


def test_noise_never_passes_silently_as_an_accurate_derivative():
    # the contract: either the column is accurate to 1e-7 of its size, or linearize warns. With
    # 1e-6 of noise the tableau's own error estimate alone was fooled for about 2 % of the noise
    # draws (salts 4 and 9 below, errors up to 1e-4); the second ladder's disagreement catches them
    import warnings
    exact = np.cos(0.3)
    for salt in range(60):
        def noisy(x, u, salt=salt):
            rng = np.random.default_rng(zlib.crc32(x.tobytes()) + salt)
            return np.sin(x) + 1e-6 * rng.normal(size=1)

        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ck.AccuracyWarning)
            A, _ = ck.linearize(noisy, [0.3], check_equilibrium=False)
        warned = any(issubclass(w.category, ck.AccuracyWarning) for w in caught)
        assert warned or abs(A[0, 0] - exact) <= 1e-7 * exact, (salt, A[0, 0] - exact)


# --- affine maps are linearized exactly (issue 25) ------------------------------------

def test_the_affine_map_of_the_issue_is_exact():
    # issue 25: 16.799999237 (relative error 4.5e-8), with the equilibrium's offset inside f
    A, _ = ck.linearize(lambda x, u: np.array([(1.6 + x[0]) * 16.8 - 1.6 * 16.8]), [0.0])
    assert abs(A[0, 0] - 16.8) <= 4 * np.finfo(float).eps * 16.8


def test_lotka_volterra_is_exact_in_both_jacobians():
    # predator-prey in deviations from its equilibrium, harvest u* + du of the predators: f is
    # bilinear in x and linear in u (main 73dc894: df/du wrong in the 8th digit, 1.25e-8)
    a, b, c, d, u_eq = 1.9, 1.0, 1.7, 0.7, 0.2
    x_eq = np.array([(c + u_eq) / d, a / b])

    def f(dx, du):
        x, y, u = x_eq[0] + dx[0], x_eq[1] + dx[1], u_eq + du[0]
        return np.array([a * x - b * x * y, d * x * y - c * y - u * y])

    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        A, B = ck.linearize(f, [0.0, 0.0], [0.0], check_equilibrium=False)
    # recomputed by hand: df/dx = [[a - b y, -b x], [d y, d x - c - u]], df/du = [0, -y]
    A_true = np.array([[a - b * x_eq[1], -b * x_eq[0]], [d * x_eq[1], d * x_eq[0] - c - u_eq]])
    np.testing.assert_allclose(A, A_true, rtol=0, atol=8 * np.finfo(float).eps * np.abs(A_true).max())
    assert B[0, 0] == 0.0 and abs(B[1, 0] + x_eq[1]) <= 4 * np.finfo(float).eps * x_eq[1]


_SCALE = st.floats(-8, 8)


@settings(max_examples=200, deadline=None)
@given(n=st.integers(1, 4), m=st.integers(0, 3), seed=st.integers(0, 2**32 - 1),
       coefficients=_SCALE, x_scale=_SCALE, u_scale=_SCALE, shifted=st.booleans())
# found in CI and in a run of 4,000 draws: a column of B of 0.006 beside A x of 2,000 (the second:
# a column of A of 10^8 beside A x of 10^16), whose rounding the values of f hide; the straight
# line was missed, and the ladder's smaller steps magnified that rounding (error 1.5e-10, not 5e-15)
@example(n=1, m=2, seed=1260492, coefficients=0.0, x_scale=2.5, u_scale=0.0, shifted=False)
@example(n=2, m=1, seed=2994914840, coefficients=8.0, x_scale=6.689816032777536, u_scale=0.07229776694135381,
         shifted=False)
@example(n=2, m=3, seed=1517457015, coefficients=0.0, x_scale=1.0, u_scale=2.0, shifted=False)
def test_random_affine_maps_are_exact_at_every_scale(n, m, seed, coefficients, x_scale, u_scale, shifted):
    rng = np.random.default_rng(seed)
    # coefficients 10^-8..10^8, each column a further factor 1..100 apart, some entries zero
    A0 = rng.normal(size=(n, n)) * 10.0 ** coefficients * 10.0 ** rng.uniform(0, 2, size=n)
    B0 = rng.normal(size=(n, m)) * 10.0 ** coefficients * 10.0 ** rng.uniform(0, 2, size=m)
    A0[rng.random(size=(n, n)) < 0.2] = 0.0
    x_eq = rng.uniform(-1, 1, size=n) * 10.0 ** x_scale
    u_eq = rng.uniform(-1, 1, size=m) * 10.0 ** u_scale
    if shifted:  # written around the equilibrium, as a model in deviations would be
        def f(x, u):
            return A0 @ (x - x_eq) + B0 @ (u - u_eq)
    else:        # written with its own offset: A x + B u + c
        c = -(A0 @ x_eq + B0 @ u_eq)
        def f(x, u):
            return A0 @ x + B0 @ u + c
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # never an AccuracyWarning ("f not smooth") on a straight line
        A, B = ck.linearize(f, x_eq, u_eq if m else None, check_equilibrium=False)
    # to rounding: a few eps of each column, plus the rounding of the largest intermediate value
    # (|A0| |x_eq| + |B0| |u_eq|, or x - x_eq) seen through the steps of that column's variable,
    # about 1/8 of its size (found in CI: x of 5 beside u of 70, A's column off by 3e-12, within
    # the rounding of 3,900 over a step of x, not over one of u)
    eps = np.finfo(float).eps
    offset = float((np.abs(A0) @ np.abs(x_eq) + np.abs(B0) @ np.abs(u_eq)).max())
    for J, J0, point in ((A, A0, x_eq), (B, B0, u_eq)):
        tol = 16 * eps * np.abs(J0).max(axis=0, initial=0.0) + 64 * eps * offset / np.maximum(1.0, np.abs(point))
        assert np.all(np.abs(J - J0) <= tol[None, :]), (np.abs(J - J0).max(axis=0), tol)


def test_a_missing_u_eq_is_named_instead_of_the_students_index_error():
    def pend(x, u):
        return np.array([x[1], -9.81 * np.sin(x[0]) + u[0]])

    with pytest.raises(ValueError, match=r"^u_eq is missing: f \(pend\) raised IndexError(?s:.*)u_eq=\[0\.0\]"):
        ck.linearize(pend, [0.0, 0.0])
    with pytest.raises(ValueError, match=r"^u_eq is missing: .*find_equilibria"):
        ck.find_equilibria(pend, n=2)


@pytest.mark.parametrize("flag", ["no", None, 0, 1, "False"])
def test_check_equilibrium_must_be_a_real_bool(flag):
    with pytest.raises(ValueError, match=r"check_equilibrium must be True or False"):
        ck.linearize(lambda x, u: -x, [1.0], check_equilibrium=flag)


@pytest.mark.parametrize("call, name", [
    (lambda x1, x2: ck.symbolic_jacobian([x2, -sp.sin(x1)], []), "variables is empty"),
    (lambda x1, x2: ck.symbolic_jacobian([x2, -sp.sin(x1)], ["x1", "x2"]), "variables must be a list"),
    (lambda x1, x2: ck.symbolic_jacobian([], [x1, x2]), "f is empty"),
    (lambda x1, x2: ck.linearize_symbolic([x2, -sp.sin(x1)], [], x_eq=[]), "x is empty"),
    (lambda x1, x2: ck.linearize_symbolic([x2, -sp.sin(x1)], "x1 x2", x_eq=[0, 0]), "x must be a list"),
])
def test_empty_or_text_symbol_lists_are_refused(call, name):
    # issue 25: an empty list gave an empty Jacobian without a word
    with pytest.raises(ValueError, match=rf"^{name}"):
        call(*sp.symbols("x1 x2"))
    # no input at all stays allowed
    x1, x2 = sp.symbols("x1 x2")
    A, B = ck.linearize_symbolic([x2, -sp.sin(x1)], [x1, x2], [], x_eq=[0, 0])
    assert B.shape == (2, 0)
