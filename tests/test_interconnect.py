"""cascade and feedback: the notes' block forms, hand-connected simulations, python-control."""

import numpy as np
import pytest
from hypothesis import assume, given, strategies as st

import coursekit as ck

def _random_ss(n, m, p, *, with_d=True, dt=None, seed=None):
    r = np.random.default_rng(seed)
    D = r.normal(size=(p, m)) if with_d else np.zeros((p, m))
    return ck.StateSpace(r.normal(size=(n, n)) - 2 * np.eye(n), r.normal(size=(n, m)),
                         r.normal(size=(p, n)), D, dt=dt)


def _hand_connected(sys1, sys2, kind, sign=1.0):
    """The two subsystems written as one nonlinear system, connected inside f."""
    n1, n2 = sys1.n, sys2.n
    assert np.allclose(sys1.D, 0) or kind == "cascade"

    def f(x, u):
        x1, x2 = x[:n1], x[n1:]
        if kind == "cascade":
            y1 = sys1.C @ x1 + sys1.D @ u
            return np.r_[sys1.A @ x1 + sys1.B @ u, sys2.A @ x2 + sys2.B @ y1]
        y1 = sys1.C @ x1                       # D1 = 0: no algebraic loop
        y2 = sys2.C @ x2 + sys2.D @ y1
        u1 = u + sign * y2
        return np.r_[sys1.A @ x1 + sys1.B @ u1, sys2.A @ x2 + sys2.B @ y1]

    def h(x, u):
        x1, x2 = x[:n1], x[n1:]
        y1 = sys1.C @ x1 + sys1.D @ u
        return sys2.C @ x2 + sys2.D @ y1 if kind == "cascade" else y1

    return ck.NonlinearSystem(f, n=n1 + n2, m=sys1.m, h=h)


def test_cascade_with_state_as_input_is_1_38():
    A1, B1 = np.array([[-1.0, 2], [0, -3]]), np.array([[1.0], [1]])
    A2, B2 = np.array([[-0.5]]), np.array([[1.0, -1.0]])
    s1 = ck.StateSpace(A1, B1)                 # C1 = I: u2 = x1 (1.35)
    s2 = ck.StateSpace(A2, B2)
    c = ck.cascade(s1, s2)
    np.testing.assert_array_equal(c.A, np.block([[A1, np.zeros((2, 1))], [B2, A2]]))
    np.testing.assert_array_equal(c.B, np.vstack([B1, np.zeros((1, 1))]))


def test_cascade_other_order_is_1_39_with_input_matrix_0_B2():
    A1, B1 = np.array([[-1.0]]), np.array([[2.0]])
    A2, B2 = np.array([[-3.0]]), np.array([[5.0]])
    c = ck.cascade(ck.StateSpace(A2, B2), ck.StateSpace(A1, B1))
    # state [x2; x1]; reorder to the notes' [x1; x2]
    P = np.array([[0, 1], [1, 0]])
    np.testing.assert_array_equal(P @ c.A @ P, [[-1, 2], [0, -3]])
    np.testing.assert_array_equal(P @ c.B, [[0], [5]])


def test_feedback_with_identity_outputs_is_1_40():
    A1, B1 = np.array([[-1.0, 1], [0, -2]]), np.array([[0.0, 1], [1, 0]])
    A2, B2 = np.array([[-4.0, 0], [1, -1]]), np.array([[1.0, 0], [0, 2]])
    fb = ck.feedback(ck.StateSpace(A1, B1), ck.StateSpace(A2, B2))
    np.testing.assert_array_equal(fb.A, np.block([[A1, B1], [B2, A2]]))
    np.testing.assert_array_equal(fb.B, np.vstack([B1, np.zeros((2, 2))]))


@pytest.mark.parametrize("m", [1, 2])
def test_cascade_equals_hand_connected_simulation(m):
    s1 = _random_ss(2, m, 2, seed=1)
    s2 = _random_ss(3, 2, 1, seed=2)
    t = np.linspace(0, 5, 101)
    u = np.column_stack([np.sin(2 * t), np.cos(t)])[:, :m]
    x0 = np.array([1.0, -1, 0.5, 0, 2])
    combined = ck.simulate(ck.cascade(s1, s2), t, u, x0=x0)
    # the same input as the array: linear between the samples
    hand = ck.simulate(_hand_connected(s1, s2, "cascade"), t,
                       lambda tk, xk: np.array([np.interp(tk, t, u[:, j]) for j in range(m)]), x0=x0)
    np.testing.assert_allclose(combined.x, hand.x, atol=1e-7)
    np.testing.assert_allclose(combined.y, hand.y, atol=1e-7)


@pytest.mark.parametrize("sign", [1, -1])
def test_feedback_equals_hand_connected_simulation(sign):
    s1 = _random_ss(2, 1, 2, with_d=False, seed=3)
    s2 = _random_ss(2, 2, 1, seed=4)
    t = np.linspace(0, 3, 61)
    x0 = np.array([0.5, -1, 1, 0])
    fb = ck.feedback(s1, s2, sign=sign)
    combined = ck.simulate(fb, t, np.sin(t)[:, None], x0=x0)
    hand = ck.simulate(_hand_connected(s1, s2, "feedback", sign), t,
                       lambda tk, xk: np.array([np.interp(tk, t, np.sin(t))]), x0=x0)
    scale = max(1.0, np.abs(hand.x).max())
    np.testing.assert_allclose(combined.x, hand.x, atol=1e-7 * scale)
    np.testing.assert_allclose(combined.y, hand.y, atol=1e-7 * scale)


def test_discrete_feedback_equals_hand_written_loop():
    s1 = ck.StateSpace([[0.5]], [[1.0]], [[1.0]], dt=1.0)
    s2 = ck.StateSpace([[0.2]], [[1.0]], [[-0.3]], [[0.1]], dt=1.0)
    fb = ck.feedback(s1, s2)
    N = 15
    r = np.cos(np.arange(N))
    res = ck.simulate(fb, np.arange(N), r[:, None], x0=[1.0, -1.0])
    x1, x2, ys = 1.0, -1.0, []
    for k in range(N):
        y1 = x1
        ys.append(y1)
        u1 = r[k] + (-0.3 * x2 + 0.1 * y1)
        x1, x2 = 0.5 * x1 + u1, 0.2 * x2 + y1
    np.testing.assert_allclose(res.y[:, 0], ys, atol=1e-12)


@given(st.integers(0, 10_000), st.sampled_from([1, -1]))
def test_feedback_matches_python_control(seed, sign):
    control = pytest.importorskip("control")
    s1 = _random_ss(2, 2, 2, seed=seed)
    s2 = _random_ss(2, 2, 2, seed=seed + 1)
    loop = np.eye(2) - sign * s1.D @ s2.D
    assume(np.linalg.cond(loop) < 1e6)
    fb = ck.feedback(s1, s2, sign=sign)
    ref = control.feedback(control.ss(s1.A, s1.B, s1.C, s1.D), control.ss(s2.A, s2.B, s2.C, s2.D), sign=sign)
    for s in (0.5j, 1.0 + 2j):
        mine = fb.C @ np.linalg.solve(s * np.eye(4) - fb.A, fb.B) + fb.D
        # skip frequencies next to a pole of the loop
        assume(np.min(np.abs(np.linalg.eigvals(fb.A) - s)) > 1e-3)
        np.testing.assert_allclose(mine, ref(s), rtol=1e-6, atol=1e-8)


@given(st.integers(0, 10_000))
def test_cascade_matches_python_control(seed):
    control = pytest.importorskip("control")
    s1 = _random_ss(2, 1, 2, seed=seed)
    s2 = _random_ss(3, 2, 2, seed=seed + 1)
    c = ck.cascade(s1, s2)
    ref = control.series(control.ss(s1.A, s1.B, s1.C, s1.D), control.ss(s2.A, s2.B, s2.C, s2.D))
    for s in (0.5j, 1.0 + 2j):
        mine = c.C @ np.linalg.solve(s * np.eye(5) - c.A, c.B) + c.D
        np.testing.assert_allclose(mine, ref(s), rtol=1e-6, atol=1e-8)


def test_singular_algebraic_loop_is_explained():
    s1 = ck.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[1.0]])
    s2 = ck.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[1.0]])
    with pytest.raises(ValueError, match="algebraic loop"):
        ck.feedback(s1, s2, sign=+1)
    ck.feedback(s1, s2, sign=-1)  # I + D1 D2 = 2: fine


@pytest.mark.parametrize("call, match", [
    (lambda: ck.cascade(ck.StateSpace([[-1.0]], [[1.0]], [[1.0], [2.0]]), ck.StateSpace([[-1.0]], [[1.0]])),
     "sys2 has the wrong number of inputs"),
    (lambda: ck.cascade(ck.StateSpace([[-1.0]], [[1.0]]), ck.StateSpace([[-1.0]], [[1.0]], dt=1.0)),
     "same dt"),
    (lambda: ck.cascade(np.eye(1), ck.StateSpace([[-1.0]], [[1.0]])), "sys1 must be a StateSpace"),
    (lambda: ck.feedback(ck.StateSpace([[-1.0]], [[1.0]]), ck.StateSpace([[-1.0]], [[1.0]]), sign=2),
     "sign must be"),
    (lambda: ck.feedback(ck.StateSpace([[-1.0]], [[1.0]]),
                         ck.StateSpace([[-1.0]], [[1.0]], [[1.0], [1.0]])),
     "sys1 has the wrong number of inputs"),
])
def test_bad_input_raises_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
