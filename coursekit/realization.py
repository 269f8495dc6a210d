"""Bridges between descriptions of a system (section 1.6).

* `ode_to_ss`: a linear ODE of order n -> the state-space realization in
  controllability canonical form (1.47)-(1.53), also with derivatives of the
  input (1.65)-(1.67);
* `difference_to_ss`: the same for a difference equation (1.68)-(1.71);
* `euler_discretize`: continuous time -> discrete time with the Euler
  method (1.41)-(1.43).

Polynomials are ascending arrays: ``a = [a_0, ..., a_{n-1}]`` stands for
``y^(n) + a_{n-1} y^(n-1) + ... + a_1 y' + a_0 y`` (the leading 1 is left out).
"""

from __future__ import annotations

import numpy as np

from ._arguments import as_system
from ._validation import as_scalar, as_vector
from .systems import NonlinearSystem, StateSpace

__all__ = ["ode_to_ss", "difference_to_ss", "euler_discretize"]


def _companion(a: np.ndarray) -> np.ndarray:
    """The n x n matrix of (1.52): ones on the superdiagonal, last row -a."""
    n = a.size
    A = np.eye(n, k=1)
    A[-1, :] = -a
    return A


def _realize(a, b, *, dt: float | None, name: str) -> StateSpace:
    """Shared body of `ode_to_ss` and `difference_to_ss` (same matrices, 1.53 = 1.70)."""
    a = as_vector(a, "a")
    n = a.size
    if n == 0:
        raise ValueError(
            "a is empty: received no coefficients, expected [a_0, ..., a_{n-1}] with at least one "
            "entry (n >= 1); for y' + 3 y = u write a = [3]."
        )
    A = _companion(a)
    e_n = np.zeros((n, 1))
    e_n[-1, 0] = 1.0
    if np.ndim(b) == 0:
        b = as_scalar(b, "b")
        # (1.53) / (1.70)-(1.71): B = [0 ... 0 b]^T, y = x_1
        B = b * e_n
        C = np.eye(1, n)
    else:
        b = as_vector(b, "b", size=n,
                      why=f"[b_0, ..., b_{{n-1}}] for an equation of order n={n}; "
                          "pad with zeros for missing derivatives of u")
        # (1.66)-(1.67): B = e_n, y = [b_0 b_1 ... b_{n-1}] x
        B = e_n
        C = b.reshape(1, n)
    return StateSpace(A, B, C, np.zeros((1, 1)), dt=dt, name=name)


def ode_to_ss(a, b) -> StateSpace:
    """State-space realization of a linear ODE in controllability canonical form.

    Parameters
    ----------
    a : sequence of n numbers
        ``[a_0, ..., a_{n-1}]`` of ``y^(n) + a_{n-1} y^(n-1) + ... + a_0 y = rhs``
        (ascending order, the leading coefficient 1 left out).
    b : number or sequence of n numbers
        A number: ``rhs = b u`` (1.47). The state is ``x = [y, y', ..., y^(n-1)]``
        (1.48) and the realization is (1.52)-(1.53): ``B = [0 ... 0 b]^T``,
        ``C = [1 0 ... 0]``.
        A sequence ``[b_0, ..., b_{n-1}]``: ``rhs = b_{n-1} u^(n-1) + ... + b_0 u``
        (1.65), realized as (1.66)-(1.67): ``B = e_n``, ``C = [b_0 ... b_{n-1}]``.

    Both give the transfer function ``b(s) / a(s)``, with
    ``a(s) = s^n + a_{n-1} s^{n-1} + ... + a_0``.

    Examples
    --------
    The mass-spring-damper (1.54) with m = 2, d = 1, k = 4, divided by m:

    >>> sys = ode_to_ss([4 / 2, 1 / 2], 1 / 2)
    >>> sys.A
    array([[ 0. ,  1. ],
           [-2. , -0.5]])
    """
    return _realize(a, b, dt=None, name="ODE realization")


def difference_to_ss(a, b) -> StateSpace:
    """State-space realization of a linear difference equation (1.68)-(1.71).

    ``y(t+n) + a_{n-1} y(t+n-1) + ... + a_0 y(t) = b u(t)`` with the state
    ``x(t) = [y(t), y(t+1), ..., y(t+n-1)]`` gives the matrices of (1.70)
    and the output (1.71), in discrete time with ``dt = 1`` (one step per
    time unit). `a` and `b` are read as in `ode_to_ss`: a sequence `b` stands
    for ``b_{n-1} u(t+n-1) + ... + b_0 u(t)`` on the right-hand side.

    Examples
    --------
    Fibonacci (1.72), y(t+2) - y(t+1) - y(t) = 0, so a = [-1, -1]:

    >>> difference_to_ss([-1, -1], 0).A
    array([[0., 1.],
           [1., 1.]])
    """
    return _realize(a, b, dt=1.0, name="difference-equation realization")


def euler_discretize(sys, Ts):
    """Discretize a continuous-time system with the Euler method (1.43).

    Replacing dx/dt by ``(x(t+1) - x(t)) / Ts`` (1.42) gives
    ``x(t+1) = x(t) + Ts f(x(t), u(t))``.

    * `StateSpace`: returns ``StateSpace(I + Ts A, Ts B, C, D, dt=Ts)``.
    * `NonlinearSystem`: returns a discrete `NonlinearSystem` with the map
      ``f'(x, u) = x + Ts f(x, u)`` and the same output map.

    The result is only an approximation of sampling the continuous system;
    its error shrinks in proportion to Ts, and for a too large Ts the
    discrete system can be unstable although the continuous one is stable
    (for x' = lambda x with lambda < 0 this happens when Ts > 2 / |lambda|).
    """
    sys = as_system(sys, hint="build one with StateSpace(A, B, C, D) or NonlinearSystem(f, n, m).")
    Ts = as_scalar(Ts, "Ts", positive=True)
    if sys.is_discrete:
        raise ValueError(
            f"sys is already a discrete-time system (dt={sys.dt:g}); euler_discretize expects "
            "a continuous-time system (dt=None)."
        )
    name = f"Euler discretization of {sys.name or 'the system'} (Ts={Ts:g})"
    if isinstance(sys, StateSpace):
        # (1.43) for f(x, u) = A x + B u: x(t+1) = (I + Ts A) x(t) + Ts B u(t)
        return StateSpace(np.eye(sys.n) + Ts * sys.A, Ts * sys.B, sys.C, sys.D, dt=Ts, name=name)

    def f_euler(x, u, _f=sys.f, _Ts=Ts):
        # (1.43): f'(x, u) = x + Ts f(x, u)
        return np.asarray(x, dtype=float) + _Ts * _f(x, u)

    return NonlinearSystem(f_euler, n=sys.n, m=sys.m, h=sys.h, dt=Ts, name=name,
                           params=dict(sys.params, Ts=Ts))
