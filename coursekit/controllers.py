"""State-feedback controllers of chapter 3, usable as ``u(t, x)`` in `simulate`.

* `StateFeedback(K, x_eq, u_eq)`: u = K (x - x*) + u* (3.92), (3.100);
  with the defaults x* = 0, u* = 0 it is the plain u = K x (3.17);
* `TrackingController(K, x_d, u_d)`: u = K (x - x_d(t)) + u_d(t) (3.104);
* integral action (section 3.6): `integral_augment` builds the augmented
  matrices (A_E, B_E) for the state [xi; x] with xi' = C x - r, so that the
  gain K_E = [K_I, K] of u = K x + K_I xi is found by pole placement on
  (A_E, B_E); `with_integrators` adds the same integrator states to any
  system so it can be simulated with `IntegralFeedback`; and
  `integral_closed_loop` returns the closed loop as a `StateSpace` driven by
  the disturbance d and the reference r;
* `PendulumLinearizingController`: the pendulum's feedback-linearizing law
  u = m g l sin(x1) + m l^2 v, v = -p0 (x1 - theta_ref) - p1 x2 (3.153)-(3.154).

Sign convention everywhere: u = K x, closed loop A + B K.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ._arguments import as_system
from ._pairs import as_pair
from ._validation import as_matrix, as_scalar, as_square, as_vector, checked_call, float_array
from .diagnostics import UserFunctionError
from .systems import NonlinearSystem, StateSpace

__all__ = ["StateFeedback", "TrackingController", "integral_augment", "with_integrators", "IntegralFeedback",
           "integral_closed_loop", "PendulumLinearizingController"]


def _fmt(v) -> str:
    return np.array2string(np.asarray(v), precision=4, suppress_small=True)


def _gain(K, name: str = "K") -> np.ndarray:
    return as_matrix(K, name, rows=1 if np.ndim(K) == 1 else None)


def _states(x, n: int, name: str = "x", gain: str = "") -> np.ndarray:
    """x as one state (n,) or a batch (n, k) of states as columns (a column (n, 1) is a
    batch of one); other shapes raise ValueError (a row (1, n) or a wrong length would
    broadcast into a wrong answer), which names `gain` ("K is 1x3") when given. A sympy
    Matrix of numbers is a column by construction, but a student writes Matrix([1, 2]) for
    the state vector: a sympy vector (n x 1 or 1 x n) is one state, as the same numbers in a list."""
    if type(x).__module__.split(".")[0] == "sympy" and 1 in getattr(x, "shape", ()):
        x = np.ravel(float_array(x, name))
    x = np.asarray(x)
    if x.dtype.kind != "f":
        x = float_array(x, name)
    if x.ndim not in (1, 2) or x.shape[0] != n:
        since = f", since {gain}" if gain else ""
        raise ValueError(f"{name} has shape {x.shape}: expected ({n},), one entry per state{since}, "
                         f"or ({n}, k) for a batch of k states as columns.")
    if not np.isfinite(x).all():
        raise ValueError(f"{name} contains NaN or infinite entries: received {_fmt(x)}; a control law "
                         "needs a measured state (look for where the state became NaN or inf).")
    return x


def _size(name: str, M: np.ndarray) -> str:
    return f"{name} is {M.shape[0]}x{M.shape[1]}"


def _column(v: np.ndarray, x: np.ndarray) -> np.ndarray:
    """v (one entry per row) shaped to broadcast against x, one state or a batch."""
    return v if x.ndim == 1 else v[:, None]


class StateFeedback:
    """u = K (x - x*) + u*: linear state feedback around an equilibrium (3.92), (3.100).

    Call it as ``controller(t, x)`` (the signature `simulate` expects); with
    x a batch (n, k) of states it returns (m, k), as `simulate_batch` expects
    (a column x (n, 1) is a batch of one and gives a column u (m, 1)).
    For a nonlinear plant, K comes from the linearization at (x*, u*)
    (3.88)-(3.91) and the law only works near x*; for a linear plant
    x' = A x + B u with A x* + B u* = 0 (3.94) it works globally (3.98)-(3.100).
    """

    def __init__(self, K, x_eq=None, u_eq=None):
        self.K = _gain(K)
        m, n = self.K.shape
        self.x_eq = np.zeros(n) if x_eq is None else as_vector(
            x_eq, "x_eq", size=n, why=f"one per state, since K is {m}x{n}")
        self.u_eq = np.zeros(m) if u_eq is None else as_vector(
            u_eq, "u_eq", size=m, why=f"one per input, since K is {m}x{n}")

    def __call__(self, t, x) -> np.ndarray:
        # x: one state (n,), or a batch (n, k) as `simulate_batch` passes it
        x = _states(x, self.K.shape[1], gain=_size("K", self.K))
        if x.ndim == 2:
            return self.K @ (x - self.x_eq[:, None]) + self.u_eq[:, None]
        # (3.92): u = K (x - x*) + u*
        return self.K @ (x - self.x_eq) + self.u_eq

    def __repr__(self) -> str:
        return f"StateFeedback(K={_fmt(self.K)}, x_eq={_fmt(self.x_eq)}, u_eq={_fmt(self.u_eq)})"


def _trajectory(func, name: str, size: int, what: str) -> Callable:
    """func(t) as `size` finite numbers, checked at t = 0 and at every call: an
    exception, NaN/inf or a wrong size raises `UserFunctionError` naming `name` and t."""
    if not callable(func):
        raise ValueError(f"{name} must be a function of time t returning {what}: "
                         f"received {type(func).__name__}.")

    def explain(t, err=None):
        checked_call(func, (t,), name, size=size, what=what, where=f"at t = {t:.6g}")
        raise UserFunctionError(f"{name} failed at t = {t:.6g}, but returned {size} finite numbers "
                                "when called again: does it change between calls?") from err

    def wrapped(t):
        try:
            value = np.ravel(np.asarray(func(t)))
            # real numbers only: complex ones would lose their imaginary part with a mere warning
            if value.dtype.kind in "fiu" and value.size == size and np.isfinite(value).all():
                return value.astype(float, copy=False)
        except Exception as err:
            explain(t, err)
        explain(t)
    wrapped(0.0)
    return wrapped


class TrackingController:
    """u = K (x - x_d(t)) + u_d(t): tracking a feasible trajectory (3.101)-(3.104).

    `x_d(t)` returns the desired state (n numbers) and `u_d(t)` the open-loop
    input that produces it (m numbers), with x_d' = A x_d + B u_d (3.101).
    The feedback term corrects the deviation Delta x = x - x_d, whose dynamics
    are A + B K (3.103).

    Call it as ``controller(t, x)`` with t a number and x one state (n,) or a
    batch (n, k) of states (returning (m, k)). x_d and u_d are checked at
    t = 0 and at every call: an exception, NaN/inf or a wrong number of
    values raises `UserFunctionError` naming the function and the time.
    """

    def __init__(self, K, x_d: Callable, u_d: Callable):
        self.K = _gain(K)
        m, n = self.K.shape
        self.x_d = _trajectory(x_d, "x_d", n, f"the desired state, {n} numbers")
        self.u_d = _trajectory(u_d, "u_d", m, f"the open-loop input, {m} numbers")

    def __call__(self, t, x) -> np.ndarray:
        x = _states(x, self.K.shape[1], gain=_size("K", self.K))
        t = as_scalar(t, "t")
        # (3.104): u = K (x - x_d(t)) + u_d(t)
        return self.K @ (x - _column(self.x_d(t), x)) + _column(self.u_d(t), x)

    def __repr__(self) -> str:
        return f"TrackingController(K={_fmt(self.K)})"


def _output_matrix(C, n: int) -> np.ndarray:
    if C is None:
        # the notes integrate the first state x1 (3.110), (3.117)
        C = np.eye(1, n)
    return as_matrix(C, "C", cols=n, cols_why=f"one per state, since A is {n}x{n}",
                     rows=1 if np.ndim(C) == 1 else None)


def _integrators(q) -> int:
    q = int(as_scalar(q, "integrators", integer=True))
    if q < 1:
        raise ValueError(f"integrators must be 1 or more: received {q}.")
    return q


def integral_augment(A, B, C=None, *, integrators: int = 1):
    """Augmented matrices (A_E, B_E) for integral action (3.113), (3.120), (3.133).

    The augmented state is ``x_E = [xi_q, ..., xi_1, x]`` with
    ``xi_1' = C x`` (the integral of y = C x, default C = [1, 0, ..., 0] as in
    (3.110) and (3.117)) and ``xi_{j+1}' = xi_j`` (double integral for ramp
    disturbances, (3.133)). A gain ``K_E = place(A_E, B_E, poles)``
    (u = K_E x_E, closed loop A_E + B_E K_E) then contains the integral gains
    first and the state gains last: ``K_E = [k_II, k_I, K]`` for q = 2.

    For a CCF plant with C = e_1^T and q = 1, A_E is again a CCF of order
    n + 1, with the same characteristic polynomial as the notes' (3.120).
    (A_E, B_E) is controllable exactly when (A, B) is and the plant has no
    zero at s = 0 (rank [[A, B], [C, 0]] = n + p).
    """
    A, B = as_pair(A, B)
    n = A.shape[0]
    C = _output_matrix(C, n)
    q = _integrators(integrators)
    p, m = C.shape[0], B.shape[1]
    N = q * p + n
    A_E = np.zeros((N, N))
    for j in range(q - 1):
        # xi_{q-j}' = xi_{q-j-1}: each block integrates the next one
        A_E[j * p:(j + 1) * p, (j + 1) * p:(j + 2) * p] = np.eye(p)
    # xi_1' = C x
    A_E[(q - 1) * p:q * p, q * p:] = C
    A_E[q * p:, q * p:] = A
    B_E = np.vstack([np.zeros((q * p, m)), B])
    return A_E, B_E


class IntegralFeedback:
    """u = K_E x_E = K_I xi + K x on the augmented state x_E = [xi; x] (3.110), (3.125).

    `K_E` is the gain found on (A_E, B_E) from `integral_augment`;
    `n_integrator_states` is q p, the number of leading entries of x_E that
    are integrator states. Attributes `K_I` (on xi) and `K` (on x) split it.
    Use with a system from `with_integrators`.
    """

    def __init__(self, K_E, n_integrator_states: int):
        self.K_E = _gain(K_E, "K_E")
        k = int(as_scalar(n_integrator_states, "n_integrator_states", integer=True))
        if not 1 <= k < self.K_E.shape[1]:
            raise ValueError(
                f"n_integrator_states must be between 1 and {self.K_E.shape[1] - 1}: received {k}."
            )
        self.K_I, self.K = self.K_E[:, :k], self.K_E[:, k:]

    def __call__(self, t, x_E) -> np.ndarray:
        # x_E: one augmented state (N,) or a batch (N, k)
        x_E = _states(x_E, self.K_E.shape[1], "x_E", _size("K_E", self.K_E))
        # (3.110)/(3.125): u = K x + K_I * integral
        return self.K_E @ x_E

    def __repr__(self) -> str:
        return f"IntegralFeedback(K_I={_fmt(self.K_I)}, K={_fmt(self.K)})"


def with_integrators(sys, C=None, r=None, *, integrators: int = 1) -> NonlinearSystem:
    """`sys` extended by integrator states: x_E = [xi_q, ..., xi_1, x], xi_1' = C x - r.

    Works for a `StateSpace` and a `NonlinearSystem` (continuous time). With
    a reference r the integrator forces C x -> r at any stable equilibrium,
    without computing u* (3.127)-(3.131). Simulate the result with
    ``u=IntegralFeedback(K_E, q * p)``; to add an input disturbance d(t)
    as in (3.122), pass ``u=lambda t, x: controller(t, x) + d(t)``.
    """
    sys = as_system(sys, time="continuous")
    n = sys.n
    C = _output_matrix(C, n)
    p = C.shape[0]
    q = _integrators(integrators)
    r = np.zeros(p) if r is None else as_vector(r, "r", size=p, why="one per row of C")
    k = q * p

    def f(x_E, u):
        # x_E: one state or a batch (n + k, ...) of them as columns
        xi, x = x_E[:k], x_E[k:]
        # xi_{j+1}' = xi_j, and (3.127): the integrator integrates the error C x - r
        return np.concatenate([xi[p:], C @ x - _column(r, x), sys.f(x, u)])

    name = f"{sys.name or 'system'} with {q} integrator(s)"
    return NonlinearSystem(f, n=n + k, m=sys.m, name=name)


def integral_closed_loop(A, B, K_E, C=None, *, integrators: int = 1) -> StateSpace:
    """Closed loop of x' = A x + B (u + d), xi' = C x - r, u = K_E [xi; x] as a StateSpace.

    Its state is x_E = [xi; x], its inputs are ``[d, r]`` (m disturbance
    entries entering like u (3.122), then p reference entries (3.127)),
    its output is y = C x. Because it is linear, `simulate` solves it
    exactly for constant or piecewise-linear d and r -- a ramp disturbance
    d = d0 t (3.132) included.
    """
    A_E, B_E = integral_augment(A, B, C, integrators=integrators)
    q = _integrators(integrators)
    n = as_square(A, "A").shape[0]
    C = _output_matrix(C, n)
    p, m, N = C.shape[0], B_E.shape[1], A_E.shape[0]
    K_E = as_matrix(K_E, "K_E", rows=m, cols=N, rows_why="one per input",
                    cols_why="one per augmented state (integrators first)")
    B_r = np.zeros((N, p))
    B_r[(q - 1) * p:q * p] = -np.eye(p)
    C_E = np.hstack([np.zeros((p, N - n)), C])
    # x_E' = (A_E + B_E K_E) x_E + B_E d - [0; I; 0] r
    return StateSpace(A_E + B_E @ K_E, np.hstack([B_E, B_r]), C_E, name="integral action loop")


class PendulumLinearizingController:
    """Feedback-linearizing control of the pendulum (3.151)-(3.154).

    u = m g l sin(x1) + d l^2 x2 + m l^2 v,   v = -p0 (x1 - theta_ref) - p1 x2

    The first terms cancel gravity (and the damping d_theta of
    `models.pendulum`, zero in the notes), leaving x2' = v (3.145); v places
    the poles at the roots of s^2 + p1 s + p0. With theta_ref = 0 this is
    exactly (3.154); theta_ref = pi holds the pendulum upright (theta = 0
    hangs down, as in `models.pendulum`). `poles` gives the two desired
    closed-loop poles (p1 = -(sum), p0 = product). Called with a batch x of
    shape (2, k) it returns (1, k), so it also works in `simulate_batch`.
    """

    def __init__(self, poles, *, m: float = 1.0, l: float = 1.0, g: float = 9.81,
                 d_theta: float = 0.0, theta_ref: float = 0.0):
        from ._validation import as_poles
        from .placement import poly_from_roots
        poles = as_poles(poles, "poles", count=2)
        self.p0, self.p1 = poly_from_roots(poles)
        self.m, self.l = as_scalar(m, "m", positive=True), as_scalar(l, "l", positive=True)
        self.g, self.d_theta = as_scalar(g, "g"), as_scalar(d_theta, "d_theta")
        self.theta_ref = as_scalar(theta_ref, "theta_ref")

    def __call__(self, t, x) -> np.ndarray:
        # x1, x2 are numbers, or rows of a batch (2, k) of states as `simulate_batch` passes it
        x1, x2 = _states(x, 2)
        # (3.147): v = -p0 x1 - p1 x2, measured from the target angle
        v = -self.p0 * (x1 - self.theta_ref) - self.p1 * x2
        # (3.153): u = m g l sin(x1) + m l^2 v (+ the damping term)
        u = self.m * self.g * self.l * np.sin(x1) + self.d_theta * self.l**2 * x2 + self.m * self.l**2 * v
        return np.array([u])

    def __repr__(self) -> str:
        return (f"PendulumLinearizingController(p0={self.p0:.4g}, p1={self.p1:.4g}, "
                f"theta_ref={self.theta_ref:.4g})")
