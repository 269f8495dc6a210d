"""The table of bad inputs run by tests/test_bad_input.py, and the worker that runs it.

Each entry is one call that a student could plausibly make by mistake, with
the argument the error message must name. One line per case::

    bad("place", "poles without conjugate", lambda: ck.place(A2, B2, [-1 + 1j, -2]), "poles")

`bad(target, label, call, arg)`: `call()` must raise ValueError or TypeError
whose message names `arg` (as a whole word; `also=` adds a regex the message
must contain). `ok(target, label, call)`: a control, the same call with good
arguments, which must not raise (so a bad case fails because of its one bad
argument, not because the fixture is wrong). `warns(target, label, call, arg)`:
a call that may run but must not pass silently: a coursekit warning (turned
into an error here) or a ValueError/TypeError naming `arg`. `feedback(target, label, call,
says)`: a `check_*` exercise, which must print "Not yet" feedback matching
`says` and return False, without raising. The `*_cases` helpers expand one
line into the standard set of bad values for a matrix, a scalar, a list of
poles or a user function.

`main()` is the worker, started by tests/test_bad_input.py in a process of its
own once the whole module (the chapters' own files of cases included) is imported: it reads case ids (one per line)
on stdin, runs each under a per-case deadline and prints one JSON line per
case (and a "start" line before it, so that the parent can tell which case a
killed worker was running).
"""

from __future__ import annotations

import contextlib
import faulthandler
import importlib
import inspect
import io
import json
import re
import signal
import sys
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

import coursekit as ck
import coursekit.exercises as ex
from coursekit.exercises._feedback import CheckResult
from coursekit import models
from coursekit.tools.chapters import check_functions

#: seconds a single case may take before it counts as a hang (the slowest good case
#: takes about 0.6 s once the libraries are imported, on a machine loaded 3x over its cores)
DEADLINE = 5
#: prefix of the worker's report lines (anything else on its stdout is ignored)
MARK = "@@bad-input "


@dataclass(frozen=True)
class Case:
    target: str      # the public name the case exercises ("place", "StateSpace.f", ...)
    label: str
    call: Callable
    kind: str        # "bad", "warns", "ok" or "feedback"
    pattern: str     # regex the message / printed feedback must contain

    @property
    def id(self) -> str:
        return f"{self.target}: {self.label}"


CASES: list[Case] = []


def _word(name: str) -> str:
    return rf"(?<!\w){re.escape(name)}(?!\w)"


def bad(target: str, label: str, call: Callable, arg: str, *, also: str = "") -> None:
    """A bad call: ValueError/TypeError naming `arg` (and matching `also`)."""
    pattern = _word(arg) + (rf"(?s:.*){also}" if also else "")
    CASES.append(Case(target, label, call, "bad", pattern))


def ok(target: str, label: str, call: Callable) -> None:
    """A control call with good arguments: must return without an exception or a warning."""
    CASES.append(Case(target, label, call, "ok", ""))


def warns(target: str, label: str, call: Callable, arg: str, *, also: str = "") -> None:
    """A call that may run but must not pass silently: a coursekit warning (the worker turns
    warnings into errors) or a ValueError/TypeError, whose message names `arg` (and matches `also`)."""
    pattern = _word(arg) + (rf"(?s:.*){also}" if also else "")
    CASES.append(Case(target, label, call, "warns", pattern))


def feedback(target: str, label: str, call: Callable, says: str = "") -> None:
    """An exercise check on a bad answer: prints "Not yet" feedback matching `says`; its result is false."""
    CASES.append(Case(target, label, call, "feedback", says))


# ---------------------------------------------------------------------------
# generators: the standard bad values of one kind of argument


def _complex_list(value):
    return (np.asarray(value, dtype=float) + 1j).tolist()


def matrix_cases(target: str, arg: str, build: Callable, good, *, shape=None, empty=True,
                 optional=False) -> None:
    """Good control plus NaN, inf, complex (array, list, sympy), None, text, wrong shape, empty.

    `build(value)` makes the call with `arg` replaced by `value`; `shape` is a
    mis-shaped value (default: `good` with one extra row); `empty=False` when
    an empty array is valid or covered by `shape`; `optional` when None is a
    valid value (a default).
    """
    good = np.asarray(good, dtype=float)
    nan, inf = good.copy(), good.copy()
    nan.flat[0], inf.flat[-1] = np.nan, np.inf
    wrong = np.vstack([good, good[:1]]) if shape is None else shape
    ok(target, f"{arg} good", lambda: build(good))
    bad(target, f"{arg} with NaN", lambda: build(nan), arg)
    bad(target, f"{arg} with inf", lambda: build(inf), arg)
    bad(target, f"{arg} complex array", lambda: build(good + 1e-3j), arg)
    bad(target, f"{arg} complex array, zero imaginary part", lambda: build(good + 0j), arg)
    bad(target, f"{arg} complex list", lambda: build(_complex_list(good)), arg)
    bad(target, f"{arg} sympy complex", lambda: build(_sympy_complex(good)), arg)
    if not optional:
        bad(target, f"{arg} None", lambda: build(None), arg)
    bad(target, f"{arg} text", lambda: build("[[1, 2], [3, 4]]"), arg)
    bad(target, f"{arg} wrong shape", lambda: build(wrong), arg)
    if empty:
        bad(target, f"{arg} empty", lambda: build(np.zeros((0, 0))), arg)


def _sympy_complex(good):
    import sympy
    return sympy.Matrix(good.reshape(good.shape[0], -1)) + sympy.I * sympy.ones(good.shape[0], good.reshape(good.shape[0], -1).shape[1])


def scalar_cases(target: str, arg: str, build: Callable, good=1.0, *, positive=False,
                 optional=False) -> None:
    """Good control plus NaN, inf, complex (Python, numpy, sympy), None, text, a list.

    `optional`: None is a valid value (e.g. ``dt=None`` for continuous time).
    """
    import sympy
    ok(target, f"{arg} good", lambda: build(good))
    values = {"NaN": np.nan, "inf": np.inf, "complex": complex(good, 1),
              "numpy complex": np.complex128(good), "sympy complex": good + sympy.I,
              "None": None, "text": str(good), "list": [good, good, good]}
    if optional:
        del values["None"]
    if positive:
        values.update({"zero": 0.0, "negative": -abs(good)})
    for label, value in values.items():
        bad(target, f"{arg} {label}", lambda value=value: build(value), arg)


def span_cases(target: str, call: Callable) -> None:
    """A time span t_end of 1e300 and 10**12 or 1e300 samples: refused at once, naming the argument."""
    bad(target, "t_end 1e300", lambda: call(t_end=1e300), "t_end")
    bad(target, "samples 10**12", lambda: call(samples=10**12), "samples")
    bad(target, "samples 1e300", lambda: call(samples=1e300), "samples")


def poles_cases(target: str, arg: str, build: Callable, good, *, any_count: bool = False) -> None:
    """Good control plus wrong count, lone complex pole, NaN, inf, None, text, empty.

    `any_count`: the function takes any number of poles (no count is wrong), so
    one more and one fewer are good controls instead of bad cases.
    """
    good = list(good)
    ok(target, f"{arg} good", lambda: build(good))
    lone = [complex(good[0].real if isinstance(good[0], complex) else good[0], 1.0)] + good[1:]
    counts = {"one too many": good + [-7.0], "one too few": good[:-1]}
    for label, value in counts.items():
        (ok if any_count else bad)(target, f"{arg} {label}", lambda value=value: build(value),
                                   *(() if any_count else (arg,)))
    for label, value in {"complex without conjugate": lone, "NaN": [np.nan] + good[1:],
                         "inf": [-np.inf] + good[1:], "None": None, "text": "-1, -2",
                         "empty": []}.items():
        bad(target, f"{arg} {label}", lambda value=value: build(value), arg)


def function_cases(target: str, arg: str, build: Callable, good: Callable, *, size: int,
                   skip=()) -> None:
    """Good control plus: not callable, raises, returns NaN / wrong shape / None / text / complex."""
    ok(target, f"{arg}() good", lambda: build(good))

    def raises(*args):
        raise ZeroDivisionError("student's bug")

    values = {"not callable": 3.0, "raises": raises,
              "returns NaN": lambda *a: np.full(size, np.nan),
              "returns inf": lambda *a: np.full(size, np.inf),
              "returns wrong shape": lambda *a: np.zeros(size + 1),
              "returns None": lambda *a: None,
              "returns complex": lambda *a: np.zeros(size) + 1j}
    for label, value in values.items():
        if label not in skip:
            bad(target, f"{arg}() {label}", lambda value=value: build(value), arg)


# ---------------------------------------------------------------------------
# fixtures: small systems from the notes

A2 = np.array([[0.0, 1.0], [-2.0, -3.0]])
B2 = np.array([[0.0], [1.0]])
C2 = np.array([[1.0, 0.0]])
P2 = [-1.0, -2.0]
K2 = np.array([[-1.0, -2.0]])
L2 = np.array([[2.0], [1.0]])
A_UNCTRL, B_UNCTRL = np.diag([-1.0, -2.0]), np.array([[1.0], [0.0]])
C_UNOBS = np.array([[1.0, 0.0]])
T11 = np.linspace(0.0, 1.0, 11)


def sys2(dt=None):
    return ck.StateSpace(A2, B2, C2, dt=dt)


def pend():
    return models.pendulum()


def pend_f(x, u):
    return np.array([x[1], -9.81 * np.sin(x[0]) + u[0]])


def linear_f(x, u):
    return A2 @ np.asarray(x) + B2 @ np.atleast_1d(u)


def _sympy():
    import sympy
    return sympy


def _sym_msd():
    return ck.symbolic_mass_spring_damper()


def _column_u(u):
    """u = K2 [1, 1]^T + 1 = -2 as a column (1, 1); anything else fails the case."""
    if np.shape(u) != (1, 1) or not np.isclose(u[0, 0], -2.0, rtol=0, atol=1e-12):  # exact in floats
        raise AssertionError(f"expected the column [[-2.]], received {u!r}")
    return u


def result():
    return ck.simulate(sys2(), T11, u=np.ones((11, 1)))


def euler_result():
    return ck.simulate(ck.euler_discretize(sys2(), 0.1), T11, u=np.ones((11, 1)))


# ---------------------------------------------------------------------------
# chapter 1: representations

matrix_cases("StateSpace", "A", lambda A: ck.StateSpace(A, B2, C2), A2)
matrix_cases("StateSpace", "B", lambda B: ck.StateSpace(A2, B, C2), B2, empty=False, optional=True)
matrix_cases("StateSpace", "C", lambda C: ck.StateSpace(A2, B2, C), C2, shape=np.ones((1, 3)), empty=False, optional=True)
matrix_cases("StateSpace", "D", lambda D: ck.StateSpace(A2, B2, C2, D), [[0.0]], empty=False, optional=True)
scalar_cases("StateSpace", "dt", lambda dt: ck.StateSpace(A2, B2, C2, dt=dt), 0.1, positive=True, optional=True)
ok("StateSpace.f", "good", lambda: sys2().f(np.zeros(2), np.zeros(1)))
bad("StateSpace.f", "column x with flat u", lambda: sys2().f(np.zeros((2, 1)), np.zeros(1)), "x")
bad("StateSpace.f", "x wrong length", lambda: sys2().f(np.zeros(3), np.zeros(1)), "x")
bad("StateSpace.f", "u wrong length", lambda: sys2().f(np.zeros(2), np.zeros(2)), "u")
bad("StateSpace.f", "x complex", lambda: sys2().f(np.zeros(2) + 1j, np.zeros(1)), "x")
bad("StateSpace.f", "x NaN", lambda: sys2().f(np.array([np.nan, 0.0]), np.zeros(1)), "x")
bad("StateSpace.f", "u None", lambda: sys2().f(np.zeros(2), None), "u")
bad("StateSpace.f", "x text", lambda: sys2().f("x", np.zeros(1)), "x")
ok("StateSpace.h", "good", lambda: sys2().h(np.zeros(2), np.zeros(1)))
bad("StateSpace.h", "column x with flat u", lambda: sys2().h(np.zeros((2, 1)), np.zeros(1)), "x")
bad("StateSpace.h", "x wrong length", lambda: sys2().h(np.zeros(3), np.zeros(1)), "x")
bad("StateSpace.h", "u complex", lambda: sys2().h(np.zeros(2), np.zeros(1) + 1j), "u")
ok("StateSpace.poles", "good", lambda: sys2().poles())
bad("StateSpace.poles", "called with an argument", lambda: sys2().poles(A2), "poles")

function_cases("NonlinearSystem", "f", lambda f: ck.NonlinearSystem(f, n=2, m=1).check(np.zeros(2), np.zeros(1)),
               pend_f, size=2)
function_cases("NonlinearSystem", "h", lambda h: ck.NonlinearSystem(pend_f, n=2, m=1, h=h).h(np.zeros(2), np.zeros(1)),
               lambda x, u: x[:1], size=1, skip=("returns wrong shape",))
scalar_cases("NonlinearSystem", "n", lambda n: ck.NonlinearSystem(pend_f, n=n, m=1), 2, positive=True)
bad("NonlinearSystem", "n fractional", lambda: ck.NonlinearSystem(pend_f, n=2.5, m=1), "n")
bad("NonlinearSystem", "m negative", lambda: ck.NonlinearSystem(pend_f, n=2, m=-1), "m")
ok("NonlinearSystem.f", "good", lambda: pend().f(np.zeros(2), np.zeros(1)))
bad("NonlinearSystem.f", "x wrong length", lambda: pend().f(np.zeros(3), np.zeros(1)), "x")
bad("NonlinearSystem.f", "x complex", lambda: pend().f(np.zeros(2) + 1j, np.zeros(1)), "x")
bad("NonlinearSystem.f", "x text", lambda: pend().f("x", np.zeros(1)), "x")
bad("NonlinearSystem.f", "u wrong length", lambda: pend().f(np.zeros(2), np.zeros(3)), "u")
bad("NonlinearSystem.f", "user f raises", lambda: ck.NonlinearSystem(lambda x, u: 1 / 0, n=1).f([1.0], []), "f")
bad("NonlinearSystem.f", "user f returns None", lambda: ck.NonlinearSystem(lambda x, u: None, n=1).f([1.0], []), "f")
bad("NonlinearSystem.f", "user f returns complex", lambda: ck.NonlinearSystem(lambda x, u: x + 1j, n=1).f(np.ones(1), []), "f")
ok("NonlinearSystem.h", "good", lambda: pend().h(np.zeros(2), np.zeros(1)))
bad("NonlinearSystem.h", "x wrong length", lambda: pend().h(np.zeros(3), np.zeros(1)), "x")
bad("NonlinearSystem.h", "user h raises", lambda: ck.NonlinearSystem(pend_f, n=2, m=1, h=lambda x, u: 1 / 0).h(np.zeros(2), np.zeros(1)), "h")

matrix_cases("simulate", "x0", lambda x0: ck.simulate(sys2(), T11, x0=x0), [1.0, 0.0], shape=[1.0, 0.0, 0.0], empty=False, optional=True)
matrix_cases("simulate", "u", lambda u: ck.simulate(sys2(), T11, u=u), np.ones((11, 1)), empty=False, optional=True)
matrix_cases("simulate", "t", lambda t: ck.simulate(sys2(), t), T11, shape=np.ones((3, 3)), empty=False)
bad("simulate", "t decreasing", lambda: ck.simulate(sys2(), T11[::-1]), "t")
bad("simulate", "t single point", lambda: ck.simulate(sys2(), [0.0]), "t")
bad("simulate", "sys is a matrix", lambda: ck.simulate(A2, T11), "sys")
bad("simulate", "sys None", lambda: ck.simulate(None, T11), "sys")
function_cases("simulate", "u", lambda u: ck.simulate(sys2(), T11, u=u), lambda t, x: np.ones(1), size=1)
function_cases("simulate", "f", lambda f: ck.simulate(ck.NonlinearSystem(f, n=2, m=1), T11, x0=[0.1, 0.0], u=np.zeros((11, 1))),
               pend_f, size=2)
bad("simulate", "f goes NaN during integration (sqrt of negative state)",
    lambda: ck.simulate(ck.NonlinearSystem(lambda x, u: -np.sqrt(x), n=1), T11, x0=[-1.0]), "f")
bad("simulate", "u(t, x) returns NaN later", lambda: ck.simulate(sys2(), T11, u=lambda t, x: [np.nan if t > 0.5 else 0.0]), "u")
scalar_cases("simulate", "rtol", lambda rtol: ck.simulate(pend(), T11, x0=[0.1, 0], rtol=rtol), 1e-6, positive=True)
scalar_cases("simulate", "atol", lambda atol: ck.simulate(pend(), T11, x0=[0.1, 0], atol=atol), 1e-9, positive=True)
bad("simulate", "method unknown", lambda: ck.simulate(pend(), T11, x0=[0.1, 0], method="Euler"), "method")
ok("SimulationResult.plot", "good", lambda: result().plot())
bad("SimulationResult.plot", "which unknown letter", lambda: result().plot(which="xz"), "which")
bad("SimulationResult.plot", "which not a string", lambda: result().plot(which=3), "which")
bad("SimulationResult.plot", "state_names wrong length", lambda: result().plot(state_names=["a"]), "state_names")
bad("SimulationResult.plot", "state_units wrong length", lambda: result().plot(state_units=["m"] * 3), "state_units")
ok("plot_response", "good", lambda: ck.plot_response(result(), "xyu", time_unit="min"))
bad("plot_response", "result a StateSpace", lambda: ck.plot_response(sys2()), "result")
bad("plot_response", "result None", lambda: ck.plot_response(None), "result")
bad("plot_response", "which empty", lambda: ck.plot_response(result(), ""), "which")
bad("plot_response", "input_names wrong length", lambda: ck.plot_response(result(), input_names=["a", "b"]), "input_names")
bad("plot_response", "time_unit None", lambda: ck.plot_response(result(), time_unit=None), "time_unit")
bad("plot_response", "figsize text", lambda: ck.plot_response(result(), figsize="big"), "figsize")

matrix_cases("simulate_batch", "x0s", lambda x0s: ck.simulate_batch(pend(), T11, x0s), np.zeros((3, 2)), shape=np.zeros((3, 3)))
bad("simulate_batch", "t with NaN", lambda: ck.simulate_batch(pend(), [0.0, np.nan, 1.0], np.zeros((3, 2))), "t")
function_cases("simulate_batch", "u", lambda u: ck.simulate_batch(pend(), T11, np.zeros((3, 2)), u=u),
               lambda t, X: np.zeros((1, X.shape[1])), size=3)
matrix_cases("lti_step_matrices", "A", lambda A: ck.lti_step_matrices(A, B2, 0.1), A2)
matrix_cases("lti_step_matrices", "B", lambda B: ck.lti_step_matrices(A2, B, 0.1), B2, empty=False)
scalar_cases("lti_step_matrices", "h", lambda h: ck.lti_step_matrices(A2, B2, h), 0.1, positive=True)

matrix_cases("ode_to_ss", "a", lambda a: ck.ode_to_ss(a, 1.0), [2.0, 3.0], shape=np.ones((2, 2)))
scalar_cases("ode_to_ss", "b", lambda b: ck.ode_to_ss([2.0, 3.0], b), 1.0)
bad("ode_to_ss", "b sequence of wrong length", lambda: ck.ode_to_ss([2.0, 3.0], [1.0, 2.0, 3.0]), "b")
matrix_cases("difference_to_ss", "a", lambda a: ck.difference_to_ss(a, 1.0), [-1.0, -1.0], shape=np.ones((2, 2)))
scalar_cases("difference_to_ss", "b", lambda b: ck.difference_to_ss([-1.0, -1.0], b), 1.0)
scalar_cases("euler_discretize", "Ts", lambda Ts: ck.euler_discretize(sys2(), Ts), 0.1, positive=True)
bad("euler_discretize", "sys a matrix", lambda: ck.euler_discretize(A2, 0.1), "sys")
bad("euler_discretize", "sys already discrete", lambda: ck.euler_discretize(sys2(dt=0.1), 0.1), "sys")
ok("cascade", "good", lambda: ck.cascade(sys2(), sys2()))
bad("cascade", "sys2 a matrix", lambda: ck.cascade(sys2(), A2), "sys2")
bad("cascade", "sys1 None", lambda: ck.cascade(None, sys2()), "sys1")
bad("cascade", "sizes do not match", lambda: ck.cascade(ck.StateSpace(A2, B2), sys2()), "sys2")
bad("cascade", "continuous with discrete", lambda: ck.cascade(sys2(), sys2(dt=0.1)), "sys2")
ok("feedback", "good", lambda: ck.feedback(sys2(), ck.StateSpace([[-1.0]], [[1.0]], [[1.0]])))
bad("feedback", "sign 0", lambda: ck.feedback(sys2(), sys2(), sign=0), "sign")
bad("feedback", "sign complex", lambda: ck.feedback(sys2(), sys2(), sign=1j), "sign")
bad("feedback", "sign text", lambda: ck.feedback(sys2(), sys2(), sign="-"), "sign")
bad("feedback", "sys2 NonlinearSystem", lambda: ck.feedback(sys2(), pend()), "sys2")
bad("feedback", "algebraic loop", lambda: ck.feedback(ck.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[1.0]]),
                                                      ck.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[1.0]])), "sys1")

ok("plot_state_plane", "good", lambda: ck.plot_state_plane([result().x]))
bad("plot_state_plane", "trajectories None", lambda: ck.plot_state_plane(None), "trajectories")
bad("plot_state_plane", "trajectories text", lambda: ck.plot_state_plane("x"), "trajectories")
bad("plot_state_plane", "trajectory complex", lambda: ck.plot_state_plane([result().x + 1j]), "trajectories")
bad("plot_state_plane", "trajectory with NaN", lambda: ck.plot_state_plane([np.full((3, 2), np.nan)]), "trajectories")
bad("plot_state_plane", "trajectory 1-D", lambda: ck.plot_state_plane([np.zeros(5)]), "trajectories")
bad("plot_state_plane", "states out of range", lambda: ck.plot_state_plane([result().x], states=(0, 5)), "states")
bad("plot_state_plane", "states one index", lambda: ck.plot_state_plane([result().x], states=(0,)), "states")
bad("plot_state_plane", "labels wrong length", lambda: ck.plot_state_plane([result().x], labels=["a", "b"]), "labels")
ok("plot_euler_comparison", "good", lambda: ck.plot_euler_comparison(result(), [euler_result()]))
bad("plot_euler_comparison", "exact None", lambda: ck.plot_euler_comparison(None, [result()]), "exact")
bad("plot_euler_comparison", "approximations continuous", lambda: ck.plot_euler_comparison(result(), [result()]), "approximations")
bad("plot_euler_comparison", "approximations a matrix", lambda: ck.plot_euler_comparison(result(), A2), "approximations")
bad("plot_euler_comparison", "state out of range", lambda: ck.plot_euler_comparison(result(), [euler_result()], state=4), "state")
bad("plot_euler_comparison", "state fractional", lambda: ck.plot_euler_comparison(result(), [euler_result()], state=0.5), "state")

# ---------------------------------------------------------------------------
# chapter 2: controllability and open-loop control

for _name, _fn in (("ctrb", ck.ctrb), ("ctrb_singular_values", ck.ctrb_singular_values),
                   ("is_controllable", ck.is_controllable), ("ccf_transform", ck.ccf_transform),
                   ("linear_flatness", ck.linear_flatness), ("symbolic_ctrb", ck.symbolic_ctrb),
                   ("symbolic_linear_flatness", ck.symbolic_linear_flatness)):
    matrix_cases(_name, "A", lambda A, _fn=_fn: _fn(A, B2), A2)
    matrix_cases(_name, "B", lambda B, _fn=_fn: _fn(A2, B), B2, empty=False)
ok("symbolic_ctrb", "symbols", lambda: ck.symbolic_ctrb(*ck.symbolic_mass_spring_damper()))
bad("symbolic_ctrb", "symbol times I", lambda: ck.symbolic_ctrb(_sym_msd()[0] * (1 + _sympy().I), _sym_msd()[1]), "A")
ok("symbolic_linear_flatness", "symbols", lambda: ck.symbolic_linear_flatness(*ck.symbolic_mass_spring_damper()))
bad("symbolic_linear_flatness", "two inputs", lambda: ck.symbolic_linear_flatness(A2, np.eye(2)), "B")
bad("is_controllable", "tol negative", lambda: ck.is_controllable(A2, B2, tol=-1.0), "tol")
bad("is_controllable", "tol NaN", lambda: ck.is_controllable(A2, B2, tol=np.nan), "tol")
bad("ccf_transform", "uncontrollable", lambda: ck.ccf_transform(A_UNCTRL, B_UNCTRL), "B")
bad("ccf_transform", "two inputs", lambda: ck.ccf_transform(A2, np.eye(2)), "B")
bad("linear_flatness", "uncontrollable", lambda: ck.linear_flatness(A_UNCTRL, B_UNCTRL), "B")
bad("symbolic_linear_flatness", "uncontrollable", lambda: ck.symbolic_linear_flatness(A_UNCTRL, B_UNCTRL), "B")
matrix_cases("charpoly", "A", ck.charpoly, A2)
ok("similarity_transform", "good", lambda: ck.similarity_transform(sys2(), np.eye(2)))
matrix_cases("similarity_transform", "T", lambda T: ck.similarity_transform(sys2(), T), np.eye(2))
bad("similarity_transform", "T singular", lambda: ck.similarity_transform(sys2(), np.ones((2, 2))), "T")
bad("similarity_transform", "sys a matrix", lambda: ck.similarity_transform(A2, np.eye(2)), "sys")

scalar_cases("poly_trajectory", "T", lambda T: ck.poly_trajectory(T, [0.0, 0.0], [1.0, 0.0]), 2.0, positive=True)
matrix_cases("poly_trajectory", "start", lambda s: ck.poly_trajectory(2.0, s, [1.0, 0.0]), [0.0, 0.0], shape=np.zeros((2, 2, 2)))
matrix_cases("poly_trajectory", "end", lambda e: ck.poly_trajectory(2.0, [0.0, 0.0], e), [1.0, 0.0], shape=[1.0, 0.0, 0.0])
ok("PolyTrajectory", "call good", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])(np.linspace(0, 2, 5), k=1))
bad("PolyTrajectory", "k negative", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])(1.0, k=-1), "k")
bad("PolyTrajectory", "k fractional", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])(1.0, k=0.5), "k")
bad("PolyTrajectory", "t complex", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])(1.0 + 1j), "t")
bad("PolyTrajectory", "t NaN", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])(np.nan), "t")
bad("PolyTrajectory", "t text", lambda: ck.poly_trajectory(2.0, [0, 0], [1, 0])("1"), "t")

def _traj():
    return ck.poly_trajectory(2.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])

matrix_cases("feedforward", "a", lambda a: ck.feedforward(a, 1.0, _traj())(1.0), [2.0, 3.0], shape=np.ones((2, 2)))
scalar_cases("feedforward", "b", lambda b: ck.feedforward([2.0, 3.0], b, _traj())(1.0), 1.0)
bad("feedforward", "traj not callable", lambda: ck.feedforward([2.0, 3.0], 1.0, [1.0, 2.0]), "traj")
bad("feedforward", "traj None", lambda: ck.feedforward([2.0, 3.0], 1.0, None), "traj")
bad("feedforward", "traj raises", lambda: ck.feedforward([2.0, 3.0], 1.0, lambda t, k=0: 1 / 0)(1.0), "traj")
bad("feedforward", "traj returns NaN", lambda: ck.feedforward([2.0, 3.0], 1.0, lambda t, k=0: np.nan * t)(1.0), "traj")

def _olc(A=A2, B=B2, x0=(0.0, 0.0), xT=(1.0, 0.0), T=2.0, **kw):
    return ck.open_loop_control(A, B, x0, xT, T, **kw)

matrix_cases("open_loop_control", "A", lambda A: _olc(A=A), A2)
matrix_cases("open_loop_control", "B", lambda B: _olc(B=B), B2, empty=False)
matrix_cases("open_loop_control", "x0", lambda x0: _olc(x0=x0), [0.0, 0.0], shape=[0.0, 0.0, 0.0], empty=False)
matrix_cases("open_loop_control", "xT", lambda xT: _olc(xT=xT), [1.0, 0.0], shape=[0.0, 0.0, 0.0], empty=False)
scalar_cases("open_loop_control", "T", lambda T: _olc(T=T), 2.0, positive=True)
bad("open_loop_control", "uncontrollable", lambda: _olc(A=A_UNCTRL, B=B_UNCTRL), "B")
bad("open_loop_control", "smooth negative", lambda: _olc(smooth=-1), "smooth")
ok("OpenLoopPlan", "methods good", lambda: (_olc().x(1.0), _olc().ud(1.0), _olc().input(1.0), _olc().z(1.0)))
bad("OpenLoopPlan", "x(t) complex", lambda: _olc().x(1.0 + 1j), "t")
bad("OpenLoopPlan", "ud(t) NaN", lambda: _olc().ud(np.nan), "t")
bad("OpenLoopPlan", "input(t) text", lambda: _olc().input("1"), "t")
bad("OpenLoopPlan", "plot samples 1", lambda: _olc().plot(samples=1), "samples")
ok("plot_plan", "good", lambda: ck.plot_plan(T11, np.zeros((11, 2)), np.zeros((11, 1)), title="plan"))
bad("plot_plan", "x wrong rows", lambda: ck.plot_plan(T11, np.zeros((10, 2)), np.zeros((11, 1)), title="plan"), "x")
bad("plot_plan", "u complex", lambda: ck.plot_plan(T11, np.zeros((11, 2)), np.zeros((11, 1)) + 1j, title="plan"), "u")
bad("plot_plan", "t NaN", lambda: ck.plot_plan(T11 * np.nan, np.zeros((11, 2)), np.zeros((11, 1)), title="plan"), "t")
bad("plot_plan", "x None", lambda: ck.plot_plan(T11, None, np.zeros((11, 1)), title="plan"), "x")

scalar_cases("pendulum_flatness", "l", lambda l: ck.pendulum_flatness(l=l), 1.0, positive=True)
bad("pendulum_flatness", "m zero", lambda: ck.pendulum_flatness(m=0.0), "m")
bad("pendulum_flatness", "g NaN", lambda: ck.pendulum_flatness(g=np.nan), "g")
bad("two_wheeled_flatness", "reverse text", lambda: ck.two_wheeled_flatness(reverse="yes"), "reverse")
scalar_cases("car_like_flatness", "L", lambda L: ck.car_like_flatness(L=L), 2.5, positive=True)
bad("car_like_flatness", "reverse None", lambda: ck.car_like_flatness(reverse=None), "reverse")

def _pflat(T=2.0, start=(0.0, 0.0), end=(1.0, 0.0), flat=None):
    return ck.plan_flat_output(ck.pendulum_flatness() if flat is None else flat, T, start, end)

ok("FlatSystem", "phi good", lambda: ck.pendulum_flatness().phi([0.1, 0.0]))
bad("FlatSystem", "phi x wrong length", lambda: ck.pendulum_flatness().phi([0.1, 0.0, 0.0]), "x")
bad("FlatSystem", "phi x complex", lambda: ck.pendulum_flatness().phi([0.1 + 1j, 0.0]), "x")
bad("FlatSystem", "psi_x derivs None", lambda: ck.pendulum_flatness().psi_x(None), "derivs")
bad("FlatSystem", "psi_u derivs too few", lambda: ck.pendulum_flatness().psi_u([[0.0]]), "derivs")
bad("plan_flat_output", "flat a matrix", lambda: _pflat(flat=A2), "flat")
scalar_cases("plan_flat_output", "T", lambda T: _pflat(T=T), 2.0, positive=True)
matrix_cases("plan_flat_output", "start", lambda s: _pflat(start=s), [0.0, 0.0], shape=[0.0, 0.0, 0.0], empty=False)
matrix_cases("plan_flat_output", "end", lambda e: _pflat(end=e), [1.0, 0.0], shape=[0.0, 0.0, 0.0], empty=False)
ok("FlatPlan", "methods good", lambda: (_pflat().x(1.0), _pflat().u(1.0), _pflat().F(1.0, k=1)))
bad("FlatPlan", "F k negative", lambda: _pflat().F(1.0, k=-1), "k")
bad("FlatPlan", "x(t) complex", lambda: _pflat().x(1.0 + 1j), "t")
bad("FlatPlan", "u(t) NaN", lambda: _pflat().u(np.nan), "t")
bad("FlatPlan", "plot samples 0", lambda: _pflat().plot(samples=0), "samples")

def _robot(start=(0.0, 0.0, 0.0), end=(4.0, 2.0, np.pi / 2), T=6.0, **kw):
    return ck.plan_robot(start, end, T, **kw)

matrix_cases("plan_robot", "start", lambda s: _robot(start=s), [0.0, 0.0, 0.0], shape=[0.0, 0.0], empty=False)
matrix_cases("plan_robot", "end", lambda e: _robot(end=e), [4.0, 2.0, 1.5], shape=[0.0, 0.0], empty=False)
scalar_cases("plan_robot", "T", lambda T: _robot(T=T), 6.0, positive=True)
bad("plan_robot", "speed NaN", lambda: _robot(speed=np.nan), "speed")
bad("plan_robot", "speed complex", lambda: _robot(speed=1j), "speed")
bad("plan_robot", "L negative", lambda: _robot(L=-1.0), "L")

ok("symbolic_mass_spring_damper", "good", ck.symbolic_mass_spring_damper)
bad("symbolic_mass_spring_damper", "called with an argument", lambda: ck.symbolic_mass_spring_damper(2.0), "symbolic_mass_spring_damper")
ok("symbolic_flat_maps", "good", lambda: ck.symbolic_flat_maps("pendulum"))
bad("symbolic_flat_maps", "system unknown", lambda: ck.symbolic_flat_maps("cart"), "system")
bad("symbolic_flat_maps", "system None", lambda: ck.symbolic_flat_maps(None), "system")
bad("symbolic_flat_maps", "unknown parameter", lambda: ck.symbolic_flat_maps("pendulum", mass=2.0), "mass")
bad("symbolic_flat_maps", "parameter NaN", lambda: ck.symbolic_flat_maps("pendulum", m=np.nan), "m")
bad("symbolic_flat_maps", "parameter complex", lambda: ck.symbolic_flat_maps("pendulum", m=1j), "m")
ok("SymbolicFlatMaps", "functions good", lambda: ck.symbolic_flat_maps("pendulum").functions())

# ---------------------------------------------------------------------------
# chapter 3: stability and state feedback

for _name, _fn in (("place", ck.place), ("place_details", ck.place_details)):
    matrix_cases(_name, "A", lambda A, _fn=_fn: _fn(A, B2, P2), A2)
    matrix_cases(_name, "B", lambda B, _fn=_fn: _fn(A2, B, P2), B2, empty=False)
    poles_cases(_name, "poles", lambda p, _fn=_fn: _fn(A2, B2, p), P2)
    bad(_name, "uncontrollable", lambda _fn=_fn: _fn(A_UNCTRL, B_UNCTRL, P2), "B")
ok("place", "complex pair", lambda: ck.place(A2, B2, [-1 + 1j, -1 - 1j]))
ok("PlacementDetails", "fields", lambda: ck.place_details(A2, B2, P2).K)
# the degree of the polynomial is the number of roots: no count is wrong, only none at all
poles_cases("poly_from_roots", "poles", ck.poly_from_roots, P2, any_count=True)
for _name, _fn in (("is_stable", ck.is_stable),):
    matrix_cases(_name, "A", _fn, A2)
    scalar_cases(_name, "dt", lambda dt, _fn=_fn: _fn(A2, dt=dt), 0.1, positive=True, optional=True)
ok("describe_figure", "good", lambda: ck.describe_figure(ck.new_figure()[0]))
bad("describe_figure", "fig None", lambda: ck.describe_figure(None), "fig")
bad("describe_figure", "fig an Axes", lambda: ck.describe_figure(ck.new_figure()[1]), "fig")
ok("format_poles", "good", lambda: ck.format_poles([-1, -0.5 + 2j, -0.5 - 2j]))
bad("format_poles", "poles text", lambda: ck.format_poles("-1, -2"), "poles")
bad("format_poles", "poles None", lambda: ck.format_poles(None), "poles")
bad("format_poles", "poles empty", lambda: ck.format_poles([]), "poles")
ok("plot_poles", "good", lambda: ck.plot_poles({"open": [-1, -2], "closed": [-1 + 1j, -1 - 1j]}))
bad("plot_poles", "poles None", lambda: ck.plot_poles(None), "poles")
bad("plot_poles", "poles text", lambda: ck.plot_poles("-1, -2"), "poles")
bad("plot_poles", "poles NaN", lambda: ck.plot_poles([np.nan, -1.0]), "poles")
bad("plot_poles", "poles empty", lambda: ck.plot_poles([]), "poles")
bad("plot_poles", "dt negative", lambda: ck.plot_poles([-1.0], dt=-0.1), "dt")
bad("plot_poles", "ax not an Axes", lambda: ck.plot_poles([-1.0], ax="ax"), "ax")

function_cases("find_equilibria", "f", lambda f: ck.find_equilibria(f, u_eq=[0.0], n=2), pend_f, size=2)
bad("find_equilibria", "u_eq complex", lambda: ck.find_equilibria(pend_f, u_eq=[1j], n=2), "u_eq")
bad("find_equilibria", "u_eq NaN", lambda: ck.find_equilibria(pend_f, u_eq=[np.nan], n=2), "u_eq")
bad("find_equilibria", "guesses wrong shape", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], guesses=np.zeros((2, 3))), "guesses")
bad("find_equilibria", "guesses complex", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], guesses=np.zeros((2, 2)) + 1j), "guesses")
bad("find_equilibria", "n zero", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], n=0), "n")
bad("find_equilibria", "bounds reversed", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], n=2, bounds=(5.0, -5.0)), "bounds")
bad("find_equilibria", "bounds NaN", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], n=2, bounds=(np.nan, 5.0)), "bounds")
bad("find_equilibria", "count zero", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], n=2, count=0), "count")
bad("find_equilibria", "tol negative", lambda: ck.find_equilibria(pend_f, u_eq=[0.0], n=2, tol=-1.0), "tol")
function_cases("equilibrium_input", "f", lambda f: ck.equilibrium_input(f, [0.0, 0.0], m=1), pend_f, size=2)
matrix_cases("equilibrium_input", "x_eq", lambda x: ck.equilibrium_input(pend_f, x, m=1), [0.0, 0.0], shape=[0.0, 0.0, 0.0])
bad("equilibrium_input", "u_guess complex", lambda: ck.equilibrium_input(pend_f, [0.0, 0.0], u_guess=[1j]), "u_guess")
bad("equilibrium_input", "m negative", lambda: ck.equilibrium_input(pend_f, [0.0, 0.0], m=-1), "m")
ok("symbolic_equilibria", "good", lambda: ck.symbolic_equilibria(*_sym_f()))
bad("symbolic_equilibria", "f text", lambda: ck.symbolic_equilibria("x**2", _sym_f()[1]), "f")
bad("symbolic_equilibria", "unknowns None", lambda: ck.symbolic_equilibria(_sym_f()[0], None), "unknowns")

def _sym_f():
    import sympy
    x1, x2 = sympy.symbols("x1 x2")
    return [x2, -sympy.sin(x1)], [x1, x2]

function_cases("linearize", "f", lambda f: ck.linearize(f, [0.0, 0.0], [0.0]), pend_f, size=2)
matrix_cases("linearize", "x_eq", lambda x: ck.linearize(pend_f, x, [0.0]), [0.0, 0.0], shape=[0.0, 0.0, 0.0])
matrix_cases("linearize", "u_eq", lambda u: ck.linearize(pend_f, [0.0, 0.0], u), [0.0], shape=np.zeros((2, 2)), empty=False,
             optional=True)
bad("linearize", "not an equilibrium", lambda: ck.linearize(pend_f, [1.0, 0.0], [0.0]), "x_eq")
bad("linearize", "tol NaN", lambda: ck.linearize(pend_f, [0.0, 0.0], [0.0], tol=np.nan), "tol")
ok("symbolic_jacobian", "good", lambda: ck.symbolic_jacobian(*_sym_f()))
bad("symbolic_jacobian", "f None", lambda: ck.symbolic_jacobian(None, _sym_f()[1]), "f")
bad("symbolic_jacobian", "variables numbers", lambda: ck.symbolic_jacobian(_sym_f()[0], [1.0, 2.0]), "variables")
ok("linearize_symbolic", "good", lambda: ck.linearize_symbolic(_sym_f()[0], _sym_f()[1], x_eq=[0, 0]))
bad("linearize_symbolic", "x_eq wrong length", lambda: ck.linearize_symbolic(_sym_f()[0], _sym_f()[1], x_eq=[0, 0, 0]), "x_eq")
bad("linearize_symbolic", "x_eq complex", lambda: ck.linearize_symbolic(_sym_f()[0], _sym_f()[1], x_eq=[1j, 0]), "x_eq")

matrix_cases("StateFeedback", "K", lambda K: ck.StateFeedback(K)(0.0, np.zeros(2)), K2, shape=np.ones((1, 3)), empty=False)
# a column x (n, 1) is a batch of one state (as in simulate_batch): u is the column K x + u* (m, 1)
ok("StateFeedback", "x column with flat u_eq", lambda: _column_u(ck.StateFeedback(K2, u_eq=[1.0])(0.0, np.ones((2, 1)))))
bad("StateFeedback", "x wrong length", lambda: ck.StateFeedback(K2)(0.0, np.zeros(3)), "x")
bad("StateFeedback", "x complex", lambda: ck.StateFeedback(K2)(0.0, np.zeros(2) + 1j), "x")
bad("StateFeedback", "x_eq wrong length", lambda: ck.StateFeedback(K2, x_eq=[0.0, 0.0, 0.0]), "x_eq")
bad("StateFeedback", "u_eq NaN", lambda: ck.StateFeedback(K2, u_eq=[np.nan]), "u_eq")
ok("TrackingController", "good", lambda: ck.TrackingController(K2, lambda t: np.zeros(2), lambda t: np.zeros(1))(0.0, np.zeros(2)))
bad("TrackingController", "x_d not callable", lambda: ck.TrackingController(K2, np.zeros(2), lambda t: np.zeros(1)), "x_d")
bad("TrackingController", "u_d not callable", lambda: ck.TrackingController(K2, lambda t: np.zeros(2), 0.0), "u_d")
bad("TrackingController", "x_d raises", lambda: ck.TrackingController(K2, lambda t: 1 / 0, lambda t: np.zeros(1))(0.0, np.zeros(2)), "x_d")
bad("TrackingController", "x_d returns NaN", lambda: ck.TrackingController(K2, lambda t: np.full(2, np.nan), lambda t: np.zeros(1))(0.0, np.zeros(2)), "x_d")
bad("TrackingController", "x_d returns wrong shape", lambda: ck.TrackingController(K2, lambda t: np.zeros(3), lambda t: np.zeros(1))(0.0, np.zeros(2)), "x_d")
bad("TrackingController", "u_d returns None", lambda: ck.TrackingController(K2, lambda t: np.zeros(2), lambda t: None)(0.0, np.zeros(2)), "u_d")
bad("TrackingController", "x wrong length", lambda: ck.TrackingController(K2, lambda t: np.zeros(2), lambda t: np.zeros(1))(0.0, np.zeros(3)), "x")
matrix_cases("integral_augment", "A", lambda A: ck.integral_augment(A, B2, C2), A2)
matrix_cases("integral_augment", "B", lambda B: ck.integral_augment(A2, B, C2), B2, empty=False)
matrix_cases("integral_augment", "C", lambda C: ck.integral_augment(A2, B2, C), C2, shape=np.ones((1, 3)), empty=False,
             optional=True)
bad("integral_augment", "integrators zero", lambda: ck.integral_augment(A2, B2, C2, integrators=0), "integrators")
bad("integral_augment", "integrators fractional", lambda: ck.integral_augment(A2, B2, C2, integrators=1.5), "integrators")
K_E = np.array([[-1.0, -2.0, -3.0]])
ok("IntegralFeedback", "good", lambda: ck.IntegralFeedback(K_E, 1)(0.0, np.zeros(3)))
bad("IntegralFeedback", "K_E complex", lambda: ck.IntegralFeedback(K_E + 1j, 1), "K_E")
bad("IntegralFeedback", "n_integrator_states negative", lambda: ck.IntegralFeedback(K_E, -1), "n_integrator_states")
bad("IntegralFeedback", "x_E wrong length", lambda: ck.IntegralFeedback(K_E, 1)(0.0, np.zeros(2)), "x_E")
ok("with_integrators", "good", lambda: ck.with_integrators(sys2(), C2, r=[1.0]))
bad("with_integrators", "r complex", lambda: ck.with_integrators(sys2(), C2, r=[1j]), "r")
bad("with_integrators", "r wrong length", lambda: ck.with_integrators(sys2(), C2, r=[1.0, 2.0]), "r")
bad("with_integrators", "sys a matrix", lambda: ck.with_integrators(A2, C2), "sys")
bad("with_integrators", "C wrong shape", lambda: ck.with_integrators(sys2(), np.ones((1, 3))), "C")
matrix_cases("integral_closed_loop", "K_E", lambda K: ck.integral_closed_loop(A2, B2, K, C2), K_E, shape=np.ones((1, 2)), empty=False)
poles_cases("PendulumLinearizingController", "poles", lambda p: ck.PendulumLinearizingController(p)(0.0, np.zeros(2)), P2)
bad("PendulumLinearizingController", "l zero", lambda: ck.PendulumLinearizingController(P2, l=0.0), "l")
bad("PendulumLinearizingController", "theta_ref NaN", lambda: ck.PendulumLinearizingController(P2, theta_ref=np.nan), "theta_ref")
bad("PendulumLinearizingController", "x wrong length", lambda: ck.PendulumLinearizingController(P2)(0.0, np.zeros(3)), "x")

# ---------------------------------------------------------------------------
# chapter 4: observability and observers

for _name, _fn in (("obsv", ck.obsv), ("obsv_singular_values", ck.obsv_singular_values),
                   ("is_observable", ck.is_observable), ("ocf_transform", ck.ocf_transform)):
    matrix_cases(_name, "A", lambda A, _fn=_fn: _fn(A, C2), A2)
    matrix_cases(_name, "C", lambda C, _fn=_fn: _fn(A2, C), C2, shape=np.ones((1, 3)), empty=False)
bad("ocf_transform", "unobservable", lambda: ck.ocf_transform(A_UNCTRL, C_UNOBS), "C")
for _name, _fn in (("place_observer", ck.place_observer), ("place_observer_details", ck.place_observer_details)):
    matrix_cases(_name, "A", lambda A, _fn=_fn: _fn(A, C2, P2), A2)
    matrix_cases(_name, "C", lambda C, _fn=_fn: _fn(A2, C, P2), C2, shape=np.ones((1, 3)), empty=False)
    poles_cases(_name, "poles", lambda p, _fn=_fn: _fn(A2, C2, p), P2)
    bad(_name, "unobservable", lambda _fn=_fn: _fn(A_UNCTRL, C_UNOBS, P2), "C")
ok("ObserverDetails", "fields", lambda: ck.place_observer_details(A2, C2, P2).L)

for _name, _fn in (("observer_system", ck.observer_system), ("plant_with_observer", ck.plant_with_observer)):
    matrix_cases(_name, "L", lambda L, _fn=_fn: _fn(sys2(), L), L2, empty=False)
    bad(_name, "sys a matrix", lambda _fn=_fn: _fn(A2, L2), "sys")
    bad(_name, "sys discrete", lambda _fn=_fn: _fn(sys2(dt=0.1), L2), "sys")
for _name, _fn in (("output_feedback", ck.output_feedback), ("separation_eigenvalues", ck.separation_eigenvalues)):
    matrix_cases(_name, "K", lambda K, _fn=_fn: _fn(sys2(), K, L2), K2, shape=np.ones((1, 3)), empty=False)
    matrix_cases(_name, "L", lambda L, _fn=_fn: _fn(sys2(), K2, L), L2, empty=False)
    bad(_name, "sys None", lambda _fn=_fn: _fn(None, K2, L2), "sys")
XD = np.zeros((11, 2))
matrix_cases("observer_tracking_input", "K", lambda K: ck.observer_tracking_input(K, XD, np.zeros((11, 1))), K2,
             shape=np.ones((1, 3)), empty=False)
matrix_cases("observer_tracking_input", "x_d", lambda x: ck.observer_tracking_input(K2, x, np.zeros((11, 1))), XD,
             shape=np.zeros((11, 3)), empty=False)
matrix_cases("observer_tracking_input", "u_d", lambda u: ck.observer_tracking_input(K2, XD, u), np.zeros((11, 1)),
             empty=False)

Q2, R1 = np.eye(2), np.array([[1.0]])
matrix_cases("kalman_gain", "A", lambda A: ck.kalman_gain(A, C2, Q2, R1), A2)
matrix_cases("kalman_gain", "C", lambda C: ck.kalman_gain(A2, C, Q2, R1), C2, shape=np.ones((1, 3)), empty=False)
matrix_cases("kalman_gain", "Q", lambda Q: ck.kalman_gain(A2, C2, Q, R1), Q2)
matrix_cases("kalman_gain", "R", lambda R: ck.kalman_gain(A2, C2, Q2, R), R1, empty=False)
bad("kalman_gain", "Q not symmetric", lambda: ck.kalman_gain(A2, C2, [[1.0, 1.0], [0.0, 1.0]], R1), "Q")
bad("kalman_gain", "Q indefinite", lambda: ck.kalman_gain(A2, C2, np.diag([1.0, -1.0]), R1), "Q")
bad("kalman_gain", "R zero", lambda: ck.kalman_gain(A2, C2, Q2, [[0.0]]), "R")
bad("kalman_gain", "unobservable unstable mode", lambda: ck.kalman_gain(np.diag([1.0, -1.0]), [[0.0, 1.0]], Q2, R1), "C")

Y11 = np.zeros((11, 1))
def _kb(sys=None, t=T11, u=None, y=Y11, Q=Q2, R=R1, P0=np.eye(2), x0=np.zeros(2), **kw):
    return ck.kalman_bucy(sys2() if sys is None else sys, t, np.zeros((11, 1)) if u is None else u, y, Q, R, P0, x0, **kw)

ok("kalman_bucy", "good", _kb)
bad("kalman_bucy", "sys a matrix", lambda: _kb(sys=A2), "sys")
matrix_cases("kalman_bucy", "y", lambda y: _kb(y=y), Y11, empty=False)
matrix_cases("kalman_bucy", "u", lambda u: _kb(u=u), np.zeros((11, 1)), empty=False, optional=True)
matrix_cases("kalman_bucy", "P0", lambda P0: _kb(P0=P0), np.eye(2))
matrix_cases("kalman_bucy", "x0", lambda x0: _kb(x0=x0), np.zeros(2), shape=np.zeros(3), empty=False)
bad("kalman_bucy", "Q complex", lambda: _kb(Q=Q2 + 1j), "Q")
bad("kalman_bucy", "R NaN", lambda: _kb(R=[[np.nan]]), "R")
bad("kalman_bucy", "t decreasing", lambda: _kb(t=T11[::-1]), "t")
bad("kalman_bucy", "substeps zero", lambda: _kb(substeps=0), "substeps")
ok("KalmanResult", "sigma", lambda: _kb().sigma)

def _ekf(sys=None, y=Y11, x0=np.zeros(2), **kw):
    sysn = pend() if sys is None else sys
    return ck.extended_kalman_filter(sysn, T11, np.zeros((11, 1)), y, Q2, R1, np.eye(2), x0, **kw)

ok("extended_kalman_filter", "good", _ekf)
function_cases("extended_kalman_filter", "f", lambda f: _ekf(sys=ck.NonlinearSystem(f, n=2, m=1, h=lambda x, u: x[:1])),
               pend_f, size=2)
function_cases("extended_kalman_filter", "dfdx", lambda d: _ekf(dfdx=d), lambda x, u: np.array([[0.0, 1.0], [-9.81, 0.0]]), size=4,
               skip=("returns wrong shape",))
function_cases("extended_kalman_filter", "dhdx", lambda d: _ekf(dhdx=d), lambda x, u: np.array([[1.0, 0.0]]), size=2,
               skip=("returns wrong shape",))
bad("extended_kalman_filter", "dhdx returns wrong shape", lambda: _ekf(dhdx=lambda x, u: np.eye(2)), "dhdx")
bad("extended_kalman_filter", "dfdx returns wrong shape", lambda: _ekf(dfdx=lambda x, u: np.eye(3)), "dfdx")
matrix_cases("extended_kalman_filter", "y", lambda y: _ekf(y=y), np.zeros((11, 1)), empty=False)
matrix_cases("extended_kalman_filter", "x0", lambda x0: _ekf(x0=x0), np.zeros(2), shape=np.zeros(3), empty=False)
bad("extended_kalman_filter", "sys linear matrix", lambda: _ekf(sys=A2), "sys")
def _dkf(sys=None, y=Y11, u=None, Q=Q2, R=R1, P0=np.eye(2), x0=np.zeros(2)):
    return ck.discrete_kalman_filter(sys2(dt=0.1) if sys is None else sys, y, u, Q=Q, R=R, P0=P0, x0=x0)

ok("discrete_kalman_filter", "good", _dkf)
bad("discrete_kalman_filter", "sys a matrix", lambda: _dkf(sys=A2), "sys")
bad("discrete_kalman_filter", "sys continuous", lambda: _dkf(sys=sys2()), "sys", also="discrete")
bad("discrete_kalman_filter", "sys nonlinear", lambda: _dkf(sys=pend()), "sys")
# y sets the number of samples N, so its wrong shape is a wrong number of columns
matrix_cases("discrete_kalman_filter", "y", lambda y: _dkf(y=y), Y11, shape=np.zeros((11, 2)))
bad("discrete_kalman_filter", "y shorter than u", lambda: _dkf(y=np.zeros((10, 1)), u=np.zeros((11, 1))),
    "y", also="too short")
bad("discrete_kalman_filter", "y with no samples", lambda: _dkf(y=np.zeros((0, 1))), "y")
matrix_cases("discrete_kalman_filter", "u", lambda u: _dkf(u=u), np.zeros((11, 1)), empty=False, optional=True)
matrix_cases("discrete_kalman_filter", "Q", lambda Q: _dkf(Q=Q), Q2)
matrix_cases("discrete_kalman_filter", "R", lambda R: _dkf(R=R), R1, empty=False)
matrix_cases("discrete_kalman_filter", "P0", lambda P0: _dkf(P0=P0), np.eye(2))
matrix_cases("discrete_kalman_filter", "x0", lambda x0: _dkf(x0=x0), np.zeros(2), shape=np.zeros(3), empty=False)
bad("discrete_kalman_filter", "Q not symmetric", lambda: _dkf(Q=[[1.0, 1.0], [0.0, 1.0]]), "Q")
bad("discrete_kalman_filter", "Q indefinite", lambda: _dkf(Q=np.diag([1.0, -1.0])), "Q")
bad("discrete_kalman_filter", "R zero", lambda: _dkf(R=[[0.0]]), "R")
bad("discrete_kalman_filter", "P0 indefinite", lambda: _dkf(P0=np.diag([1.0, -1.0])), "P0")
matrix_cases("white_noise", "t", lambda t: ck.white_noise(t, 1.0, seed=0), T11, shape=np.ones((3, 3)), empty=False)
scalar_cases("white_noise", "intensity", lambda q: ck.white_noise(T11, q, seed=0), 1.0)
bad("white_noise", "intensity negative", lambda: ck.white_noise(T11, -1.0, seed=0), "intensity")
bad("white_noise", "seed text", lambda: ck.white_noise(T11, 1.0, seed="a"), "seed")
matrix_cases("van_loan", "A", lambda A: ck.van_loan(A, np.eye(2), 0.1), A2)
matrix_cases("van_loan", "Q", lambda Q: ck.van_loan(A2, Q, 0.1), np.eye(2))
bad("van_loan", "Q not symmetric", lambda: ck.van_loan(A2, [[1.0, 1.0], [0.0, 1.0]], 0.1), "Q")
bad("van_loan", "Q negative", lambda: ck.van_loan(A2, -np.eye(2), 0.1), "Q")
scalar_cases("van_loan", "dt", lambda dt: ck.van_loan(A2, np.eye(2), dt), 0.1, positive=True)
def _swn(**kw):
    args = dict(u=np.zeros((11, 1)), x0=np.zeros(2), Q=Q2, R=R1, seed=0)
    args.update(kw)
    return ck.simulate_with_noise(sys2(), T11, **args)

ok("simulate_with_noise", "good", _swn)
bad("simulate_with_noise", "Q complex", lambda: _swn(Q=Q2 + 1j), "Q")
bad("simulate_with_noise", "Q wrong shape", lambda: _swn(Q=np.eye(3)), "Q")
bad("simulate_with_noise", "R NaN", lambda: _swn(R=[[np.nan]]), "R")
bad("simulate_with_noise", "R negative", lambda: _swn(R=[[-1.0]]), "R")
bad("simulate_with_noise", "x0 complex", lambda: _swn(x0=[1j, 0.0]), "x0")

# ---------------------------------------------------------------------------
# course tools

bad("lecture_mode", "on text", lambda: ck.lecture_mode("yes"), "on")
bad("lecture_mode", "on None", lambda: ck.lecture_mode(None), "on")
ok("is_lecture_mode", "good", ck.is_lecture_mode)
bad("is_lecture_mode", "called with an argument", lambda: ck.is_lecture_mode(True), "is_lecture_mode")
ok("new_figure", "good", lambda: ck.new_figure(2, 1))
bad("new_figure", "nrows zero", lambda: ck.new_figure(0, 1), "nrows")
bad("new_figure", "ncols text", lambda: ck.new_figure(1, "2"), "ncols")
bad("new_figure", "nrows fractional", lambda: ck.new_figure(1.5, 1), "nrows")
bad("new_figure", "figsize one number", lambda: ck.new_figure(1, 1, figsize=5), "figsize")
bad("new_figure", "figsize NaN", lambda: ck.new_figure(1, 1, figsize=(np.nan, 3)), "figsize")
bad("new_figure", "figsize negative", lambda: ck.new_figure(1, 1, figsize=(-4, 3)), "figsize")
ok("course_subplots", "good", lambda: ck.course_subplots(ck.new_figure()[0], 1, 2))
bad("course_subplots", "fig an Axes", lambda: ck.course_subplots(ck.new_figure()[1]), "fig")
bad("course_subplots", "nrows zero", lambda: ck.course_subplots(ck.new_figure()[0], 0), "nrows")
ok("curve_style", "good", lambda: ck.curve_style(5, marker=True))
bad("curve_style", "k negative", lambda: ck.curve_style(-1), "k")
bad("curve_style", "k fractional", lambda: ck.curve_style(1.5), "k")
bad("curve_style", "marker text", lambda: ck.curve_style(0, marker="yes"), "marker")
ok("contrast_ratio", "good", lambda: ck.contrast_ratio("#0072B2", (1, 1, 1, 0.5)))
bad("contrast_ratio", "foreground no colour", lambda: ck.contrast_ratio("blueish"), "foreground")
bad("contrast_ratio", "background a number", lambda: ck.contrast_ratio("k", 3), "background")
ok("text_colour", "good", lambda: ck.text_colour(ck.PALETTE["vermillion"]))
bad("text_colour", "colour None", lambda: ck.text_colour(None), "colour")
bad("text_colour", "background dark", lambda: ck.text_colour("C0", background="black"), "background")
ok("fit_margins", "good", lambda: ck.fit_margins(ck.new_figure()[0]))
bad("fit_margins", "fig None", lambda: ck.fit_margins(None), "fig")
bad("fit_margins", "fig an Axes", lambda: ck.fit_margins(ck.new_figure()[1]), "fig")
ok("check_environment", "good", lambda: ck.check_environment(show=False))
bad("check_environment", "show text", lambda: ck.check_environment(show="no"), "show")
ok("EnvironmentReport", "ok", lambda: ck.check_environment(show=False).ok)
ok("find_widget_frontend", "good", lambda: ck.find_widget_frontend([]))
bad("find_widget_frontend", "dirs a string", lambda: ck.find_widget_frontend("/nonexistent"), "dirs")
bad("find_widget_frontend", "dirs a number", lambda: ck.find_widget_frontend(3), "dirs")

# ---------------------------------------------------------------------------
# models

for _name, _param, _good, _pos in (("bank_account", "rate", 0.03, False), ("mass_spring_damper", "m", 1.0, True),
                                   ("mass_spring_damper", "k", 2.0, False), ("compartment", "V1", 1.0, True),
                                   ("compartment", "q", 0.5, False), ("pendulum", "l", 1.0, True),
                                   ("pendulum", "d_theta", 0.0, False), ("lorenz", "p", 10.0, False),
                                   ("car_like_robot", "L", 2.5, True), ("vehicle", "m", 1000.0, True),
                                   ("vehicle", "d", 50.0, False)):
    scalar_cases(f"models.{_name}", _param,
                 lambda v, _name=_name, _param=_param: getattr(models, _name)(**{_param: v}), _good, positive=_pos)
bad("models.vehicle", "sensor unknown", lambda: models.vehicle(sensor="radar"), "sensor")
bad("models.vehicle", "sensor None", lambda: models.vehicle(sensor=None), "sensor")
for _name in ("two_wheeled_robot", "state_example", "fibonacci"):
    ok(f"models.{_name}", "good", getattr(models, _name))
    bad(f"models.{_name}", "called with an argument", lambda _name=_name: getattr(models, _name)(1.0), _name)
bad("models.two_wheeled_robot", "f with wrong x", lambda: models.two_wheeled_robot().f(np.zeros(2), np.zeros(2)), "x")
bad("models.pendulum", "f with wrong u", lambda: models.pendulum().f(np.zeros(2), np.zeros(3)), "u")

# ---------------------------------------------------------------------------
# issue 25: the tail of bad inputs (hangs, raw internal errors, silent acceptances) and the
# systems of python-control and scipy.signal

def _control():
    import control
    return control


def _signal():
    import scipy.signal
    return scipy.signal


def _vdp(mu):
    return ck.NonlinearSystem(lambda x, u: np.array([x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]]), n=2)


ok("simulate", "python-control system", lambda: ck.simulate(_control().ss(A2, B2, C2, 0), T11))
ok("simulate", "scipy.signal system", lambda: ck.simulate(_signal().lti(A2, B2, C2, 0), T11))
bad("simulate", "python-control transfer function", lambda: ck.simulate(_control().tf([1], [1, 2]), T11), "sys",
    also=r"control\.xferfcn\.TransferFunction(?s:.*)StateSpace\.from_control")
bad("simulate", "scipy.signal transfer function", lambda: ck.simulate(_signal().lti([1], [1, 2]), T11), "sys",
    also=r"StateSpace\.from_scipy")
bad("simulate", "python-control dt=True", lambda: ck.simulate(_control().ss(A2, B2, C2, 0, True), T11), "sys",
    also=r"StateSpace\.from_control")
bad("simulate", "stiff Van der Pol with DOP853", lambda: ck.simulate(_vdp(1e4), np.linspace(0, 1000, 11), x0=[2.0, 0.0],
                                                                     method="DOP853"), "method", also="Radau")
ok("is_stable", "python-control system", lambda: ck.is_stable(_control().ss(A2, B2, C2, 0)))
bad("is_stable", "python-control transfer function", lambda: ck.is_stable(_control().tf([1], [1, 2])), "A",
    also=r"StateSpace\.from_control")
ok("similarity_transform", "python-control system", lambda: ck.similarity_transform(_control().ss(A2, B2, C2, 0), np.eye(2)))
ok("cascade", "scipy.signal systems", lambda: ck.cascade(_signal().StateSpace(A2, B2, C2, 0), sys2()))
ok("observer_system", "python-control system", lambda: ck.observer_system(_control().ss(A2, B2, C2, 0), L2))
ok("kalman_bucy", "python-control system", lambda: _kb(sys=_control().ss(A2, B2, C2, 0)))
ok("linearize", "python-control system", lambda: ck.linearize(_control().ss(A2, B2, C2, 0), [0.0, 0.0], [0.0]))
for _name, _fn in (("place", lambda A: ck.place(A, B2, P2)), ("ctrb", lambda A: ck.ctrb(A, B2)),
                   ("obsv", lambda A: ck.obsv(A, C2)), ("kalman_gain", lambda A: ck.kalman_gain(A, C2, Q2, R1))):
    bad(_name, "A a python-control system", lambda _fn=_fn: _fn(_control().ss(A2, B2, C2, 0)), "A",
        also=r"sys\.A(?s:.*)StateSpace\.from_control")
bad("place", "200 states, 3 inputs", lambda: ck.place(np.random.default_rng(0).normal(size=(200, 200)),
                                                      np.random.default_rng(1).normal(size=(200, 3)),
                                                      -np.linspace(1, 20, 200)), "A", also="100 states")
bad("place_observer", "200 states, 3 outputs", lambda: ck.place_observer(np.random.default_rng(0).normal(size=(200, 200)),
                                                                          np.random.default_rng(1).normal(size=(3, 200)),
                                                                          -np.linspace(1, 20, 200)), "A", also="100 states")
bad("kalman_bucy", "substeps 10**9", lambda: _kb(substeps=10**9), "substeps", also="at most 1000")
bad("extended_kalman_filter", "substeps 10**9", lambda: _ekf(substeps=10**9), "substeps", also="at most 1000")
bad("kalman_gain", "Q zero, undriven double integrator",
    lambda: ck.kalman_gain([[0.0, 1.0], [0.0, 0.0]], C2, np.zeros((2, 2)), R1), "Q", also=r"does not drive it")
bad("OpenLoopPlan", "plot samples 10**12", lambda: _olc().plot(samples=10**12), "samples")
bad("FlatPlan", "plot samples 10**12", lambda: _pflat().plot(samples=10**12), "samples")
for _name, _fn in (("symbolic_ctrb", ck.symbolic_ctrb), ("symbolic_linear_flatness", ck.symbolic_linear_flatness)):
    bad(_name, "A 0-d array", lambda _fn=_fn: _fn(np.array(1.0), [[1.0]]), "A")
    bad(_name, "A 3-D array", lambda _fn=_fn: _fn(np.zeros((2, 2, 2)), B2), "A")
    bad(_name, "B 3-D array", lambda _fn=_fn: _fn(A2, np.zeros((2, 1, 1))), "B")


def _pendulum_maps(which=0, **params):
    return ck.symbolic_flat_maps("pendulum", **(params or dict(m=1.0, l=1.0, g=9.81, d_theta=0.0))).functions()[which]


ok("SymbolicFlatMaps", "functions called", lambda: (_pendulum_maps(0)([0.1, 0.2, 0.3]), _pendulum_maps(1)([0.1, 0.2, 0.3])))
bad("SymbolicFlatMaps", "values too short", lambda: _pendulum_maps(0)([0.0]), "values")
bad("SymbolicFlatMaps", "values a dict", lambda: _pendulum_maps(1)({"a": 1}), "values")
bad("SymbolicFlatMaps", "values None", lambda: _pendulum_maps(0)(None), "values")
bad("SymbolicFlatMaps", "values text", lambda: _pendulum_maps(0)("abc"), "values")
bad("SymbolicFlatMaps", "values wrong columns", lambda: ck.symbolic_flat_maps("two_wheeled").functions()[0]([[0.0], [0.0], [0.0]]),
    "values")
bad("SymbolicFlatMaps", "parameters still symbols", lambda: ck.symbolic_flat_maps("pendulum").functions()[1]([0.1, 0.2, 0.3]),
    "psi_u", also="d_theta, g, l, m")
bad("plot_state_plane", "ax text", lambda: ck.plot_state_plane([result().x], ax="ax"), "ax")
bad("plot_state_plane", "ax a number", lambda: ck.plot_state_plane([result().x], ax=3), "ax")
bad("StateFeedback", "x NaN", lambda: ck.StateFeedback(K2)(0.0, np.array([np.nan, 0.0])), "x")
bad("StateFeedback", "x inf", lambda: ck.StateFeedback(K2)(0.0, np.array([np.inf, 0.0])), "x")
bad("TrackingController", "x NaN", lambda: ck.TrackingController(K2, lambda t: np.zeros(2), lambda t: np.zeros(1))(
    0.0, np.array([np.nan, 0.0])), "x")
bad("IntegralFeedback", "x_E NaN", lambda: ck.IntegralFeedback(K_E, 1)(0.0, np.array([0.0, np.nan, 0.0])), "x_E")
bad("PendulumLinearizingController", "x NaN", lambda: ck.PendulumLinearizingController(P2)(0.0, np.array([np.nan, 0.0])), "x")
for _label, _flag in (("text 'no'", "no"), ("None", None), ("1", 1)):
    bad("linearize", f"check_equilibrium {_label}", lambda _flag=_flag: ck.linearize(pend_f, [0.0, 0.0], [0.0],
                                                                                     check_equilibrium=_flag),
        "check_equilibrium")
bad("linearize", "u_eq missing for an f that reads u", lambda: ck.linearize(pend_f, [0.0, 0.0]), "u_eq", also="missing")
bad("find_equilibria", "u_eq missing for an f that reads u", lambda: ck.find_equilibria(pend_f, n=2), "u_eq")
bad("linearize", "dt zero", lambda: ck.linearize(linear_f, [0.0, 0.0], [0.0], dt=0), "dt", also=r"dt=None")
bad("StateSpace", "dt zero points to None", lambda: ck.StateSpace(A2, B2, C2, dt=0), "dt", also=r"dt=None")
bad("symbolic_jacobian", "variables empty", lambda: ck.symbolic_jacobian(_sym_f()[0], []), "variables")
bad("symbolic_jacobian", "variables text", lambda: ck.symbolic_jacobian(_sym_f()[0], ["x1", "x2"]), "variables")
bad("symbolic_jacobian", "f empty", lambda: ck.symbolic_jacobian([], _sym_f()[1]), "f")
bad("linearize_symbolic", "x empty", lambda: ck.linearize_symbolic(_sym_f()[0], [], x_eq=[]), "x")
bad("linearize_symbolic", "x text", lambda: ck.linearize_symbolic(_sym_f()[0], "x1 x2", x_eq=[0, 0]), "x")
bad("plot_plan", "t decreasing", lambda: ck.plot_plan(T11[::-1], np.zeros((11, 2)), np.zeros((11, 1)), title="plan"), "t")
warns("similarity_transform", "T of condition 1e15", lambda: ck.similarity_transform(sys2(), [[1.0, 1.0], [1.0, 1.0 + 1e-15]]),
      "T", also="nearly singular")
warns("place", "A scaled by 1e200", lambda: ck.place(A2 * 1e200, B2, P2), "poles", also="largest error")


# ---------------------------------------------------------------------------
# issue 35: the tail after issue 25 (one hang, raw errors, NaN/inf answers, quiet misses)

bad("simulate", "Van der Pol stiff on the way, DOP853", lambda: ck.simulate(_vdp(1e4), np.linspace(0, 100, 11), x0=[1.0, 0.0],
                                                                           method="DOP853"), "method", also="stiff(?s:.*)Radau")
ok("plan_robot", "T 1e300 (the slowest point overflowed)", lambda: _robot(T=1e300).min_speed)
for _name, _call in (("poly_trajectory", lambda: ck.poly_trajectory(1e-300, [0.0, 0.0], [1.0, 0.0])(0.5e-300, k=2)),
                     ("open_loop_control", lambda: _olc(T=1e-300).ud(0.5e-300)),
                     ("plan_flat_output", lambda: _pflat(T=1e-300).u(0.5e-300)),
                     ("plan_robot", lambda: _robot(T=1e-300).u(0.5e-300))):
    bad(_name, "T 1e-300 (derivatives overflow)", _call, "T", also="out of reach")

# symbolic_equilibria of equations without a closed form: tests/test_equilibria.py (sympy takes
# seconds to give up, beyond this table's deadline on a loaded machine)
bad("symbolic_equilibria", "f contains sympy.nan", lambda: ck.symbolic_equilibria([_sym_f()[0][0], _sympy().nan], _sym_f()[1]), "f")
bad("symbolic_jacobian", "f contains sympy.nan", lambda: ck.symbolic_jacobian([_sym_f()[0][0] * _sympy().nan, 0], _sym_f()[1]), "f")
bad("linearize_symbolic", "f contains sympy.nan", lambda: ck.linearize_symbolic([_sym_f()[0][0], _sympy().nan], _sym_f()[1], x_eq=[0, 0]), "f")
bad("linearize_symbolic", "u_eq text", lambda: ck.linearize_symbolic(_sym_f()[0], _sym_f()[1][:1], u=_sym_f()[1][1:], x_eq=[0],
                                                                    u_eq="a"), "u_eq")
def _sym_square():
    """Four state symbols as a 2x2 matrix (a mistake: variables are a list) and an f of them."""
    X = _sympy().Matrix(2, 2, _sympy().symbols("x1:5"))
    return [v ** 2 - 1 for v in X], X


bad("symbolic_jacobian", "variables a 2x2 matrix", lambda: ck.symbolic_jacobian(*_sym_square()), "variables")
bad("symbolic_equilibria", "unknowns a 2x2 matrix", lambda: ck.symbolic_equilibria(*_sym_square()), "unknowns")
bad("linearize_symbolic", "x a 2x2 matrix", lambda: ck.linearize_symbolic(*_sym_square(), x_eq=[1, 1, 1, 1]), "x")
for _label, _m in (("zero", 0.0), ("negative", -1.0)):
    bad("symbolic_flat_maps", f"m {_label}", lambda _m=_m: ck.symbolic_flat_maps("pendulum", m=_m), "m")
bad("FlatSystem", "psi_x derivs complex", lambda: ck.pendulum_flatness().psi_x([0.1 + 1j, 0.0]), "derivs")
bad("FlatSystem", "psi_u derivs numpy complex", lambda: ck.pendulum_flatness().psi_u(np.array([0.1 + 1j, 0.0, 0.0])), "derivs")
for _name, _call in (("charpoly", lambda: ck.charpoly(A2 * 1e200)),
                     ("linear_flatness", lambda: ck.linear_flatness(A2 * 1e200, B2 * 1e200)),
                     ("place_details", lambda: ck.place_details(A2 * 1e200, B2 * 1e200, P2)),
                     ("place_observer_details", lambda: ck.place_observer_details(A2 * 1e200, C2 * 1e200, P2))):
    bad(_name, "entries scaled by 1e200 (coefficients overflow)", _call, "A", also="float range")
bad("simulate_with_noise", "unstable system overflows", lambda: ck.simulate_with_noise(
    ck.StateSpace([[1.0]], [[1.0]], [[1.0]]), np.linspace(0.0, 1000.0, 1001), x0=[1.0], Q=[[1.0]], R=[[1.0]], seed=0),
    "t", also="overflows by t")
for _name, _call in (("lti_step_matrices", lambda B: ck.lti_step_matrices(A2, B, 0.1)),
                     ("integral_augment", lambda B: ck.integral_augment(A2, B, C2)),
                     ("symbolic_ctrb", lambda B: ck.symbolic_ctrb(A2, B))):
    bad(_name, "B of zero columns", lambda _call=_call: _call(np.zeros((2, 0))), "B", also="no columns")
ok("lti_step_matrices", "B scaled by 1e200 (was refused as an overflow)", lambda: ck.lti_step_matrices(A2, B2 * 1e200, 0.1))
bad("plot_plan", "x of zero columns", lambda: ck.plot_plan(T11, np.zeros((11, 0)), np.zeros((11, 1)), title="plan"), "x")
bad("plot_plan", "u of zero columns", lambda: ck.plot_plan(T11, np.zeros((11, 2)), np.zeros((11, 0)), title="plan"), "u")
bad("plot_state_plane", "labels a string for two trajectories", lambda: ck.plot_state_plane([result().x, result().x], labels="ab"),
    "labels")
bad("plot_euler_comparison", "state a list", lambda: ck.plot_euler_comparison(result(), [euler_result()], state=[0]), "state")
bad("feedforward", "traj's second derivative NaN", lambda: ck.feedforward(
    [2.0, 3.0], 1.0, lambda t, k=0: np.nan if k == 2 else 0.0), "traj")
_A3, _B32 = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 2.0, 3.0]]), np.array([[0.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
warns("place", "pole repeated 3 times with 2 inputs (one Jordan chain)", lambda: ck.place(_A3, _B32, [-2.0] * 3), "poles",
      also="Jordan chain")
warns("place_observer", "pole repeated 3 times with 2 outputs (one Jordan chain)",
      lambda: ck.place_observer(_A3, _B32.T, [-2.0] * 3), "poles", also="Jordan chain")
warns("ccf_transform", "30 random states (the result is no CCF; the issue had 200)", lambda: ck.ccf_transform(
    np.random.default_rng(0).normal(size=(30, 30)), np.random.default_rng(1).normal(size=(30, 1))), "A",
    also="canonical form")

def _same_answer(controller, x):
    """controller(0, x) for x a sympy Matrix of numbers, which must equal the answer for the array."""
    got, want = controller(0.0, _sympy().Matrix(x)), controller(0.0, np.array(x, dtype=float))
    if np.shape(got) != np.shape(want) or not np.allclose(got, want, rtol=1e-15, atol=0):
        raise AssertionError(f"a sympy Matrix gave {got!r}, the array {want!r}")
    return got


ok("StateFeedback", "x a sympy Matrix answers as the array", lambda: _same_answer(ck.StateFeedback(K2), [1, 2]))
ok("PendulumLinearizingController", "x a sympy Matrix answers as the array",
   lambda: _same_answer(ck.PendulumLinearizingController(P2), [1, 2]))

# ---------------------------------------------------------------------------
# exercises: feedback, never an exception and never "Correct"

#: every check of the course (a new chapter's too) and the number of answers it takes
_EXERCISE_ARGS = {label.split(".")[1]: len(inspect.signature(check).parameters)
                  for label, check in check_functions().items()}
for _check, _count in _EXERCISE_ARGS.items():
    # the feedback names the problem; for a list of poles or of True/False answers a complex
    # 2x2 matrix is first of all the wrong number of entries
    for _label, _value, _says in (("None", None, "None"), ("text", "[[1, 2]]", "text|received str|received '"),
                                  ("complex", np.ones((2, 2)) + 1j, "complex|function|must list|entries|do not match"),
                                  ("NaN", np.full((2, 2), np.nan), "NaN|function|must list|entries")):
        feedback(f"exercises.{_check}", _label,
                 lambda _check=_check, _count=_count, _value=_value: getattr(ex, _check)(*[_value] * _count), _says)

# issue 35: a rank typed as text stays refused, with a message about the rank (not a matrix example)
feedback("exercises.check_kalman_decision", "rank the string '2'", lambda: ex.check_kalman_decision("2", False),
         r"rank must be a whole number, not text: received the string '2'; type the number without quotes")

# ---------------------------------------------------------------------------
# each chapter's explorer functions: its own file of cases tests/cases_chN.py (docs/extending.md),
# which takes bad, ok, scalar_cases, ... from this module; CHAPTER_CASES are those modules, where
# the tests of exercises and explorers also find a chapter's WRONG_ANSWERS and STATED
CHAPTER_CASES = [importlib.import_module(_path.stem)
                 for _path in sorted(Path(__file__).parent.glob("cases_ch*.py"), key=lambda p: int(p.stem[8:]))]

# ---------------------------------------------------------------------------
# the worker


class CaseTimeout(BaseException):
    """Raised by the alarm inside a case that runs past DEADLINE (not an Exception, so no
    `except Exception` in the code under test can swallow it)."""


def _alarm(signum, frame):
    raise CaseTimeout()


def _run_case(case: Case) -> dict:
    import matplotlib.pyplot as plt
    out = io.StringIO()
    try:
        with warnings.catch_warnings():
            # a warning on the way to an error is a defect too (e.g. numpy's ComplexWarning)
            warnings.simplefilter("error")
            warnings.simplefilter("ignore", DeprecationWarning)
            warnings.simplefilter("ignore", PendingDeprecationWarning)
            with contextlib.redirect_stdout(out):
                value = case.call()
    except CaseTimeout:
        return dict(status="hang", detail=f"still running after {DEADLINE} s")
    except BaseException as err:  # anything a case raises is data for the verdict
        text = f"{type(err).__name__}: {err}"
        if case.kind == "bad" and isinstance(err, (ValueError, TypeError)) or \
                case.kind == "warns" and isinstance(err, (ValueError, TypeError, ck.CoursekitWarning)):
            if re.search(case.pattern, str(err)):
                return dict(status="pass", detail=text)
            return dict(status="fail", detail=f"message does not match {case.pattern!r}: {text}")
        where = traceback.extract_tb(err.__traceback__)[-1]
        return dict(status="fail", detail=f"{text} (at {where.filename.split('/')[-1]}:{where.lineno})")
    finally:
        plt.close("all")
    printed = out.getvalue()
    if case.kind == "ok":
        return dict(status="pass", detail="")
    if case.kind in ("bad", "warns"):
        return dict(status="fail", detail=f"no error; returned {type(value).__name__}")
    if isinstance(value, CheckResult) and not value and printed.startswith("Not yet") and re.search(case.pattern, printed):
        return dict(status="pass", detail=printed)
    return dict(status="fail", detail=f"returned {value!r}, printed {printed!r}")


def main() -> None:
    # the libraries the cases use, imported before the first deadline starts
    import matplotlib.pyplot  # noqa: F401
    import scipy.integrate  # noqa: F401
    import scipy.linalg  # noqa: F401
    import sympy  # noqa: F401
    by_id = {case.id: case for case in CASES}
    signal.signal(signal.SIGALRM, _alarm)
    for line in sys.stdin:
        case = by_id[line.strip()]
        print(MARK + json.dumps({"start": case.id}), flush=True)
        # the alarm stops a hang in Python code; the fault handler kills the worker when
        # the hang is inside compiled code that never returns to the interpreter
        faulthandler.dump_traceback_later(DEADLINE + 5, exit=True)
        signal.alarm(DEADLINE)
        start = time.perf_counter()
        try:
            verdict = _run_case(case)
        finally:
            signal.alarm(0)
            faulthandler.cancel_dump_traceback_later()
        print(MARK + json.dumps(dict(verdict, id=case.id, seconds=time.perf_counter() - start)), flush=True)
