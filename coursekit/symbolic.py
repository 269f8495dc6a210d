"""Symbolic versions of chapter 2's computations, with sympy.

* `symbolic_ctrb(A, B)`: Wc = [B, AB, ..., A^(n-1) B] (2.13) for matrices
  with symbols, e.g. `symbolic_mass_spring_damper()` in m, d, k (2.27);
* `symbolic_linear_flatness(A, B)`: F = T_1 x, psi_x and psi_u (2.74)-(2.87)
  in exact arithmetic;
* `symbolic_flat_maps(system)`: psi_x, psi_u of the pendulum, the
  two-wheeled robot and the car-like robot *derived* by sympy from the model
  equations, as in (2.90)-(2.102).

sympy is imported inside the functions, so ``import coursekit`` stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

__all__ = ["SymbolicFlatMaps", "symbolic_ctrb", "symbolic_mass_spring_damper", "symbolic_linear_flatness",
           "symbolic_flat_maps"]

_SYSTEMS = ("pendulum", "two_wheeled", "car_like")


def _check_real(expr, name: str) -> None:
    """Raise unless the sympy expression is real where it is a number (symbols may stay)."""
    import sympy as sp
    if expr.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise ValueError(f"{name} contains NaN or infinite entries: received {expr}; "
                         "expected finite numbers or symbols.")
    if expr.has(sp.I) or expr.is_number and expr.is_real is False:
        raise ValueError(f"{name} must be real: received the complex entry {expr}; "
                         "pass the real matrix (complex numbers are only accepted as poles).")


def _sym_matrix(value, name: str):
    import sympy as sp
    from ._validation import is_complex, is_text
    if value is None or is_text(value):
        raise ValueError(f"{name} must be a matrix (nested list or sympy Matrix): received {value!r}.")
    if is_complex(value):
        raise ValueError(f"{name} must be real: received complex entries; pass the real matrix "
                         "(complex numbers are only accepted as poles).")
    dims = _dimensions(value)
    if dims not in (1, 2):
        raise ValueError(f"{name} must be a matrix (nested list or sympy Matrix): received "
                         f"{type(value).__name__} with {dims} dimensions; write it as a list of rows, "
                         "e.g. [[0, 1], [-k / m, -d / m]] (a 1x1 matrix is [[a]]).")
    try:
        M = sp.Matrix(value)
    except (TypeError, ValueError, NotImplementedError, sp.SympifyError) as err:
        raise ValueError(f"{name} must be a matrix (nested list or sympy Matrix): received "
                         f"{type(value).__name__} ({err}).") from None
    for entry in M:
        _check_real(entry, name)
    return M


def _dimensions(value) -> int:
    """The number of dimensions of a nested list, array or sympy Matrix (a scalar has 0)."""
    import numpy as np
    try:
        return int(np.ndim(np.asarray(value, dtype=object)))
    except (TypeError, ValueError):
        return int(np.ndim(value))


def _sym_pair(A, B):
    from ._validation import require_columns
    A, B = _sym_matrix(A, "A"), _sym_matrix(B, "B")
    if not A.is_square or A.rows == 0:
        raise ValueError(f"A must be square: received shape {A.shape}, expected (n, n).")
    if B.rows != A.rows:
        raise ValueError(f"B has the wrong number of rows: received shape {B.shape}, "
                         f"expected {A.rows} rows (one per state, since A is {A.rows}x{A.rows}).")
    require_columns(B.shape, "B")
    return A, B


def symbolic_ctrb(A, B):
    """Controllability matrix Wc = [B, AB, ..., A^(n-1) B] (2.13) as a sympy Matrix."""
    import sympy as sp
    A, B = _sym_pair(A, B)
    blocks = [B]
    for _ in range(A.rows - 1):
        blocks.append(A * blocks[-1])
    return sp.Matrix.hstack(*blocks)


def symbolic_mass_spring_damper():
    """(A, B) of the mass-spring-damper (2.27) with positive symbols m, d, k."""
    import sympy as sp
    m, d, k = sp.symbols("m d k", positive=True)
    A = sp.Matrix([[0, 1], [-k / m, -d / m]])
    B = sp.Matrix([[0], [1 / m]])
    return A, B


@dataclass
class SymbolicFlatMaps:
    """psi_x and psi_u as sympy expressions of plain symbols for F and its derivatives.

    ``derivs[k][j]`` is the symbol for the k-th derivative of the j-th flat
    output; ``psi_x`` and ``psi_u`` are column Matrices in these symbols.
    ``functions()`` turns them into numerical functions with FlatSystem's
    calling convention (one time: ``derivs[k]`` has one entry per flat output).
    """

    name: str
    derivs: list
    psi_x: object
    psi_u: object

    def functions(self):
        """(psi_x, psi_u) as numerical functions of ``[F, F', ...]`` (numpy, via lambdify).

        Each takes `values`, one row per derivative order 0..r (``len(derivs)``) with
        one entry per flat output (for one flat output a flat list ``[F, F', ...]``);
        any other shape, NaN or text raises ValueError naming `values`.
        """
        import numpy as np
        import sympy as sp

        from ._validation import as_matrix
        flat = [s for row in self.derivs for s in row]
        orders, m = len(self.derivs), len(self.derivs[0])

        def numerical(psi, label: str):
            func = sp.lambdify(flat, psi, "numpy")
            free = sorted(map(str, psi.free_symbols - set(flat)))

            def call(values):
                rows = as_matrix(values, "values", rows=orders, cols=m, cols_why="one per flat output",
                                 rows_why=f"F and its derivatives up to order {orders - 1}")
                if free:
                    raise ValueError(
                        f"{label} still contains the parameters {', '.join(free)} as symbols: give them "
                        f"numbers, e.g. symbolic_flat_maps({self.name!r}, "
                        + ", ".join(f"{p}=1.0" for p in free) + ").functions().")
                return np.asarray(func(*rows.ravel()), dtype=float).ravel()
            return call

        return numerical(self.psi_x, "psi_x"), numerical(self.psi_u, "psi_u")


def _derivative_symbols(order: int, m: int):
    import sympy as sp
    if m == 1:
        return [[sp.Symbol(f"F_{k}")] for k in range(order + 1)]
    return [[sp.Symbol(f"F{j + 1}_{k}") for j in range(m)] for k in range(order + 1)]


def _to_symbols(expr, funcs, t, derivs):
    """Replace F_j(t) and its time derivatives by the plain symbols derivs[k][j]."""
    import sympy as sp
    for k in reversed(range(len(derivs))):
        for j, F in enumerate(funcs):
            expr = expr.subs(sp.diff(F, t, k) if k else F, derivs[k][j])
    return expr


def symbolic_linear_flatness(A, B) -> SymbolicFlatMaps:
    """F = T_1 x for a controllable single-input (A, B), in exact arithmetic (2.74)-(2.87).

    T_1 = e_n^T Wc^-1 (2.65), T_{i+1} = T_i A (2.61), x = T^-1 [F, ..., F^(n-1)]
    (2.78), u = a_0 F + ... + a_{n-1} F^(n-1) + F^(n) (2.79). Raises
    ValueError when Wc is singular. The result also carries ``T1`` and ``a``.
    """
    import sympy as sp
    A, B = _sym_pair(A, B)
    n = A.rows
    if B.cols != 1:
        raise ValueError(f"B must have a single column: received shape {B.shape}.")
    Wc = symbolic_ctrb(A, B)
    if sp.simplify(Wc.det()) == 0:
        raise ValueError("(A, B) is not controllable: det Wc = 0 (2.13), so no flat output "
                         "F = T_1 x exists (2.65); check B and A.")
    e_n = sp.zeros(1, n)
    e_n[n - 1] = 1
    # (2.65): T_1 = e_n^T Wc^-1
    rows = [sp.simplify(e_n * Wc.inv())]
    # (2.61): T_{i+1} = T_i A
    for _ in range(n - 1):
        rows.append(sp.simplify(rows[-1] * A))
    T = sp.Matrix.vstack(*rows)
    s = sp.Symbol("s")
    a = list(reversed(A.charpoly(s).all_coeffs()))[:-1]
    derivs = _derivative_symbols(n, 1)
    Z = sp.Matrix([derivs[k][0] for k in range(n)])
    # (2.78): x = Lambda z with Lambda = T^-1; (2.79): u = sum a_i F^(i) + F^(n)
    psi_x = sp.simplify(T.inv() * Z)
    psi_u = sp.Matrix([sp.expand(sum(a[i] * derivs[i][0] for i in range(n)) + derivs[n][0])])
    maps = SymbolicFlatMaps("linear system", derivs, psi_x, psi_u)
    maps.T1, maps.a = T[0, :], a
    return maps


def _pendulum():
    """(2.90)-(2.92): F = theta; x2 = F'; tau from the second state equation (with damping)."""
    import sympy as sp
    t, u = sp.symbols("t u")
    m, l, g = sp.symbols("m l g", positive=True)
    d = sp.Symbol("d_theta", nonnegative=True)
    F = sp.Function("F")(t)
    x1 = F
    # first equation x1' = x2 gives x2 = F'
    x2 = sp.diff(x1, t)
    # second equation (1.8): m l^2 x2' + d l^2 x2 + m g l sin x1 = u, solved for u
    # (linear in u: solve without its simplify pass, whose trigsimp is slow; factor gives the same form)
    u_expr = sp.factor(sp.solve(sp.Eq(m * l**2 * sp.diff(x2, t) + d * l**2 * x2 + m * g * l * sp.sin(x1), u),
                                u, simplify=False)[0])
    derivs = _derivative_symbols(2, 1)
    psi_x = sp.Matrix([_to_symbols(e, [F], t, derivs) for e in (x1, x2)])
    psi_u = sp.Matrix([_to_symbols(u_expr, [F], t, derivs)])
    return "pendulum", derivs, psi_x, psi_u


def _planar(car: bool):
    """(2.94)-(2.102) and the car-like exercise: F = (x1, x2), derived from the model."""
    import sympy as sp
    t = sp.Symbol("t")
    F1, F2 = sp.Function("F1")(t), sp.Function("F2")(t)
    v = sp.Symbol("v", positive=True)
    d1, d2 = sp.diff(F1, t), sp.diff(F2, t)
    # (2.98): squaring and adding the first two equations: v^2 = F1'^2 + F2'^2, forward root
    roots = sp.solve(sp.Eq(v**2, d1**2 + d2**2), v, simplify=False)
    speed = next(r for r in roots if not r.could_extract_minus_sign())
    # (2.96)-(2.97): dividing them: tan(theta) = F2'/F1'; atan2 picks the quadrant of (cos, sin)
    theta = sp.atan2(d2, d1)
    # (2.100)-(2.101): theta' by differentiation, over one common denominator
    theta_dot = sp.cancel(sp.diff(theta, t))
    derivs = _derivative_symbols(2, 2)
    funcs = [F1, F2]
    psi_x = sp.Matrix([_to_symbols(e, funcs, t, derivs) for e in (F1, F2, theta)])
    if car:
        L = sp.Symbol("L", positive=True)
        delta = sp.Symbol("delta")
        # (1.11): theta' = v tan(delta) / L, solved for delta (one simplify, for the signs)
        second = sp.simplify(sp.solve(sp.Eq(theta_dot, speed * sp.tan(delta) / L), delta, simplify=False)[0])
    else:
        # (2.94): theta' = u2
        second = theta_dot
    # speed (the root) and theta' (over one denominator) are already in their simplest form
    psi_u = sp.Matrix([_to_symbols(e, funcs, t, derivs) for e in (speed, second)])
    name = "car-like robot" if car else "two-wheeled robot"
    return name, derivs, psi_x, psi_u


def _sym_parameter(value, key: str, *, positive: bool = False):
    """A parameter value for `symbolic_flat_maps`: a real number or a sympy expression, > 0 when
    `positive` (a mass, a length: the symbol is declared positive, and the maps divide by it)."""
    import sympy as sp
    from ._validation import is_complex, is_text
    if value is None or is_text(value) or is_complex(value):
        raise ValueError(f"{key} must be a real number or a sympy expression: received {value!r}.")
    try:
        expr = sp.sympify(value)
    except (sp.SympifyError, TypeError) as err:
        raise ValueError(f"{key} must be a real number or a sympy expression: received "
                         f"{type(value).__name__} ({err}).") from None
    if not isinstance(expr, sp.Expr):
        raise ValueError(f"{key} must be a real number or a sympy expression: received {value!r}.")
    _check_real(expr, key)
    if positive and expr.is_number and not bool(expr > 0):
        raise ValueError(f"{key} must be positive: received {value!r}; it is a physical size (a mass, "
                         "a length, gravity) that the maps divide by or take as > 0.")
    return expr


@lru_cache(maxsize=None)
def _derivation(system: str):
    """The maps of `system`, derived once per session (sympy is slow); callers copy them."""
    if system == "pendulum":
        return _pendulum()
    return _planar(car=system == "car_like")


def symbolic_flat_maps(system: str, **params) -> SymbolicFlatMaps:
    """Derive psi_x and psi_u with sympy from the model equations.

    `system` is ``"pendulum"`` (2.90)-(2.92, with damping d_theta),
    ``"two_wheeled"`` (2.94)-(2.102) or ``"car_like"`` (the exercise; forward
    driving). Keyword `params` (e.g. ``m=1, l=0.5, g=9.81, d_theta=0`` or
    ``L=2.5``) are substituted for the symbols of the same name; the others stay symbolic.
    """
    import sympy as sp
    if not isinstance(system, str) or system not in _SYSTEMS:
        raise ValueError(f"system must be one of {_SYSTEMS}: received {system!r}.")
    name, derivs, psi_x, psi_u = _derivation(system)
    derivs = [list(row) for row in derivs]  # fresh containers: the cached ones stay untouched
    flat_symbols = {s for row in derivs for s in row}
    known = {s.name: s for s in (psi_x.free_symbols | psi_u.free_symbols) - flat_symbols}
    for key, value in params.items():
        if key not in known:
            raise ValueError(f"{key} is not a parameter of the {name}: expected one of {sorted(known)}.")
        value = _sym_parameter(value, key, positive=bool(known[key].is_positive))
        psi_x, psi_u = psi_x.subs(known[key], value), psi_u.subs(known[key], value)
    return SymbolicFlatMaps(name, derivs, sp.Matrix(psi_x), sp.Matrix(psi_u))
