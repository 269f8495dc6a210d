"""simulate and simulate_batch on the error path: no hang, no crash, errors with context.

The cases that used to hang (NaN from a model or an input, NaN or zero
tolerances) run in one child interpreter, each under its own alarm and the
whole under a subprocess timeout, so a regression fails the test instead of
hanging the suite.
"""

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import coursekit as ck

# generous: each case takes well under a second; the alarm only has to catch a hang
PER_CASE_SECONDS = 30

# name: (statement, expected exception class name, regex its message must match)
ISOLATED = {
    "f NaN at the start (the sqrt example)": (
        "ck.simulate(ck.NonlinearSystem(lambda x, u: -np.sqrt(x), n=1), np.linspace(0, 1, 11), x0=[-1.0])",
        "UserFunctionError", r"f returned NaN or inf at t = 0, x = \[-1\.\]"),
    "f NaN later (x reaches 1 near t = 0.6)": (
        "ck.simulate(ck.NonlinearSystem(lambda x, u: np.sqrt(1 - x) + 1, n=1), np.linspace(0, 1, 11), x0=[0.0])",
        "UserFunctionError", r"f returned NaN or inf at t = 0\.\d+, x = \[1\.0"),
    "stiff Van der Pol, mu = 1e4, explicit method (issue 25: hung)": (
        "ck.simulate(ck.NonlinearSystem(lambda x, u: np.array([x[1], 1e4 * (1 - x[0] ** 2) * x[1] - x[0]]), n=2), "
        "np.linspace(0, 100, 11), x0=[2.0, 0.0], method='DOP853')",
        "SimulationError", r"method='DOP853' cannot finish in bounded work: .*\|lambda\| = 3e\+04(?s:.*)method='Radau'"),
    "f NaN later, Radau": (
        "ck.simulate(ck.NonlinearSystem(lambda x, u: np.sqrt(1 - x) + 1, n=1), np.linspace(0, 1, 11), "
        "x0=[0.0], method='Radau')",
        "UserFunctionError", r"f returned NaN or inf at t = 0\.\d+"),
    "f NaN later, LSODA": (
        "ck.simulate(ck.NonlinearSystem(lambda x, u: np.sqrt(1 - x) + 1, n=1), np.linspace(0, 1, 11), "
        "x0=[0.0], method='LSODA')",
        "UserFunctionError", r"f returned NaN or inf at t = 0\.\d+"),
    "u NaN at the first call": (
        "ck.simulate(ck.StateSpace([[-1.0]], [[1.0]]), np.linspace(0, 1, 11), u=lambda t, x: [np.nan])",
        "UserFunctionError", r"u returned NaN or inf at t = 0, x = \[0\.\]"),
    "u NaN after t = 0.5": (
        "ck.simulate(ck.StateSpace([[-1.0]], [[1.0]]), np.linspace(0, 1, 11), "
        "u=lambda t, x: [np.nan if t > 0.5 else 0.0])",
        "UserFunctionError", r"u returned NaN or inf at t = 0\.[5-9]\d*, x = \[0\.\]"),
    "rtol NaN": (
        "ck.simulate(ck.models.pendulum(), np.linspace(0, 1, 11), x0=[1, 0], rtol=np.nan)",
        "ValueError", r"rtol contains NaN"),
    "atol NaN": (
        "ck.simulate(ck.models.pendulum(), np.linspace(0, 1, 11), x0=[1, 0], atol=np.nan)",
        "ValueError", r"atol contains NaN"),
    "rtol 0": (
        "ck.simulate(ck.models.pendulum(), np.linspace(0, 1, 11), x0=[1, 0], rtol=0)",
        "ValueError", r"rtol must be between 2\.2e-14 .* received 0\.0"),
    "atol 0": (
        "ck.simulate(ck.models.pendulum(), np.linspace(0, 1, 11), x0=[1, 0], atol=0)",
        "ValueError", r"atol must be > 0: received \[0\.\]"),
    "batch: f NaN at the start": (
        "ck.simulate_batch(ck.NonlinearSystem(lambda x, u: -np.sqrt(x), n=1), np.linspace(0, 1, 11), "
        "[[1.0], [-1.0]])",
        "UserFunctionError", r"f returned NaN or inf at t = 0, x = \[-1\.\] \(x0s\[1\]\)"),
    "batch: f NaN later": (
        "ck.simulate_batch(ck.NonlinearSystem(lambda x, u: np.sqrt(1 - x) + 1, n=1), np.linspace(0, 1, 11), "
        "[[-5.0], [0.0]])",
        "UserFunctionError", r"f returned NaN or inf at t = 0\.\d+, x = \[1\.0.*\(trajectory 1, from x0s\[1\]\)"),
    "batch: u NaN later": (
        "ck.simulate_batch(ck.models.pendulum(), np.linspace(0, 1, 11), [[0, 0], [1, 0]], "
        "u=lambda t, X: X[:1] * (np.nan if t > 0.5 else 1.0))",
        "UserFunctionError", r"u returned NaN or inf at t = 0\.[5-9]\d* on the batch X of shape \(2, 2\)"),
    "batch: atol 0": (
        "ck.simulate_batch(ck.models.pendulum(), np.linspace(0, 1, 11), [[0, 0], [1, 0]], atol=0)",
        "ValueError", r"atol must be > 0"),
    "tracking controller: x_d NaN later": (
        "ck.simulate(ck.models.mass_spring_damper(), np.linspace(0, 1, 11), x0=[0, 0], "
        "u=ck.TrackingController([[-1.0, -1.0]], lambda t: [0.0, np.nan if t > 0.5 else 0.0], lambda t: [0.0]))",
        "UserFunctionError", r"u raised UserFunctionError at t = 0\.[5-9].*x_d returned NaN or inf at t = 0\.[5-9]"),
}

RUNNER = f"""
import json, signal, sys
import numpy as np
import coursekit as ck

class Hang(BaseException):    # not an Exception: no `except Exception` may swallow it
    pass

def on_alarm(*_):
    raise Hang()

alarm = hasattr(signal, "SIGALRM")
if alarm:
    signal.signal(signal.SIGALRM, on_alarm)
for name, code in json.loads(sys.stdin.read()).items():
    if alarm:
        signal.alarm({PER_CASE_SECONDS})
    try:
        exec(code, {{"np": np, "ck": ck}})
        kind, message = "no error", ""
    except Hang:
        kind, message = "hang", "no answer within {PER_CASE_SECONDS} s"
    except Exception as err:
        kind, message = type(err).__name__, str(err)
    finally:
        if alarm:
            signal.alarm(0)
    print(json.dumps([name, kind, message]), flush=True)
"""


@pytest.fixture(scope="module")
def isolated_results():
    cases = json.dumps({name: code for name, (code, _, _) in ISOLATED.items()})
    try:
        out = subprocess.run([sys.executable, "-c", RUNNER], input=cases, capture_output=True,
                             text=True, timeout=PER_CASE_SECONDS * len(ISOLATED) + 60).stdout
    except subprocess.TimeoutExpired as expired:   # a hang in compiled code, out of the alarm's reach
        out = expired.stdout or ""
        out = out.decode() if isinstance(out, bytes) else out
    return {name: (kind, message) for name, kind, message in map(json.loads, out.splitlines())}


@pytest.mark.parametrize("name", list(ISOLATED))
def test_error_path_answers_with_a_clear_error(name, isolated_results):
    _, kind, pattern = ISOLATED[name]
    assert name in isolated_results, f"{name!r}: no answer (the child hung or crashed)"
    got, message = isolated_results[name]
    assert got == kind, f"{name!r}: {got}: {message}"
    assert re.search(pattern, message), message


# ---------------------------------------------------------------- exceptions at later times

def test_an_exception_in_f_during_integration_is_wrapped_with_time_and_state():
    sys = ck.NonlinearSystem(lambda x, u: [1.0] if x[0] < 0.5 else [1 / 0], n=1)
    with pytest.raises(ck.UserFunctionError, match=r"f raised ZeroDivisionError at t = 0\.5\d*, "
                                                    r"x = \[0\.5\d*\]") as info:
        ck.simulate(sys, np.linspace(0, 1, 11), x0=[0.0])
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_an_exception_in_u_during_integration_is_wrapped():
    pend = ck.models.pendulum()
    with pytest.raises(ck.UserFunctionError, match=r"u raised KeyError at t = 0\.[3-9]"):
        ck.simulate(pend, np.linspace(0, 1, 11), u=lambda t, x: [0.0] if t < 0.3 else {}["missing"],
                    x0=[1.0, 0.0])


def test_a_wrong_return_size_later_is_explained_with_the_time():
    sys = ck.NonlinearSystem(lambda x, u: [1.0] if x[0] < 0.5 else [1.0, 2.0], n=1)
    with pytest.raises(ValueError, match=r"f returned shape \(2,\); expected 1 numbers.*at t = 0\.5"):
        ck.simulate(sys, np.linspace(0, 1, 11), x0=[0.0])


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")   # log(negative)
def test_an_output_map_failing_later_is_named_with_the_time():
    sys = ck.NonlinearSystem(lambda x, u: [1.0], n=1, h=lambda x, u: np.log(1 - x))
    with pytest.raises(ck.UserFunctionError, match=r"h returned NaN or inf at t = 1\.2, x = \[1\.2\]"):
        ck.simulate(sys, np.linspace(0, 2, 11), x0=[0.0])


def test_an_output_map_failing_at_the_start_is_caught_before_integrating():
    calls = []
    sys = ck.NonlinearSystem(lambda x, u: calls.append(1) or [1.0], n=1, h=lambda x, u: 1 / 0)
    with pytest.raises(ck.UserFunctionError, match=r"h raised ZeroDivisionError at t = 0"):
        ck.simulate(sys, np.linspace(0, 1, 11))
    assert len(calls) == 1        # f was only called by the check, not integrated


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")   # sqrt(negative)
def test_discrete_map_nan_names_the_step():
    sys = ck.NonlinearSystem(lambda x, u: np.sqrt(x - 1), n=1, dt=1)
    with pytest.raises(ck.UserFunctionError, match=r"f returned NaN or inf at t = 3, x = \[0\.\]"):
        ck.simulate(sys, np.arange(10.0), x0=[5.0])


def test_batch_wraps_an_exception_from_u():
    with pytest.raises(ck.UserFunctionError, match=r"u raised ZeroDivisionError at t = 0 on the batch"):
        ck.simulate_batch(ck.models.pendulum(), np.linspace(0, 1, 5), [[0, 0], [1, 0]], u=lambda t, X: 1 / 0)


# ---------------------------------------------------------------- solver options

@pytest.mark.parametrize("options, message", [
    (dict(rtol=1e-16), r"rtol must be between 2\.2e-14 .* received 1e-16"),
    (dict(rtol=1.0), r"rtol must be between .* and 1: received 1\.0"),
    (dict(rtol=[1e-6, 1e-6]), r"rtol must be a single number"),
    (dict(atol=-1e-9), r"atol must be > 0"),
    (dict(atol=[1e-9, 1e-9, 1e-9]), r"atol must be one number or one per state \(2\): received 3"),
    (dict(method="rk45"), r"method must be one of 'RK45', .* received 'rk45' \(did you mean 'RK45'\?"),
    (dict(method="Euler"), r"method must be one of .*'LSODA'.* received 'Euler'\.$"),
    (dict(method=dict), r"method must be one of .* received <class 'dict'>"),
])
def test_solver_options_are_checked_up_front_on_every_path(options, message):
    # the exact LTI path ignores the options, but a typo must not pass silently there either
    for system in (ck.models.pendulum(), ck.models.mass_spring_damper()):
        with pytest.raises(ValueError, match=message):
            ck.simulate(system, np.linspace(0, 1, 11), x0=[1, 0], **options)
    with pytest.raises(ValueError, match=message):
        ck.simulate_batch(ck.models.pendulum(), np.linspace(0, 1, 11), [[1, 0]], **options)


def test_valid_options_are_passed_on():
    from scipy.integrate import RK45
    pend, t = ck.models.pendulum(), np.linspace(0, 2, 21)
    ref = ck.simulate(pend, t, x0=[1, 0]).x
    for options in (dict(method=RK45, rtol=1e-10, atol=1e-12), dict(atol=[1e-12, 1e-11]),
                    dict(method="Radau", rtol=1e-10)):
        # all runs ask for ~1e-10 relative accuracy on an O(1) solution
        np.testing.assert_allclose(ck.simulate(pend, t, x0=[1, 0], **options).x, ref, atol=1e-7)
    batch = ck.simulate_batch(pend, t, [[1, 0], [0.5, 0]], atol=[1e-12, 1e-11])
    np.testing.assert_allclose(batch[:, 0], ref, atol=1e-7)


# ---------------------------------------------------------------- solver failure and overflow

def test_a_solver_failure_at_the_first_step_is_reported_not_an_attribute_error():
    # at t ~ 1e18 the spacing of floats (128) is far above the step cos(t) needs
    with pytest.raises(ck.SimulationError, match=r"stopped at t = 1e\+18 \(it could not complete a "
                                                  r"first step\): Required step size") as info:
        ck.simulate(ck.StateSpace([[-1.0]], [[1.0]]), np.linspace(1e18, 1e18 + 1e4, 11), x0=[1.0],
                    u=lambda t, x: [np.cos(t)])
    assert isinstance(info.value, RuntimeError) and isinstance(info.value, ValueError)


def test_finite_escape_time_stops_with_a_simulation_error():
    # x' = x^2, x(0) = 1 is 1 / (1 - t): it escapes at t = 1
    with pytest.raises(ck.SimulationError, match=r"at t = (0\.9\d*|1)\b"):
        ck.simulate(ck.NonlinearSystem(lambda x, u: x**2, n=1), np.linspace(0, 2, 11), x0=[1.0])


# log of the largest float: e^a overflows exactly when a > LOG_MAX
LOG_MAX = np.log(np.finfo(float).max)


@settings(max_examples=25)
@given(st.floats(0.05, 5.0), st.floats(-4.0, 4.0))
def test_exact_lti_overflow_is_reported_exactly_when_the_solution_leaves_the_floats(a, log_scale):
    # x' = a x, x(0) = 1 (after a change of time unit by 10**log_scale: A -> s A, t -> t / s)
    s = 10.0**log_scale
    t = np.linspace(0, 1000 / a, 101) / s           # a t runs to 1000 > LOG_MAX
    with pytest.raises(ck.SimulationError, match=r"largest real part of the eigenvalues of A is .* > 0: "
                                                  r"the system is unstable") as info:
        ck.simulate(ck.StateSpace([[a * s]]), t, x0=[1.0])
    # the first sample beyond the floats: a s t_k > LOG_MAX; the message brackets it
    k = int(np.argmax(a * s * t > LOG_MAX))
    bracket = re.search(r"finite up to t = (\S+) .* overflows by t = (\S+)\.", str(info.value))
    assert np.isclose(float(bracket[1]), t[k - 1], rtol=1e-5) and np.isclose(float(bracket[2]), t[k], rtol=1e-5)
    # just short of the overflow the same system is simulated, finite and exact
    short = ck.simulate(ck.StateSpace([[a * s]]), t[:k], x0=[1.0])
    # exp is evaluated to a few ulps per step; the recursion multiplies k of them
    np.testing.assert_allclose(short.x[:, 0], np.exp(a * s * t[:k]), rtol=1e-12 * k)


@settings(max_examples=20)
@given(st.floats(1.1, 4.0))
def test_discrete_overflow_names_the_spectral_radius(rho):
    steps = int(LOG_MAX / np.log(rho)) + 5
    with pytest.raises(ck.SimulationError, match=rf"spectral radius .* of A is {rho:.4g} > 1"):
        ck.simulate(ck.StateSpace([[rho]], dt=1.0), np.arange(steps), x0=[1.0])
    res = ck.simulate(ck.StateSpace([[rho]], dt=1.0), np.arange(steps - 10), x0=[1.0])
    assert np.isfinite(res.x).all()


def test_ode_path_overflow_under_feedback_points_at_the_closed_loop():
    sys = ck.StateSpace([[1.0]], [[1.0]])
    with pytest.raises(ck.SimulationError, match=r"left the float range.*of A alone .*A \+ B K"):
        ck.simulate(sys, np.linspace(0, 1000, 11), x0=[1.0], u=lambda t, x: 0.5 * x)


def test_batch_overflow_is_reported():
    with pytest.raises(ck.SimulationError, match=r"left the float range"):
        ck.simulate_batch(ck.StateSpace([[1.0]]), np.linspace(0, 1000, 11), [[1.0], [2.0]])


def test_step_matrices_overflow_is_an_error_not_inf():
    with pytest.raises(ck.SimulationError, match=r"e\^\(A h\) over one step h = 1000"):
        ck.lti_step_matrices([[1.0]], [[1.0]], 1000.0)


def test_a_large_but_finite_state_is_returned():
    # e^300 ~ 2e130 is far from the float limit: no error, the exact value
    res = ck.simulate(ck.StateSpace([[1.0]]), np.linspace(0, 300, 31), x0=[1.0])
    np.testing.assert_allclose(res.x[-1, 0], np.exp(300.0), rtol=1e-12)   # a few ulps per step, 30 steps


def test_stiffness_that_appears_later_is_found_on_the_way():
    # Van der Pol from x0 = [1, 0]: the Jacobian there has rate 1, so the run starts, and the
    # stiffness (rate ~ 3e4) comes later; the test repeated during the run refuses it there
    # (issue 35: it used to run into the bound of 1e6 evaluations, six seconds and more)
    vdp = ck.NonlinearSystem(lambda x, u: np.array([x[1], 1e4 * (1 - x[0] ** 2) * x[1] - x[0]]), n=2)
    for run in (lambda: ck.simulate(vdp, np.linspace(0, 100, 11), x0=[1.0, 0.0]),
                lambda: ck.simulate_batch(vdp, np.linspace(0, 100, 11), [[1.0, 0.0], [1.0, 0.1]])):
        with pytest.raises(ck.SimulationError, match=r"cannot finish in bounded work: the fastest mode of f at "
                                                     r"t = 0\.\d+, x = .*\|lambda\| = [23](?:\.\d)?e\+04(?s:.*)"
                                                     r"became stiff on the way(?s:.*)method='Radau'"):
            run()
    # from x0 = [2, 0] the stiffness shows at the start: refused before any step, in a batch too
    with pytest.raises(ck.SimulationError, match=r"cannot finish in bounded work"):
        ck.simulate_batch(vdp, np.linspace(0, 100, 11), [[2.0, 0.0], [2.0, 0.1]])
    # the implicit methods are not stopped: Radau solves it in a few hundred steps
    assert ck.simulate(vdp, np.linspace(0, 100, 11), x0=[1.0, 0.0], method="Radau").x.shape == (11, 2)


def test_any_run_stops_at_the_evaluation_bound(monkeypatch):
    # a harmonic oscillator is not stiff, but a long span at tight tolerances takes many steps;
    # the bound on evaluations (lowered here to keep the test fast) stops it, naming the time reached
    import coursekit.simulation as simulation
    monkeypatch.setattr(simulation, "_MAX_EVALUATIONS", 20_000)
    osc = ck.NonlinearSystem(lambda x, u: np.array([x[1], -x[0]]), n=2)
    for run in (lambda: ck.simulate(osc, np.linspace(0, 5000, 11), x0=[1.0, 0.0]),
                lambda: ck.simulate_batch(osc, np.linspace(0, 5000, 11), [[1.0, 0.0], [0.0, 1.0]])):
        with pytest.raises(ck.SimulationError, match=r"evaluated f 20,000 times and reached only t = "
                                                     r"[\d.]+ of 5000(?s:.*)method='Radau'"):
            run()


def test_simulate_with_noise_refuses_a_state_that_overflows():
    # issue 35: e^(t) passes 1e308 near t = 710; the noisy simulation returned inf without a word
    unstable = ck.StateSpace([[1.0]], [[1.0]], [[1.0]])
    with pytest.raises(ck.SimulationError, match=r"left the float range .* finite up to t = 709 .* overflows by "
                                                 r"t = 710(?s:.*)unstable \(section 3\.2\.2\)"):
        ck.simulate_with_noise(unstable, np.linspace(0.0, 1000.0, 1001), x0=[1.0], Q=[[1.0]], R=[[1.0]], seed=0)
    # below the float limit the result is returned as before
    res = ck.simulate_with_noise(unstable, np.linspace(0.0, 700.0, 701), x0=[1.0], Q=[[1.0]], R=[[1.0]], seed=0)
    assert np.isfinite(res.x).all() and np.isfinite(res.y).all()


@pytest.mark.parametrize("scale", [1e100, 1e200, 1e-200])
def test_step_matrices_of_a_huge_or_tiny_input_matrix(scale):
    # issue 35: with B scaled by 1e200, Ad differed from e^(A h) (or the overflow error blamed the
    # input); the input blocks are linear in B, Ad does not depend on it
    from scipy.linalg import expm
    A, B, h = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]]), 0.1
    Ad, B0, B1 = ck.lti_step_matrices(A, B * scale, h)
    Ad_1, B0_1, B1_1 = ck.lti_step_matrices(A, B, h)
    np.testing.assert_allclose(Ad, expm(A * h), rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(B0 / scale, B0_1, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(B1 / scale, B1_1, rtol=1e-13, atol=1e-16)
