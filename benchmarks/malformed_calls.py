"""Count hangs, raw internal errors and silent acceptances over a broad set of malformed calls.

Usage: ``python benchmarks/malformed_calls.py [--verbose]`` (with the coursekit to test on
the path). Each call runs in a worker process under a per-call deadline (signal.alarm);
a worker that does not answer in time is killed and the call counts as a hang.

Verdicts: ``clear`` a ValueError/TypeError (or, for ``warn`` calls, a warning of coursekit's
own classes) whose message names the argument; ``vague`` a ValueError/TypeError that does
not name it, or names the refused type as the wanted one; ``raw`` any other exception;
``silent`` no error (for ``ok`` calls, the good verdict); ``hang`` past the deadline.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time

DEADLINE = 10

SETUP = r'''
import warnings
import numpy as np
import coursekit as ck
from coursekit import models
from coursekit.explorers import ch1 as xp1, ch2 as xp2, ch3 as xp3, ch4 as xp4
import control, scipy.signal as signal, sympy as sp
import matplotlib
matplotlib.use("Agg")
A2 = np.array([[0.0, 1.0], [-2.0, -3.0]]); B2 = np.array([[0.0], [1.0]]); C2 = np.array([[1.0, 0.0]])
P2 = [-1.0, -2.0]; K2 = np.array([[-1.0, -2.0]]); L2 = np.array([[2.0], [1.0]])
T11 = np.linspace(0.0, 1.0, 11); Y11 = np.zeros((11, 1)); U11 = np.zeros((11, 1))
CSYS = control.ss(A2, B2, C2, 0); SSYS = signal.StateSpace(A2, B2, C2, 0)
CSYS_D = control.ss(A2 * 0.1, B2, C2, 0, 0.1); SLTI = signal.lti(A2, B2, C2, 0)
CTF = control.tf([1], [1, 2]); STF = signal.lti([1], [1, 2])
def pend_f(x, u): return np.array([x[1], -9.81 * np.sin(x[0]) + u[0]])
def vdp(mu):
    return ck.NonlinearSystem(lambda x, u: np.array([x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]]), n=2)
rng = np.random.default_rng(0)
A200, B200 = rng.standard_normal((200, 200)), rng.standard_normal((200, 3))
P200 = -np.linspace(1, 20, 200)
x1, x2 = sp.symbols("x1 x2")
SYMF = [x2, -sp.sin(x1)]
T_ILL = np.array([[1.0, 1.0], [1.0, 1.0 + 1e-15]])
ROT = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]
A3, B32 = np.array([[0, 1, 0], [0, 0, 1], [1, 2, 3.0]]), np.array([[0, 1], [1, 0], [0, 1.0]])
'''

# (kind, argument the message must name, call); kind: bad (an error), warn (an error or a
# coursekit warning), ok (must work)
CALLS = [
    # hangs
    ("bad", "method", "ck.simulate(vdp(1e4), np.linspace(0, 100, 11), x0=[2.0, 0.0], method='DOP853')"),
    ("bad", "method", "ck.simulate(vdp(1e5), np.linspace(0, 1000, 11), x0=[2.0, 0.0], method='RK45')"),
    ("bad", "A", "ck.place(A200, B200, P200)"),
    ("bad", "B", "ck.place_details(A200, B200, P200)"),
    ("bad", "substeps", "ck.kalman_bucy(ck.StateSpace(A2, B2, C2), T11, U11, Y11, np.eye(2), [[1.0]], np.eye(2), np.zeros(2), substeps=10**9)"),
    ("bad", "substeps", "ck.extended_kalman_filter(models.pendulum(), T11, U11, Y11, np.eye(2), [[1.0]], np.eye(2), np.zeros(2), substeps=10**9)"),
    ("bad", "substeps", "ck.kalman_bucy(ck.StateSpace(A2, B2, C2), T11, U11, Y11, np.eye(2), [[1.0]], np.eye(2), np.zeros(2), substeps=1e300)"),
    ("bad", "t_end", "xp1.msd_compute(1.0, 0.5, 2.0, t_end=1e300)"),
    ("bad", "t_end", "xp3.pole_placement_compute(t_end=1e300)"),
    ("bad", "t_end", "xp3.upright_pendulum_compute(t_end=1e300)"),
    ("bad", "t_end", "xp3.integral_action_compute(t_end=1e300)"),
    ("bad", "t_end", "xp4.observer_noise_compute(1.0, 0.1, t_end=1e300)"),
    ("bad", "t_end", "xp4.kalman_tuning_compute(0.0, 0.0, t_end=1e300)"),
    ("bad", "T", "xp2.planner_compute(T=1e300)"),
    ("bad", "T", "xp2.robot_planner_compute(T=1e300)"),
    # huge samples / parameters: MemoryError, OverflowError
    ("bad", "samples", "xp1.msd_compute(1.0, 0.5, 2.0, samples=10**12)"),
    ("bad", "samples", "xp3.pole_placement_compute(samples=10**12)"),
    ("bad", "samples", "xp3.upright_pendulum_compute(samples=10**12)"),
    ("bad", "samples", "xp3.integral_action_compute(samples=10**12)"),
    ("bad", "samples", "xp4.observer_noise_compute(1.0, 0.1, samples=10**12)"),
    ("bad", "samples", "xp4.kalman_tuning_compute(0.0, 0.0, samples=10**12)"),
    ("bad", "samples", "xp2.planner_compute(samples=10**12)"),
    ("bad", "samples", "xp2.robot_planner_compute(samples=10**12)"),
    ("bad", "samples", "xp1.euler_compute(0.1, samples=10**12)"),
    ("bad", "samples", "xp1.msd_compute(1.0, 0.5, 2.0, samples=1e300)"),
    ("bad", "samples", "ck.open_loop_control(A2, B2, [0, 0], [1, 0], 2.0).plot(samples=10**12)"),
    ("bad", "log10_q", "xp4.kalman_tuning_compute(400.0, 0.0)"),
    ("bad", "wn", "xp3.pole_placement_compute(wn=1e300)"),
    ("bad", "m", "xp1.msd_compute(1e-300, 0.5, 1e300)"),
    # raw internal errors
    ("bad", "A", "ck.symbolic_ctrb(1.0, 1.0)"),
    ("bad", "A", "ck.symbolic_ctrb(np.zeros((2, 2, 2)), B2)"),
    ("bad", "B", "ck.symbolic_ctrb(A2, np.zeros((2, 1, 1)))"),
    ("bad", "A", "ck.symbolic_linear_flatness(1.0, 1.0)"),
    ("bad", "A", "ck.symbolic_linear_flatness(np.zeros((2, 2, 2)), B2)"),
    ("bad", "values", "ck.symbolic_flat_maps('pendulum').functions()[0]([0.0])"),
    ("bad", "values", "ck.symbolic_flat_maps('pendulum').functions()[1]([0.0, 0.0])"),
    ("bad", "values", "ck.symbolic_flat_maps('pendulum').functions()[0]({'a': 1})"),
    ("bad", "values", "ck.symbolic_flat_maps('two_wheeled').functions()[0]([[0.0], [0.0], [0.0]])"),
    ("bad", "values", "ck.symbolic_flat_maps('pendulum').functions()[0](None)"),
    ("bad", "values", "ck.symbolic_flat_maps('pendulum').functions()[0]('abc')"),
    ("bad", "ax", "ck.plot_state_plane([np.zeros((3, 2))], ax='ax')"),
    ("bad", "ax", "ck.plot_state_plane([np.zeros((3, 2))], ax=3)"),
    # silent acceptances
    ("bad", "x", "ck.StateFeedback(K2)(0.0, np.array([np.nan, 0.0]))"),
    ("bad", "x", "ck.StateFeedback(K2)(0.0, np.array([np.inf, 0.0]))"),
    ("bad", "x", "ck.PendulumLinearizingController(P2)(0.0, np.array([np.nan, 0.0]))"),
    ("bad", "check_equilibrium", "ck.linearize(pend_f, [0.0, 0.0], [0.0], check_equilibrium='no')"),
    ("bad", "check_equilibrium", "ck.linearize(pend_f, [0.0, 0.0], [0.0], check_equilibrium=None)"),
    ("bad", "variables", "ck.symbolic_jacobian(SYMF, [])"),
    ("bad", "variables", "ck.symbolic_jacobian(SYMF, 'x1 x2')"),
    ("bad", "x", "ck.linearize_symbolic(SYMF, [], x_eq=[])"),
    ("bad", "x", "ck.linearize_symbolic(SYMF, 'x1 x2', x_eq=[0, 0])"),
    ("bad", "f", "ck.symbolic_jacobian([], [x1, x2])"),
    ("bad", "t", "ck.plot_plan(T11[::-1], np.zeros((11, 2)), np.zeros((11, 1)), title='plan')"),
    ("warn", "T", "ck.similarity_transform(ck.StateSpace(A2, B2, C2), T_ILL)"),
    ("warn", "A", "ck.place(A2 * 1e200, B2, P2)"),
    # smaller messages
    ("bad", "dt", "ck.StateSpace(A2, B2, C2, dt=0)", "dt=None"),
    ("bad", "u_eq", "ck.linearize(pend_f, [0.0, 0.0])"),
    ("bad", "m", "ck.equilibrium_input(pend_f, [0.0, 0.0], m=0)"),
    ("bad", "Q", "ck.kalman_gain([[0.0, 1.0], [0.0, 0.0]], [[1.0, 0.0]], np.zeros((2, 2)), [[1.0]])", "no_repeat"),
    ("bad", "Q", "ck.kalman_gain(ROT @ np.diag([0.0, -1.0, -2.0]) @ ROT.T, np.array([[1.0, 0, 0]]) @ ROT.T, np.zeros((3, 3)), [[1.0]])", "no_repeat"),
    # systems of the neighbouring libraries: accepted, or the bridge named
    ("ok", "", "ck.simulate(CSYS, T11)"),
    ("ok", "", "ck.simulate(SSYS, T11)"),
    ("ok", "", "ck.simulate(SLTI, T11)"),
    ("ok", "", "ck.simulate(CSYS_D, np.arange(11) * 0.1)"),
    ("ok", "", "ck.is_stable(CSYS)"),
    ("ok", "", "ck.is_stable(SSYS)"),
    ("ok", "", "ck.place(CSYS.A, CSYS.B, P2)"),
    ("ok", "", "ck.simulate_batch(CSYS, T11, np.zeros((2, 2)))"),
    ("ok", "", "ck.euler_discretize(CSYS, 0.1)"),
    ("ok", "", "ck.cascade(CSYS, SSYS)"),
    ("ok", "", "ck.feedback(CSYS, CSYS)"),
    ("ok", "", "ck.similarity_transform(CSYS, np.eye(2))"),
    ("ok", "", "ck.observer_system(CSYS, L2)"),
    ("ok", "", "ck.plant_with_observer(SSYS, L2)"),
    ("ok", "", "ck.output_feedback(CSYS, K2, L2)"),
    ("ok", "", "ck.separation_eigenvalues(CSYS, K2, L2)"),
    ("ok", "", "ck.kalman_bucy(CSYS, T11, U11, Y11, np.eye(2), [[1.0]], np.eye(2), np.zeros(2))"),
    ("ok", "", "ck.discrete_kalman_filter(CSYS_D, Y11, None, Q=np.eye(2), R=[[1.0]], P0=np.eye(2), x0=np.zeros(2))"),
    ("ok", "", "ck.simulate_with_noise(CSYS, T11, Q=np.eye(2), R=[[1.0]], seed=0)"),
    ("ok", "", "ck.with_integrators(CSYS, C2)"),
    ("ok", "", "ck.linearize(CSYS, [0.0, 0.0], [0.0])"),
    ("ok", "", "ck.find_equilibria(CSYS, u_eq=[0.0])"),
    ("bad", "A", "ck.place(CSYS, B2, P2)", "from_control"),
    ("bad", "A", "ck.ctrb(CSYS, B2)", "from_control"),
    ("bad", "A", "ck.is_controllable(SSYS, B2)", "from_scipy"),
    ("bad", "A", "ck.obsv(CSYS, C2)", "from_control"),
    ("bad", "A", "ck.kalman_gain(CSYS, C2, np.eye(2), [[1.0]])", "from_control"),
    ("bad", "sys", "ck.simulate(CTF, T11)", "from_control|control.ss"),
    ("bad", "sys", "ck.simulate(STF, T11)", "from_scipy|to_ss"),
    ("bad", "A", "ck.is_stable(CTF)", "from_control|control.ss"),
    ("bad", "sys", "ck.simulate(control.ss(A2, B2, C2, 0, True), T11)", "from_control"),
    ("bad", "sys", "ck.observer_system(control.ss(A2, B2, C2, 0, 0.1), L2)"),
    # more of the same kinds
    ("bad", "method", "ck.simulate(vdp(1e4), np.linspace(0, 1000, 11), x0=[2.0, 0.0], method='RK23')"),
    ("bad", "method", "ck.simulate_batch(vdp(1e4), np.linspace(0, 1000, 11), [[2.0, 0.0], [2.0, 0.1]])"),
    ("bad", "A", "ck.place_observer(A200, B200.T, P200)"),
    ("bad", "x", "ck.TrackingController(K2, lambda t: np.zeros(2), lambda t: np.zeros(1))(0.0, np.array([np.nan, 0.0]))"),
    ("bad", "x_E", "ck.IntegralFeedback(np.array([[-1.0, -2.0, -3.0]]), 1)(0.0, np.array([0.0, np.nan, 0.0]))"),
    ("bad", "dt", "ck.NonlinearSystem(lambda x, u: -x, n=1, dt=0)", "dt=None"),
    ("bad", "dt", "ck.is_stable(A2, dt=0)", "dt=None"),
    ("bad", "dt", "ck.kalman_gain(A2, C2, np.eye(2), [[1.0]], dt=0)", "dt=None"),
    ("bad", "u_eq", "ck.find_equilibria(pend_f, n=2)"),
    ("bad", "check_equilibrium", "ck.linearize(pend_f, [0.0, 0.0], [0.0], check_equilibrium=1)"),
    ("bad", "A", "ck.symbolic_linear_flatness(np.float64(1.0), [[1.0]])"),
    ("bad", "ax", "ck.plot_poles([-1.0], ax=3)"),
    ("bad", "poles", "ck.place(A2, B2, [10**400, -1.0])"),
    ("bad", "x0", "ck.simulate(ck.StateSpace(A2, B2, C2), T11, x0=[10**400, 0.0])"),
    ("bad", "A", "ck.StateSpace([[10**400]])"),
    ("bad", "T", "ck.poly_trajectory(10**400, [0.0], [1.0])"),
    ("ok", "", "ck.white_noise(T11, 1.0, seed=10**400)"),   # numpy takes any integer as a seed
    ("bad", "wn", "xp3.pair_poles(10**400, 0.7)"),
    ("bad", "A", "ck.place_details(CSYS, B2, P2)", "from_control"),
    ("bad", "sys2", "ck.feedback(CSYS, STF)", "from_scipy|to_ss"),
    ("bad", "sys", "ck.observer_system(signal.StateSpace(A2 * 0.1, B2, C2, 0, dt=0.1), L2)"),
    ("bad", "t", "ck.kalman_bucy(CSYS, T11[::-1], U11, Y11, np.eye(2), [[1.0]], np.eye(2), np.zeros(2))"),
    ("bad", "T", "ck.similarity_transform(SSYS, np.ones((2, 2)))"),
    ("bad", "values", "ck.symbolic_flat_maps('car_like', L=2.5).functions()[0]([1.0, 2.0])"),
    ("bad", "variables", "ck.symbolic_jacobian(SYMF, [x1, 'x2'])"),
    ("bad", "u", "ck.linearize_symbolic(SYMF, [x1, x2], 'u', x_eq=[0, 0])"),
    ("bad", "samples", "ck.plan_flat_output(ck.pendulum_flatness(), 2.0, [0.0, 0.0], [1.0, 0.0]).plot(samples=10**12)"),
    ("ok", "", "ck.simulate(vdp(1e4), np.linspace(0, 1000, 11), x0=[2.0, 0.0], method='Radau')"),
    ("ok", "", "ck.place(A2 * 1e6, B2, P2)"),
    ("ok", "", "ck.similarity_transform(ck.StateSpace(A2, B2, C2), [[1.0, 1.0], [0.0, 1e-4]])"),
    ("ok", "", "ck.linearize(lambda x, u: np.array([(1.6 + x[0]) * 16.8 - 1.6 * 16.8]), [0.0])"),
    # issue 35: a hang, raw errors, NaN/inf answers, malformed arguments, quiet misses
    ("bad", "method", "ck.simulate(vdp(1e4), np.linspace(0, 100, 11), x0=[1.0, 0.0], method='DOP853')", "stiff"),
    ("ok", "", "ck.plan_robot([0, 0, 0], [4, 2, 1.5], 1e300)"),
    ("bad", "f", "ck.symbolic_equilibria([-x1 + 10 * sp.sin(x1)], [x1])", "find_equilibria"),
    ("bad", "f", "ck.symbolic_equilibria([-x1 - sp.sin(x1)], [x1], discrete=True)", "find_equilibria"),
    ("ok", "", "xp3.pair_poles(2.0, 1e300)"),
    ("bad", "zeta", "xp3.pole_placement_compute(zeta=1e300)"),
    ("bad", "noise_std", "xp4.observer_noise_compute(1.0, 1e300)"),
    ("bad", "x_T", "xp2.robot_planner_compute(x_T=1e300)"),
    ("bad", "speed", "xp2.robot_planner_compute(speed=1e300)"),
    ("bad", "T", "ck.poly_trajectory(1e-300, [0.0, 0.0], [1.0, 0.0])"),
    ("bad", "T", "ck.open_loop_control(A2, B2, [0, 0], [1, 0], 1e-300)"),
    ("bad", "T", "ck.plan_flat_output(ck.pendulum_flatness(), 1e-300, [0.0, 0.0], [1.0, 0.0])"),
    ("bad", "T", "ck.plan_robot([0, 0, 0], [4, 2, 1.5], 1e-300)"),
    ("bad", "A", "ck.charpoly(A2 * 1e200)"),
    ("bad", "A", "ck.linear_flatness(A2 * 1e200, B2 * 1e200)"),
    ("bad", "A", "ck.place_details(A2 * 1e200, B2 * 1e200, P2)"),
    ("bad", "A", "ck.place_observer_details(A2 * 1e200, C2 * 1e200, P2)"),
    ("bad", "t", "ck.simulate_with_noise(ck.StateSpace([[1.0]], [[1.0]], [[1.0]]), np.linspace(0, 1000, 1001), "
     "x0=[1.0], Q=[[1.0]], R=[[1.0]], seed=0)", "float range"),
    ("warn", "poles", "ck.place(A3, B32, [-2.0] * 3)"),
    ("warn", "poles", "ck.place_observer(A3, B32.T, [-2.0] * 3)"),
    ("warn", "A", "ck.ccf_transform(np.random.default_rng(0).normal(size=(30, 30)), "
     "np.random.default_rng(1).normal(size=(30, 1)))"),
    ("ok", "", "ck.lti_step_matrices(A2, B2 * 1e200, 0.1)"),
    ("bad", "B", "ck.lti_step_matrices(A2, np.zeros((2, 0)), 0.1)"),
    ("bad", "B", "ck.integral_augment(A2, np.zeros((2, 0)), C2)"),
    ("bad", "B", "ck.symbolic_ctrb(A2, np.zeros((2, 0)))"),
    ("bad", "x", "ck.plot_plan(T11, np.zeros((11, 0)), U11, title='plan')"),
    ("bad", "labels", "ck.plot_state_plane([np.zeros((3, 2)), np.ones((3, 2))], labels='ab')"),
    ("bad", "state", "ck.plot_euler_comparison(ck.simulate(ck.StateSpace(A2, B2, C2), T11, u=U11 + 1), "
     "[ck.simulate(ck.euler_discretize(ck.StateSpace(A2, B2, C2), 0.1), T11, u=U11 + 1)], state=[0])"),
    ("bad", "x_d", "ck.TrackingController(K2, lambda t: np.zeros(2) + (1j if t > 1 else 0), "
     "lambda t: np.zeros(1))(2.0, np.zeros(2))"),
    ("bad", "traj", "ck.feedforward([2.0, 3.0], 1.0, lambda t, k=0: np.nan if k == 2 else 0.0)"),
    ("bad", "f", "ck.symbolic_jacobian([x1 * sp.nan, x2], [x1, x2])"),
    ("bad", "u_eq", "ck.linearize_symbolic([x2], [x1], u=[x2], x_eq=[0], u_eq='a')"),
    ("bad", "variables", "ck.symbolic_jacobian([x1, x2, x1, x2], sp.Matrix(2, 2, sp.symbols('y1:5')))"),
    ("bad", "m", "ck.symbolic_flat_maps('pendulum', m=0.0)"),
    ("bad", "derivs", "ck.pendulum_flatness().psi_u(np.array([0.1 + 1j, 0.0, 0.0]))"),
    ("ok", "", "ck.StateFeedback(K2)(0.0, sp.Matrix([1, 2])).shape == (1,) or 1 / 0"),
    ("ok", "", "ck.PendulumLinearizingController(P2)(0.0, sp.Matrix([1, 2])).shape == (1,) or 1 / 0"),
]


def _worker() -> None:
    import signal
    import traceback
    import warnings
    ns: dict = {}
    exec(SETUP, ns)

    def alarm(*_):
        raise TimeoutError("deadline")

    signal.signal(signal.SIGALRM, alarm)
    for line in sys.stdin:
        i = int(line)
        kind, arg, expr, *extra = CALLS[i]
        print(json.dumps({"start": i}), flush=True)
        signal.alarm(DEADLINE)
        caught = []
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                eval(expr, ns)
            error = None
        except TimeoutError:
            error = ("hang", "")
        except BaseException as err:  # the verdict's data
            tb = traceback.extract_tb(err.__traceback__)[-1]
            error = (type(err).__name__, f"{err} (at {tb.filename.split('/')[-1]}:{tb.lineno})",
                     isinstance(err, (ValueError, TypeError)))
        finally:
            signal.alarm(0)
        ours = [str(w.message) for w in caught if type(w.message).__module__.startswith("coursekit")]
        print(json.dumps({"done": i, "error": error, "warnings": ours}), flush=True)
        import matplotlib.pyplot as plt
        plt.close("all")


def _verdict(call, record) -> tuple[str, str]:
    kind, arg, expr, *extra = call
    error, ours = record["error"], record["warnings"]
    if error and error[0] == "hang":
        return "hang", ""
    if kind == "ok":
        if error is None:
            return "silent", ""
        return ("refused" if error[2] else "raw"), f"{error[0]}: {error[1]}"
    if error is None:
        if kind == "warn" and ours:
            return "clear", ours[0]
        return "silent", ""
    name, text = error[0], error[1]
    if not error[2]:
        return "raw", f"{name}: {text}"
    named = re.search(rf"(?<!\w){re.escape(arg)}(?!\w)", text)
    if extra and extra[0] == "no_repeat":
        sentences = [s for s in re.split(r"(?<=\.) ", text) if len(s) > 40]
        repeated = len(sentences) != len(set(sentences)) or re.search(r"\d\.\de-1[5-9]", text)
        return ("vague" if repeated or not named else "clear"), text
    if extra and not re.search(extra[0], text):
        return "vague", f"{name}: {text}"
    wanted_as_received = re.search(r"must be an? (\w+).*received (\w+)\b", text)
    if wanted_as_received and wanted_as_received.group(1) == wanted_as_received.group(2):
        return "vague", f"{name}: {text}"
    return ("clear" if named else "vague"), f"{name}: {text}"


def run() -> dict:
    verdicts: dict[int, tuple[str, str]] = {}
    todo = list(range(len(CALLS)))
    while todo:
        proc = subprocess.Popen([sys.executable, __file__, "--worker"], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, text=True)
        proc.stdin.write("\n".join(map(str, todo)) + "\n")
        proc.stdin.close()
        current, deadline = None, None
        import selectors
        sel = selectors.DefaultSelector()
        sel.register(proc.stdout, selectors.EVENT_READ)
        while True:
            if not sel.select(timeout=DEADLINE + 60 if current is None else DEADLINE + 5):
                proc.kill()
                break
            line = proc.stdout.readline()
            if not line:
                break
            try:
                record = json.loads(line)
            except ValueError:
                continue
            if "start" in record:
                current = record["start"]
            elif "done" in record:
                verdicts[record["done"]] = _verdict(CALLS[record["done"]], record)
                current = None
        proc.wait()
        if current is not None:
            verdicts[current] = ("hang", "worker killed")
        todo = [i for i in todo if i not in verdicts]
    return verdicts


def main() -> None:
    if "--worker" in sys.argv:
        return _worker()
    start = time.time()
    verdicts = run()
    counts: dict[str, int] = {}
    for i, (verdict, detail) in sorted(verdicts.items()):
        kind = CALLS[i][0]
        key = "works" if kind == "ok" and verdict == "silent" else verdict
        counts[key] = counts.get(key, 0) + 1
        if "--verbose" in sys.argv and key not in ("clear", "works"):
            print(f"{key:7s} {CALLS[i][2]}\n        {detail[:300]}")
    print(f"{len(CALLS)} calls in {time.time() - start:.0f} s:", json.dumps(counts, sort_keys=True))


if __name__ == "__main__":
    main()
