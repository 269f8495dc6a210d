"""Simulation of continuous- and discrete-time systems: `simulate`.

Three paths, chosen from the system and the input:

* continuous LTI with an array input (or none): exact. The input is taken as
  linear between samples (as `scipy.signal.lsim` and python-control do) and
  the solution formula (2.4) is evaluated over each step with one matrix
  exponential of an augmented matrix, so the result has no integration error
  and works for any `A`, diagonalizable or not. On a uniform grid the
  resulting recursion runs through a Schur form, one first-order recursion
  per eigenvalue (see `_recurse`), with no Python loop over samples;
* discrete-time systems (1.18), (1.27): the difference equation is iterated;
* everything else (nonlinear systems, inputs given as a function `u(t, x)`):
  `scipy.integrate.solve_ivp` with the DOP853 method and tight tolerances
  (rtol=1e-9, atol=1e-12 by default).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._validation import as_matrix, as_series, as_time_grid, as_vector, check_function_output, is_uniform
from .systems import NonlinearSystem, StateSpace

__all__ = ["simulate", "simulate_batch", "SimulationResult", "lti_step_matrices"]


@dataclass(repr=False)
class SimulationResult:
    """What `simulate` returns; every series is time-major.

    Attributes
    ----------
    t : (N,) array      -- the time grid
    x : (N, n) array    -- the state at each time
    y : (N, p) array    -- the output at each time
    u : (N, m) array    -- the input that was applied at each time
    system : StateSpace or NonlinearSystem -- the simulated system
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    system: object

    def __repr__(self) -> str:
        name = getattr(self.system, "name", "") or type(self.system).__name__
        return (f"SimulationResult of {name}: {self.t.size} samples from t={self.t[0]:g} "
                f"to t={self.t[-1]:g}; x {self.x.shape}, y {self.y.shape}, u {self.u.shape}")

    def plot(self, *, which: str = "xu", **kwargs):
        """Plot the response (see `coursekit.plotting.plot_response`); returns the figure."""
        from .plotting import plot_response
        return plot_response(self, which=which, **kwargs)


def simulate(sys, t, u=None, x0=None, *, rtol: float = 1e-9, atol: float = 1e-12,
             method: str = "DOP853") -> SimulationResult:
    """Simulate `sys` on the time grid `t`.

    Parameters
    ----------
    sys : StateSpace or NonlinearSystem
    t : (N,) array
        Strictly increasing times. For a discrete-time system the grid must
        step by ``sys.dt`` (e.g. ``np.arange(N) * dt``).
    u : None, (N, m) array or callable, optional
        None means zero input. An array gives the input at each time; in
        continuous time it is taken as linear between samples. A callable
        ``u(t, x)`` returns the m inputs at time t and state x: open-loop
        signals ignore x, state feedback ``u = K x`` uses it (3.17).
    x0 : (n,) array, optional
        Initial state (default zero).
    rtol, atol, method :
        Tolerances and method of `scipy.integrate.solve_ivp`, used for
        nonlinear systems and callable inputs only; the exact LTI path
        ignores them. Pick ``method="LSODA"`` or ``"Radau"`` for a stiff system.

    Returns
    -------
    SimulationResult with ``t, x, y, u`` (time-major) and ``.plot()``.
    """
    if not isinstance(sys, (StateSpace, NonlinearSystem)):
        raise ValueError(
            f"sys must be a StateSpace or NonlinearSystem: received {type(sys).__name__}; "
            "build one with StateSpace(A, B, C, D) or NonlinearSystem(f, n, m)."
        )
    t = as_time_grid(t, "t", min_points=1 if sys.is_discrete else 2)
    x0 = np.zeros(sys.n) if x0 is None else as_vector(
        x0, "x0", size=sys.n, why=f"one per state of the {sys.n}-state system")
    u_arr, u_fun = _input(sys, t, u, x0)
    if sys.is_discrete:
        _check_discrete_grid(t, sys.dt)
        x, u_arr = _iterate(sys, t, x0, u_arr, u_fun)
    elif isinstance(sys, StateSpace) and u_fun is None:
        x = _lti_exact(sys, t, x0, u_arr)
    else:
        if isinstance(sys, NonlinearSystem):
            sys.check(x0, u_fun(t[0], x0))
        x = _integrate(sys, t, x0, u_fun, rtol=rtol, atol=atol, method=method)
        u_arr = np.array([u_fun(tk, xk) for tk, xk in zip(t, x)]).reshape(t.size, sys.m)
    return SimulationResult(t=t, x=x, y=_outputs(sys, x, u_arr), u=u_arr, system=sys)


def simulate_batch(sys, t, x0s, u=None, *, rtol: float = 1e-9, atol: float = 1e-12,
                   method: str = "DOP853") -> np.ndarray:
    """Simulate many initial states at once as one stacked ODE.

    Much faster than a loop of `simulate` calls when a figure needs dozens of
    trajectories (a region of attraction, a fan of initial angles), because
    the solver runs once on the stacked state.

    Parameters
    ----------
    sys : StateSpace or continuous NonlinearSystem
        For a NonlinearSystem, ``f(x, u)`` must also accept a batch: `x` of
        shape (n, k) and `u` of shape (m, k), returning (n, k). Functions
        written with numpy operations on the rows ``x[0], x[1], ...`` do
        (all of `coursekit.models` do); this is checked once before integrating.
    t : (N,) array
    x0s : (k, n) array
        One initial state per row.
    u : callable, optional
        ``u(t, X)`` with X of shape (n, k) returning (m, k), e.g.
        ``lambda t, X: K @ X`` for state feedback; default zero input.

    Returns
    -------
    x : (N, k, n) array -- ``x[:, j]`` is the trajectory from ``x0s[j]``.
    """
    if not isinstance(sys, (StateSpace, NonlinearSystem)) or sys.is_discrete:
        raise ValueError("sys must be a continuous-time StateSpace or NonlinearSystem for simulate_batch.")
    t = as_time_grid(t, "t")
    X0 = as_matrix(x0s, "x0s", cols=sys.n, cols_why="one column per state")
    n, k, m = sys.n, X0.shape[0], sys.m
    u_fun = (lambda tk, X: np.zeros((m, X.shape[1]))) if u is None else u
    _check_batch(sys, t[0], X0.T, u_fun)

    def rhs(tk, flat):
        X = flat.reshape(n, k)
        return np.asarray(sys.f(X, np.asarray(u_fun(tk, X), float).reshape(m, k)), float).ravel()

    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (t[0], t[-1]), X0.T.ravel(), t_eval=t, method=method, rtol=rtol, atol=atol)
    if not sol.success or sol.y.shape[1] != t.size:
        raise RuntimeError(f"the ODE solver stopped early: {sol.message}")
    return sol.y.T.reshape(t.size, n, k).transpose(0, 2, 1)


def _check_batch(sys, t0: float, X: np.ndarray, u_fun) -> None:
    """Check once that f and u accept a batch and agree with column-by-column calls."""
    U = np.asarray(u_fun(t0, X), dtype=float)
    if U.shape != (sys.m, X.shape[1]):
        raise ValueError(f"u returned shape {U.shape} for a batch X of shape {X.shape}; "
                         f"expected ({sys.m}, {X.shape[1]}), one column per initial state.")
    try:
        F = np.asarray(sys.f(X, U), dtype=float)
    except Exception as err:
        raise ValueError(f"f cannot be evaluated on a batch of states (shape {X.shape}): {err}; "
                         "write f with numpy operations on the rows x[0], x[1], ... "
                         "or use simulate for one initial state at a time.") from err
    if not _agrees_column_by_column(sys.f, X, U, F):
        raise ValueError("f gives different results on a batch of states than one state at a time; "
                         "use simulate for one initial state at a time.")


def _agrees_column_by_column(fun, X: np.ndarray, U: np.ndarray, batch: np.ndarray) -> bool:
    """True when `batch`, fun's answer for the states X and inputs U as columns, holds
    fun(X[:, j], U[:, j]) in column j for every j (within 1e-12)."""
    single = np.column_stack([np.ravel(fun(X[:, j], U[:, j])) for j in range(X.shape[1])])
    return batch.size == single.size and np.allclose(batch.reshape(single.shape), single,
                                                     rtol=1e-12, atol=1e-12)


def _input(sys, t: np.ndarray, u, x0: np.ndarray):
    """Return (u_arr, u_fun): the input as samples, or as a function u(t, x)."""
    m = sys.m
    if u is None:
        return np.zeros((t.size, m)), (None if isinstance(sys, StateSpace) else lambda tk, xk: np.zeros(m))
    if callable(u):
        def u_fun(tk, xk, _u=u):
            return np.atleast_1d(np.asarray(_u(tk, xk), dtype=float)).ravel()
        check_function_output(u, (t[0], x0), "u", size=m,
                              what=f"the {m} input(s) at time t and state x")
        return None, u_fun
    if m == 0:
        raise ValueError("u was given, but the system has no input (m = 0); leave u=None.")
    u_arr = as_series(u, "u", samples=t.size, channels=m, channels_why="one column per input")
    if isinstance(sys, StateSpace) or sys.is_discrete:
        return u_arr, None

    def interpolated(tk, xk):
        return np.array([np.interp(tk, t, u_arr[:, j]) for j in range(m)])
    return u_arr, interpolated


def _check_discrete_grid(t: np.ndarray, dt: float) -> None:
    if t.size > 1 and not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
        raise ValueError(
            f"t must step by the system's sampling period dt={dt:g} for a discrete-time "
            f"system: received steps between {np.diff(t).min():g} and {np.diff(t).max():g}; "
            f"use t = np.arange(N) * {dt:g}."
        )


def _iterate(sys, t, x0, u_arr, u_fun):
    """Iterate x(k+1) = f(x(k), u(k)) (1.18) / (1.27), one step at a time, exactly as written."""
    N, n = t.size, sys.n
    if isinstance(sys, NonlinearSystem):
        sys.check(x0, u_fun(t[0], x0) if u_fun else u_arr[0])
    x = np.empty((N, n))
    u_out = np.empty((N, sys.m))
    x[0] = x0
    for k in range(N):
        u_out[k] = u_fun(t[k], x[k]) if u_fun else u_arr[k]
        if k + 1 < N:
            x[k + 1] = sys.f(x[k], u_out[k])
    return x, u_out


def lti_step_matrices(A: np.ndarray, B: np.ndarray, h: float):
    """Exact one-step matrices for x' = A x + B u with u linear over a step h.

    Returns ``(Ad, B0, B1)`` with ``x(k+1) = Ad x(k) + B0 u(k) + B1 u(k+1)``,
    from the matrix exponential of the augmented matrix
    ``[[A h, B h, 0], [0, 0, I], [0, 0, 0]]`` -- the integral in (2.4)
    evaluated in closed form for a piecewise-linear input.
    """
    from scipy.linalg import expm
    n, m = B.shape
    M = np.zeros((n + 2 * m, n + 2 * m))
    M[:n, :n] = A * h
    M[:n, n:n + m] = B * h
    M[n:n + m, n + m:] = np.eye(m)
    E = expm(M)
    Ad, G0, G1 = E[:n, :n], E[:n, n:n + m], E[:n, n + m:]
    return Ad, G0 - G1, G1


def _lti_exact(sys: StateSpace, t: np.ndarray, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Exact response of a continuous LTI system to a piecewise-linear input."""
    if is_uniform(t):
        Ad, B0, B1 = lti_step_matrices(sys.A, sys.B, t[1] - t[0])
        return _recurse(Ad, x0, [(B0, u[:-1]), (B1, u[1:])])
    x = np.empty((t.size, sys.n))
    x[0] = x0
    cache = {}
    for k, h in enumerate(np.diff(t)):
        key = round(float(h), 12)
        if key not in cache:
            cache[key] = lti_step_matrices(sys.A, sys.B, h)
        Ad, B0, B1 = cache[key]
        x[k + 1] = Ad @ x[k] + B0 @ u[k] + B1 @ u[k + 1]
    return x


def _recurse(Ad: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """Run x(k+1) = Ad x(k) + w(k) from x(0) = x0, with w(k) = sum of Bj uj(k).

    `terms` is a list of pairs ``(Bj, uj)``, each `uj` with one row per step.
    Fast and exact for any Ad, diagonalizable or not: in a Schur basis
    Ad = Z S Z^T (S block upper triangular) the coordinates z = Z^T x obey
    z_i(k+1) = S_ii z_i(k) + [v_i(k) + sum_{j>i} S_ij z_j(k)], v = Z^T w.
    The last block depends on nothing else; solving the blocks from the last
    to the first, each is a recursion of order one (a real eigenvalue) or two
    (a complex pair) solved over the whole time axis at once by
    `_first_order`, with no Python loop over samples.
    """
    from scipy.linalg import schur
    S, Z = schur(Ad, output="real")
    blocks = _schur_blocks(S)
    pairs = {i: _pair_modes(S[i:i + 2, i:i + 2]) for i, size in blocks if size == 2}
    if any(mode is None for mode in pairs.values()):
        return _recurse_complex(Ad, x0, terms)
    z = _projected_input(Z, x0, terms)
    for i, size in reversed(blocks):
        _solve_block(S, z, i, size, pairs.get(i))
    _to_original_basis(Z, z)
    x = z.T  # time-major view of the (n, N) array: columns contiguous, no copy
    x[0] = x0  # exactly, not after a round trip through the Schur basis
    return x


def _schur_blocks(S: np.ndarray) -> list:
    """(start, size) of the 1x1 and 2x2 diagonal blocks of a real Schur form."""
    blocks, i, n = [], 0, S.shape[0]
    while i < n:
        size = 2 if i + 1 < n and S[i + 1, i] != 0.0 else 1
        blocks.append((i, size))
        i += size
    return blocks


def _pair_modes(M: np.ndarray):
    """Eigen-decomposition (lambda, p, r) of a 2x2 block with a complex pair, or None.

    With M = P diag(lambda, conj(lambda)) P^-1, p the first column of P and r the
    first row of P^-1, a real recursion y(k+1) = M y(k) + e(k) is
    y = 2 Re(p q) with q(k+1) = lambda q(k) + r e(k): one complex first-order
    filter. In closed form, for M = [[a, b], [c, d]] with a complex pair
    lambda = (a + d)/2 + i w: p = [b, lambda - a], r = [conj(lambda) - a, -b] / (-2 i w b).
    None when P is badly conditioned (cond > 1e4: a nearly repeated eigenvalue).
    """
    (a, b), (c, d) = M
    half = 0.5 * (a - d)
    w = np.sqrt(-(half * half + b * c))
    lam = complex(0.5 * (a + d), w)
    p = np.array([b, lam - a])
    # P = [p, conj(p)]: its squared singular values are |p|^2 +- |p^T p|
    norm2, overlap = float(np.vdot(p, p).real), abs(p @ p)
    if norm2 - overlap <= 1e-8 * (norm2 + overlap):
        return None
    r = np.array([lam.conjugate() - a, -b]) / (-2j * w * b)
    return lam, p, r


def _projected_input(Z: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """z(0) = Z^H x0 and z(k+1) slots holding v(k) = Z^H w(k), as an (n, N) array.

    One matrix product writes all the inputs' contributions into place:
    ``[Z^H B1, Z^H B2, ...]`` times the inputs side by side, transposed.
    """
    ZH = Z.conj().T
    N = terms[0][1].shape[0] + 1
    z = np.empty((x0.size, N), dtype=np.result_type(Z, x0))
    z[:, 0] = ZH @ x0
    G = ZH @ np.hstack([Bj for Bj, _ in terms])
    W = np.hstack([uj for _, uj in terms])
    np.matmul(G, W.T, out=z[:, 1:])
    return z


def _to_original_basis(Z: np.ndarray, z: np.ndarray) -> None:
    """Overwrite z (n, N) with x = Z z, a slab of time samples at a time.

    Each sample transforms on its own, so working in place through slabs of
    about 128 kB needs no second n-by-N array (whose fresh pages would cost
    as much as the product itself).
    """
    width = max(1, 16384 // z.shape[0])
    for start in range(0, z.shape[1], width):
        slab = z[:, start:start + width]
        slab[...] = Z @ slab


def _solve_block(S: np.ndarray, z: np.ndarray, i: int, size: int, modes) -> None:
    """Replace rows i..i+size-1 of z (input on entry) by the block's solution."""
    k = i + size
    if k < S.shape[0]:
        z[i:k, 1:] += S[i:k, k:] @ z[k:, :-1]
    if size == 1:
        # y(0) = z_i(0), y(k+1) = S_ii y(k) + input(k)
        z[i] = _first_order(S[i, i], z[i])
        return
    lam, p, r = modes
    q = _first_order(lam, r[0] * z[i] + r[1] * z[i + 1])
    for row, pj in zip((i, i + 1), 2.0 * p):  # z_row = 2 Re(p_j q), without complex temporaries
        np.multiply(pj.real, q.real, out=z[row])
        z[row] -= pj.imag * q.imag


def _first_order(a, v: np.ndarray) -> np.ndarray:
    """y(0) = v(0), y(k) = a y(k-1) + v(k) for all k, as one forward substitution.

    The recursion is the unit lower-bidiagonal system y(k) - a y(k-1) = v(k);
    LAPACK's banded triangular solve (?tbtrs, no pivoting) runs it in compiled
    code -- the same operations as ``scipy.signal.lfilter([1], [1, -a], v)``,
    without importing scipy.signal (most of a second) for it. `v` may be
    overwritten.
    """
    from scipy.linalg import lapack
    cplx = np.iscomplexobj(v) or np.iscomplexobj(a)
    dtype = complex if cplx else float
    band = np.empty((2, v.size), dtype=dtype)  # band storage: diagonal row, then the row below
    band[0] = 1.0
    band[1] = -a
    solve = lapack.ztbtrs if cplx else lapack.dtbtrs
    y, _ = solve(band, np.asarray(v, dtype=dtype)[:, None], uplo="L", diag="U", overwrite_b=1)
    return y[:, 0]


def _recurse_complex(Ad: np.ndarray, x0: np.ndarray, terms) -> np.ndarray:
    """`_recurse` through the complex Schur form: triangular, so robust when
    eigenvalues nearly coincide, at about twice the cost."""
    from scipy.linalg import schur
    S, Z = schur(Ad, output="complex")
    z = _projected_input(Z, x0, terms)
    for i in range(x0.size - 1, -1, -1):
        _solve_block(S, z, i, 1, None)
    x = (z.real.T @ Z.real.T) - (z.imag.T @ Z.imag.T)
    x[0] = x0
    return x


def _integrate(sys, t, x0, u_fun: Callable, *, rtol, atol, method) -> np.ndarray:
    """Integrate x' = f(x, u(t, x)) with solve_ivp, returning x on the grid t."""
    from scipy.integrate import solve_ivp

    def rhs(tk, xk):
        return sys.f(xk, u_fun(tk, xk))

    sol = solve_ivp(rhs, (t[0], t[-1]), x0, t_eval=t, method=method, rtol=rtol, atol=atol)
    if not sol.success or sol.y.shape[1] != t.size:
        raise RuntimeError(
            f"the ODE solver stopped at t={sol.t[-1] if sol.t.size else t[0]:g}: {sol.message}. "
            "The solution may blow up (check the model), or the system may be stiff: "
            "try method='LSODA' or method='Radau'."
        )
    return sol.y.T


def _outputs(sys, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    if isinstance(sys, StateSpace):
        return x @ sys.C.T + u @ sys.D.T
    return np.array([sys.h(xk, uk) for xk, uk in zip(x, u)]).reshape(x.shape[0], -1)
