"""Open-loop control (section 2.3): polynomial trajectories and feedforward.

* `poly_trajectory(T, start, end)` is the polynomial of degree 2r - 1 that
  meets r boundary values (value and r - 1 derivatives) at t = 0 and t = T,
  the construction (2.31)-(2.38) for any r;
* `feedforward(a, b, traj)` is the input (2.25) that makes the output of a
  plant in controllability canonical form follow `traj`;
* `open_loop_control(A, B, x0, xT, T)` is the algorithm (2.73) for any
  controllable single-input system: transform to the CCF, plan z1 from
  z0 = T x0 to zT = T xT, and apply the feedforward input.
"""

from __future__ import annotations

from math import factorial, isfinite
from typing import Callable

import numpy as np

from ._validation import as_scalar, as_vector
from .controllability import _pair, ccf_transform, charpoly

__all__ = ["PolyTrajectory", "poly_trajectory", "feedforward", "OpenLoopPlan", "open_loop_control",
           "plot_plan"]


def _times(t, name: str = "t"):
    """Return (times as a 1-D array, whether the input was a single number)."""
    return as_vector(t, name), np.ndim(t) == 0


def _derivative_order(k) -> int:
    k_float = as_scalar(k, "k", integer=True)
    if k_float < 0:
        raise ValueError(f"k must be a derivative order >= 0: received {k!r}; use k=0 for the value.")
    return int(k_float)


class PolyTrajectory:
    """A polynomial y_d(t) of degree 2r - 1 with given values and derivatives at 0 and T.

    Call it as ``traj(t, k=0)`` for the k-th time derivative at time(s) `t`
    (a number gives a number, an array an array of the same length). The
    polynomial is stored in the centred, normalized time s = 2 t / T - 1
    (s = -1 at t = 0, s = 1 at t = T), where its coefficients are of order
    one whatever T is; a derivative in t is the derivative in s times
    (2 / T)^k. Outside [0, T] the polynomial is simply continued.
    """

    def __init__(self, T: float, start: np.ndarray, end: np.ndarray, coeffs: np.ndarray):
        self.T = T
        self.start = start
        self.end = end
        self.r = start.size
        # coefficients of p(s) = sum_j c_j s^j (ascending) and of its derivatives
        self.coeffs = coeffs
        self._derivs = [coeffs]
        for _ in range(2 * self.r - 1):
            self._derivs.append(np.polynomial.polynomial.polyder(self._derivs[-1]))
        self._derivs = [[float(c) for c in d] for d in self._derivs]

    @property
    def degree(self) -> int:
        """Degree 2r - 1 of the polynomial."""
        return 2 * self.r - 1

    def __call__(self, t, k=0):
        if isinstance(t, float) and isfinite(t) and type(k) is int and k >= 0:
            # one finite time, as an ODE solver asks at every step: skip the array checks
            return self._scalar_derivatives(t, k)[k]
        tt, scalar = _times(t)
        values = self._eval(tt, _derivative_order(k))
        return float(values[0]) if scalar else values

    def _scalar_derivatives(self, t: float, order: int) -> list:
        """[y, y', ..., y^(order)] at one time t, in plain floats (fast path for ODE solvers)."""
        s = 2.0 * t / self.T - 1.0
        out = []
        for k in range(order + 1):
            value = 0.0
            if k < len(self._derivs):
                # Horner's rule for p^(k)(s)
                for c in self._derivs[k][::-1]:
                    value = value * s + c
            out.append(value * (2.0 / self.T) ** k)
        return out

    def _eval(self, tt, k: int):
        """k-th derivative at the checked times `tt` (no input validation: for inner loops)."""
        if k >= len(self._derivs):
            return np.zeros_like(tt)
        s = 2.0 * tt / self.T - 1.0
        # d^k y/dt^k = (2/T)^k d^k p/ds^k
        return np.polynomial.polynomial.polyval(s, np.array(self._derivs[k])) * (2.0 / self.T) ** k

    def __repr__(self) -> str:
        return (f"PolyTrajectory of degree {self.degree} on [0, {self.T:g}]: "
                f"start {self.start.tolist()}, end {self.end.tolist()}")


def _hermite_coefficients(r: int, start_s: np.ndarray, end_s: np.ndarray) -> np.ndarray:
    """Coefficients of the degree 2r-1 polynomial p(s) meeting s-derivatives at s = -1 and s = 1."""
    size = 2 * r
    M = np.zeros((size, size))
    for k in range(r):
        for j in range(k, size):
            # d^k/ds^k s^j = j!/(j-k)! s^(j-k), at s = -1 and at s = 1
            falling = factorial(j) / factorial(j - k)
            M[k, j] = falling * (-1.0) ** (j - k)
            M[r + k, j] = falling
    # (2.34)-(2.37) in matrix form: M c = [start; end]; (2.38) solves it
    return np.linalg.solve(M, np.concatenate([start_s, end_s]))


def poly_trajectory(T, start, end) -> PolyTrajectory:
    """Polynomial trajectory from `start` at t = 0 to `end` at t = T.

    Implements (2.31)-(2.38) for any number r of boundary conditions:
    ``start = [y(0), y'(0), ..., y^(r-1)(0)]`` and likewise `end` at T give
    the unique polynomial of degree 2r - 1 (r = 2 is the cubic (2.33)).

    Returns a `PolyTrajectory` ``traj`` with ``traj(t, k=0)`` the k-th
    derivative. The linear system (2.37) is set up in the centred normalized
    time s = 2 t / T - 1, where the k-th derivative is scaled by (T / 2)^k,
    so it is the same well-conditioned system for T = 0.01 and T = 1000
    (the monomials t^j of (2.37) would make it hopeless for large r or T).
    """
    T = as_scalar(T, "T", positive=True)
    start = as_vector(start, "start")
    end = as_vector(end, "end", size=start.size,
                    why="the same number of boundary conditions at t = 0 and t = T")
    r = start.size
    if r == 0:
        raise ValueError("start is empty: expected at least the value y(0) (and its derivatives).")
    # d^k y/dt^k = (2/T)^k d^k p/ds^k, so the s-derivatives are (T/2)^k times the t-derivatives
    scale = (T / 2.0) ** np.arange(r)
    coeffs = _hermite_coefficients(r, start * scale, end * scale)
    return PolyTrajectory(T, start, end, coeffs)


def _check_trajectory(traj) -> None:
    if not callable(traj):
        raise ValueError(
            f"traj must be a function traj(t, k) returning the k-th derivative of y_d at t: "
            f"received {type(traj).__name__}; build one with poly_trajectory(T, start, end)."
        )
    value = np.asarray(traj(0.0, 0), dtype=float)
    if value.size != 1:
        raise ValueError(
            f"traj(0.0, 0) returned shape {value.shape}; expected one number (the desired output y_d(0))."
        )


def feedforward(a, b, traj: Callable) -> Callable:
    """Feedforward input u_d(t) for a plant in controllability canonical form.

    Implements (2.25): ``u_d = (a_0 y_d + a_1 y_d' + ... + a_{n-1} y_d^(n-1) + y_d^(n)) / b``
    for the CCF (2.16) with last row ``-[a_0 ... a_{n-1}]`` (ascending, as
    returned by `charpoly`) and input gain b. `traj(t, k)` is the desired
    output and its derivatives, e.g. a `poly_trajectory`.

    Returns ``ud(t)``: a number for a number, an array for an array of times.
    """
    a = as_vector(a, "a")
    b = as_scalar(b, "b")
    if b == 0:
        raise ValueError("b must be nonzero: received 0; with b = 0 the input does not enter "
                         "the plant (2.16) and no feedforward exists.")
    _check_trajectory(traj)
    n = a.size

    def ud(t):
        # (2.25): u_d = (1/b) [a_0 y_d + ... + a_{n-1} y_d^(n-1) + y_d^(n)]
        total = traj(t, n)
        for i in range(n):
            total = total + a[i] * traj(t, i)
        return total / b

    return ud


class OpenLoopPlan:
    """Result of `open_loop_control`: the plan from x0 to xT in time T.

    Attributes
    ----------
    A, B : the plant; x0, xT : start and target state; horizon : the time T.
    transform : the matrix T with z = T x in CCF (2.59)-(2.65).
    a : ascending characteristic polynomial of A (last row of the CCF is -a).
    z0, zT : T x0 and T xT, the boundary conditions of y_d = z1.
    yd : the `PolyTrajectory` planned for z1.

    Methods ``ud(t)``, ``z(t)``, ``x(t)`` evaluate the planned input and
    states; ``input(t, x)`` is ``ud`` in the form `simulate` accepts. Times
    outside [0, T] are clipped: before 0 and after T the end values are held.
    """

    def __init__(self, A, B, x0, xT, horizon, transform, a, yd):
        self.A, self.B, self.x0, self.xT = A, B, x0, xT
        self.horizon = horizon
        self.transform = transform
        self.a = a
        self.yd = yd
        self.z0 = transform @ x0
        self.zT = transform @ xT
        self._ud = feedforward(a, 1.0, yd)

    @property
    def n(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    def _clip(self, t):
        tt, scalar = _times(t)
        return np.clip(tt, 0.0, self.horizon), scalar

    def ud(self, t):
        """Planned input u_d(t) (2.73), the CCF feedforward (2.25) with b = 1."""
        tt, scalar = self._clip(t)
        values = self._ud(tt)
        return float(values[0]) if scalar else values

    def z(self, t) -> np.ndarray:
        """Planned CCF state z = [y_d, y_d', ..., y_d^(n-1)] (2.20)-(2.23), shape (N, n)."""
        tt, scalar = self._clip(t)
        z = np.column_stack([self.yd(tt, k) for k in range(self.n)])
        return z[0] if scalar else z

    def x(self, t) -> np.ndarray:
        """Planned original state x = T^-1 z (2.46), shape (N, n)."""
        # x = T^-1 z, solved rather than inverted
        z = self.z(t)
        return np.linalg.solve(self.transform, z.T).T

    def input(self, t, x=None) -> np.ndarray:
        """``u(t, x)`` for `simulate`: the open-loop input ignores x (t is clipped to [0, T])."""
        tt = min(max(float(t), 0.0), self.horizon)
        # the same u_d as ud(t), (2.25) with b = 1, without re-checking t at every solver step
        y = self.yd._scalar_derivatives(tt, self.n)
        total = y[self.n]
        for i in range(self.n):
            total = total + self.a[i] * y[i]
        return np.array([total])

    def plot(self, samples: int = 301):
        """Figure of the planned states x(t) and the input u_d(t) on [0, T]; returns the figure."""
        t = np.linspace(0.0, self.horizon, int(as_scalar(samples, "samples", positive=True, integer=True)))
        return plot_plan(t, self.x(t), self.ud(t).reshape(-1, 1),
                         title=f"open-loop plan (2.73) from x0 = {self.x0.tolist()} to xT = {self.xT.tolist()}")

    def __repr__(self) -> str:
        return (f"OpenLoopPlan over [0, {self.horizon:g}] from x0 = {self.x0.tolist()} "
                f"to xT = {self.xT.tolist()}; CCF a = {np.round(self.a, 6).tolist()}")


def plot_plan(t, x, u, *, title: str):
    """Two panels: planned states and planned inputs against time (used by the plan objects)."""
    from .style import new_figure
    fig, (ax_x, ax_u) = new_figure(1, 2, figsize=(10, 3.6))
    for i in range(x.shape[1]):
        ax_x.plot(t, x[:, i], label=f"x{i + 1}")
    for j in range(u.shape[1]):
        ax_u.plot(t, u[:, j], label=f"u{j + 1}" if u.shape[1] > 1 else "u_d")
    ax_x.set(title="planned state", xlabel="time t [s]", ylabel="state x [units of x]")
    ax_u.set(title="planned input", xlabel="time t [s]", ylabel="input u [units of u]")
    for ax in (ax_x, ax_u):
        ax.grid(True, alpha=0.4)
        ax.legend()
    fig.suptitle(title)
    return fig


def open_loop_control(A, B, x0, xT, T, *, smooth: int = 0) -> OpenLoopPlan:
    """Open-loop steering of x' = A x + B u from x0 to xT in time T (algorithm (2.73)).

    1. check controllability and compute the CCF transform z = T x (2.59)-(2.65)
       (raises `NotControllableError` otherwise);
    2. translate the task: z0 = T x0, zT = T xT;
    3. plan y_d = z1 as the polynomial of degree 2n - 1 with
       y_d^(k)(0) = z0[k], y_d^(k)(T) = zT[k] (2.31)-(2.38);
    4. apply the feedforward u_d (2.25) with the CCF's a and b = 1.

    ``smooth = s > 0`` adds s more boundary conditions, y_d^(n)..y_d^(n+s-1)
    = 0 at both ends (degree 2(n + s) - 1): then u_d starts and ends at the
    value a . z that holds an equilibrium, without a jump.

    Single input only. Returns an `OpenLoopPlan`.
    """
    A, B = _pair(A, B)
    n = A.shape[0]
    why = f"one per state of the {n}-state system"
    x0 = as_vector(x0, "x0", size=n, why=why)
    xT = as_vector(xT, "xT", size=n, why=why)
    horizon = as_scalar(T, "T", positive=True)
    extra = as_scalar(smooth, "smooth", integer=True)
    if extra < 0:
        raise ValueError(f"smooth must be >= 0: received {smooth!r} (the number of extra zero derivatives).")
    Tz = ccf_transform(A, B)
    a = charpoly(A)
    zeros = np.zeros(int(extra))
    # z0 = T x0, zT = T xT; in the CCF z = [z1, z1', ..., z1^(n-1)]
    yd = poly_trajectory(horizon, np.concatenate([Tz @ x0, zeros]), np.concatenate([Tz @ xT, zeros]))
    return OpenLoopPlan(A, B, x0, xT, horizon, Tz, a, yd)
