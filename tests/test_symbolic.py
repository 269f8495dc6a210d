"""sympy derivations against the numerical functions."""

import numpy as np
import pytest
import sympy as sp

import coursekit as ck


def test_mass_spring_damper_ctrb_and_determinant():
    A, B = ck.symbolic_mass_spring_damper()
    W = ck.symbolic_ctrb(A, B)
    m, d, k = sp.symbols("m d k", positive=True)
    assert sp.simplify(W - sp.Matrix([[0, 1 / m], [1 / m, -d / m**2]])) == sp.zeros(2, 2)
    # det Wc = -1/m^2 != 0 for every mass: controllable for all m, d, k
    assert sp.simplify(W.det() + 1 / m**2) == 0
    # agrees with the numerical ctrb for one choice of the parameters
    values = {m: 2.0, d: 0.5, k: 3.0}
    sys = ck.models.mass_spring_damper(m=2.0, d=0.5, k=3.0)
    np.testing.assert_allclose(np.array(W.subs(values), dtype=float), ck.ctrb(sys.A, sys.B))


def test_symbolic_ctrb_of_2_14():
    W = ck.symbolic_ctrb([[-1, 1, 0], [1, -1, 1], [0, 1, -1]], [[0], [1], [0]])
    assert W == sp.Matrix([[0, 1, -2], [1, -1, 3], [0, 1, -2]])
    assert W.det() == 0


def test_symbolic_linear_flatness_of_2_80():
    maps = ck.symbolic_linear_flatness([[0, 2], [1, -3]], [[1], [0]])
    F0, F1, F2 = (row[0] for row in maps.derivs)
    assert maps.T1 == sp.Matrix([[0, 1]])
    assert sp.simplify(maps.psi_x - sp.Matrix([3 * F0 + F1, F0])) == sp.zeros(2, 1)
    assert sp.expand(maps.psi_u[0] - (-2 * F0 + 3 * F1 + F2)) == 0


def test_symbolic_flat_output_of_the_mass_spring_damper_is_m_y():
    A, B = ck.symbolic_mass_spring_damper()
    maps = ck.symbolic_linear_flatness(A, B)
    m, d, k = sp.symbols("m d k", positive=True)
    assert maps.T1 == sp.Matrix([[m, 0]])
    # numerically the same as linear_flatness for m = 2, d = 0.5, k = 3
    sys = ck.models.mass_spring_damper(m=2.0, d=0.5, k=3.0)
    flat = ck.linear_flatness(sys.A, sys.B)
    np.testing.assert_allclose(flat.T1, [2.0, 0.0])
    fx, fu = _maps_at(maps, {m: 2.0, d: 0.5, k: 3.0})
    probe = [0.3, -0.2, 1.1]
    np.testing.assert_allclose(fx(probe), flat.psi_x(probe))
    np.testing.assert_allclose(fu(probe), flat.psi_u(probe))


def _maps_at(maps, values):
    """The maps with parameter values substituted, as numerical functions."""
    fixed = ck.SymbolicFlatMaps(maps.name, maps.derivs, maps.psi_x.subs(values), maps.psi_u.subs(values))
    return fixed.functions()


@pytest.mark.parametrize("system, params, flat", [
    ("pendulum", dict(m=1.5, l=0.8, g=9.81, d_theta=0.3),
     lambda: ck.pendulum_flatness(m=1.5, l=0.8, g=9.81, d_theta=0.3)),
    ("two_wheeled", {}, ck.two_wheeled_flatness),
    ("car_like", dict(L=2.5), lambda: ck.car_like_flatness(2.5)),
])
def test_symbolic_maps_equal_the_numerical_ones(system, params, flat):
    maps = ck.symbolic_flat_maps(system, **params)
    fx, fu = maps.functions()
    numeric = flat()
    rng = np.random.default_rng(3)
    for _ in range(5):
        derivs = [rng.normal(size=numeric.m) for _ in range(3)]
        np.testing.assert_allclose(fx(derivs), numeric.psi_x(derivs), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(fu(derivs), numeric.psi_u(derivs), rtol=1e-12, atol=1e-12)


def test_derived_robot_maps_satisfy_the_model():
    maps = ck.symbolic_flat_maps("two_wheeled")
    (F1, F2), (dF1, dF2), _ = maps.derivs
    theta = maps.psi_x[2]
    u1 = maps.psi_u[0]
    # (2.94): x1' = u1 cos(theta), x2' = u1 sin(theta)
    assert sp.simplify(u1 * sp.cos(theta) - dF1) == 0
    assert sp.simplify(u1 * sp.sin(theta) - dF2) == 0


def test_symbolic_bad_input():
    with pytest.raises(ValueError, match=r"system must be one of"):
        ck.symbolic_flat_maps("bicycle")
    with pytest.raises(ValueError, match=r"mass is not a parameter of the pendulum"):
        ck.symbolic_flat_maps("pendulum", mass=1.0)
    with pytest.raises(ValueError, match=r"A must be square"):
        ck.symbolic_ctrb([[1, 2, 3]], [[1]])
    with pytest.raises(ValueError, match=r"B has the wrong number of rows"):
        ck.symbolic_ctrb([[1, 0], [0, 1]], [[1], [0], [0]])
    with pytest.raises(ValueError, match=r"not controllable: det Wc = 0"):
        ck.symbolic_linear_flatness([[-3, 0], [1, -2]], [[0], [1]])


@pytest.mark.parametrize("call", [
    lambda: ck.symbolic_ctrb(np.array(1.0), [[1.0]]),
    lambda: ck.symbolic_ctrb(np.zeros((2, 2, 2)), [[1.0], [0.0]]),
    lambda: ck.symbolic_ctrb([[0.0, 1.0], [0.0, 0.0]], np.zeros((2, 1, 1))),
    lambda: ck.symbolic_linear_flatness(np.float64(1.0), [[1.0]]),
    lambda: ck.symbolic_linear_flatness(np.zeros((2, 2, 2)), [[1.0], [0.0]]),
])
def test_arrays_that_are_not_matrices_are_named(call):
    # issue 25: sympy's NotImplementedError "SymPy supports just 1D and 2D matrices"
    with pytest.raises(ValueError, match=r"^[AB] must be a matrix .* with [03] dimensions"):
        call()


@pytest.mark.parametrize("values, message", [
    ([0.0], r"values has the wrong number of rows: received shape \(1, 1\), expected 3 rows"),
    ({"a": 1}, r"values must contain real numbers"),
    (None, r"values is missing"),
    ([np.nan, 0.0, 0.0], r"values contains NaN"),
])
def test_flat_map_functions_name_wrong_values(values, message):
    # issue 25: IndexError / KeyError / TypeError from inside the lambdified maps
    fx, fu = ck.symbolic_flat_maps("pendulum", m=1.0, l=1.0, g=9.81, d_theta=0.0).functions()
    for func in (fx, fu):
        with pytest.raises(ValueError, match=message):
            func(values)
    gx, _ = ck.symbolic_flat_maps("two_wheeled").functions()
    with pytest.raises(ValueError, match=r"values has the wrong number of columns: received shape \(3, 1\), "
                                         r"expected 2 columns \(one per flat output\)"):
        gx([[0.0], [0.0], [0.0]])


def test_flat_map_functions_with_symbolic_parameters_say_which():
    fx, fu = ck.symbolic_flat_maps("pendulum").functions()
    np.testing.assert_array_equal(fx([0.1, 0.2, 0.3]), [0.1, 0.2])     # psi_x has no parameter
    with pytest.raises(ValueError, match=r"psi_u still contains the parameters d_theta, g, l, m"):
        fu([0.1, 0.2, 0.3])
