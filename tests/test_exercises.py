"""The exercise checks: right answers in any form pass, typical mistakes are named.

Every wrong-answer case asserts the printed feedback names the problem and
never contains the solution's numbers.
"""

import inspect
import re

import numpy as np
import pytest
import sympy as sp

import coursekit.exercises as ex
from coursekit.exercises._feedback import CheckResult
from coursekit.placement import place
from coursekit.tools.chapters import chapter_modules

from bad_input_cases import CHAPTER_CASES

MSD = ex.MSD
CP = ex.COMPARTMENT
PEN = ex.PENDULUM
LIN = ex.LINEARIZE


def _verdict(result) -> bool:
    """A check's verdict: its result must be a CheckResult; True when correct."""
    assert isinstance(result, CheckResult), f"a check returned {type(result).__name__}, not a CheckResult"
    return bool(result)


def _msd():
    m, d, k = MSD["m"], MSD["d"], MSD["k"]
    return [[0, 1], [-k / m, -d / m]], [[0], [1 / m]], [[1, 0]]


def _compartment():
    V1, V2, q, q0, c0 = (CP[k] for k in ("V1", "V2", "q", "q0", "c0"))
    return [[-(q + q0) / V1, q / V1], [q / V2, -q / V2]], [[c0 / V1], [0]], [[0, 1]]


def _pendulum_f(x, u):
    return [x[1], -PEN["g"] / PEN["l"] * np.sin(x[0]) - PEN["d_theta"] / PEN["m"] * x[1]
            + u[0] / (PEN["m"] * PEN["l"] ** 2)]


def _ode():
    a0, a1, a2 = ex.ODE["a"]
    return [[0, 1, 0], [0, 0, 1], [-a0, -a1, -a2]], [[0], [0], [ex.ODE["b"]]], [[1, 0, 0]]


def _euler():
    A, B, Ts = np.array(ex.EULER["A"]), np.array(ex.EULER["B"]), ex.EULER["Ts"]
    return np.eye(2) + Ts * A, Ts * B


def _ctrb():
    A, B = np.array(ex.CTRB["A"]), np.array(ex.CTRB["B"])
    return np.hstack([B, A @ B, A @ A @ B])


def _ccf_T():
    A, B = np.array(ex.CCF["A"]), np.array(ex.CCF["B"])
    T1 = np.array([[0, 1]]) @ np.linalg.inv(np.hstack([B, A @ B]))
    return np.vstack([T1, T1 @ A])


def _car():
    L, (d1, d2), (dd1, dd2) = ex.CAR["L"], ex.CAR["dF"], ex.CAR["ddF"]
    v = np.hypot(d1, d2)
    return v, np.arctan(L * (dd2 * d1 - dd1 * d2) / (d1**2 + d2**2) / v)


def _alpha():
    T, (x10, x20), (x1T, x2T) = ex.TRAJECTORY["T"], ex.TRAJECTORY["x0"], ex.TRAJECTORY["xT"]
    a2, a3 = np.linalg.solve([[T**2, T**3], [2 * T, 3 * T**2]], [x1T - x10 - x20 * T, x2T - x20])
    return [x10, x20, a2, a3]


def _K(data):
    return place(np.array(data["A"]), np.array(data["B"]), data["poles"])


def _lin():
    m, l, g, d = LIN["m"], LIN["l"], LIN["g"], LIN["d_theta"]
    return [[0, 1], [g / l, -d / m]], [[0], [1 / (m * l**2)]]


def _obsv():
    A, C = np.array(ex.OBSV["A"]), np.array(ex.OBSV["C"])
    return np.vstack([C, C @ A, C @ A @ A])


def _L():
    A, C = np.array(ex.OBSERVER["A"]), np.array(ex.OBSERVER["C"])
    return -place(A.T, C.T, ex.OBSERVER["poles"]).T


def _sep():
    A, B, C, K, L = (np.array(ex.SEPARATION[k]) for k in ("A", "B", "C", "K", "L"))
    return np.concatenate([np.linalg.eigvals(A + B @ K), np.linalg.eigvals(A - L @ C)])


#: checker -> its correct answer (a tuple of arguments); matrices given as nested lists or arrays
RIGHT = {
    "check_msd_state_space": _msd,
    "check_compartment_state_space": _compartment,
    "check_ode_realization": _ode,
    "check_euler_discretization": _euler,
    "check_ctrb_matrix": lambda: (_ctrb(),),
    "check_ccf_transform": lambda: (_ccf_T(),),
    "check_car_flatness": _car,
    "check_trajectory_coefficients": lambda: (_alpha(),),
    "check_gain_ccf": lambda: (_K(ex.PLACE_CCF),),
    "check_gain_general": lambda: (_K(ex.PLACE_GENERAL),),
    "check_pendulum_linearization": _lin,
    "check_obsv_matrix": lambda: (_obsv(),),
    "check_observer_gain": lambda: (_L(),),
}


def _as_list(a):
    return np.asarray(a, dtype=float).tolist()


def _as_sympy(a):
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 0:
        return sp.Float(float(arr))
    # rationals, as a student working with sympy by hand would have them
    return sp.Matrix(arr.reshape(arr.shape[0], -1) if arr.ndim == 2 else arr).applyfunc(
        lambda v: sp.nsimplify(v, tolerance=1e-12, rational=True))


def _as_1d(a):
    arr = np.asarray(a, dtype=float)
    return arr.ravel() if arr.ndim == 2 and 1 in arr.shape else arr


def _as_complex(a):
    """The answer as np.linalg.eig-based work gives it: complex dtype, imaginary parts zero."""
    return np.asarray(a, dtype=float) + 0j


def _as_complex_rounded(a):
    """Complex, with imaginary parts of rounding size (1e-15 of the largest entry)."""
    arr = np.asarray(a, dtype=float)
    return arr + 1e-15j * max(1.0, float(np.abs(arr).max())) * np.cos(np.arange(arr.size)).reshape(arr.shape)


FORMS = {"list": _as_list, "array": np.asarray, "sympy": _as_sympy, "flat": _as_1d,
         "complex, zero imaginary parts": _as_complex, "complex, imaginary parts of rounding": _as_complex_rounded}


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("name", RIGHT)
def test_right_answer_in_every_form_is_correct(name, form, capsys):
    args = tuple(FORMS[form](a) for a in RIGHT[name]())
    assert _verdict(getattr(ex, name)(*args)) is True
    out = capsys.readouterr().out
    assert out.startswith("Correct:"), out


@pytest.mark.parametrize("name", ["check_ccf_transform", "check_msd_state_space", "check_trajectory_coefficients"])
def test_answers_rounded_to_three_digits_are_accepted(name):
    args = tuple(np.round(np.asarray(a, dtype=float), 3) for a in RIGHT[name]())
    assert _verdict(getattr(ex, name)(*args)) is True


@pytest.mark.parametrize("name", ["check_ccf_transform", "check_gain_ccf", "check_observer_gain"])
def test_complex_answers_with_real_imaginary_parts_stay_refused(name, capsys):
    # issue 35 accepts imaginary parts of rounding size only: 1e-6 of the entries is a wrong answer
    args = tuple(np.asarray(a, dtype=float) * (1 + 1e-6j) for a in RIGHT[name]())
    assert _verdict(getattr(ex, name)(*args)) is False
    assert "contains complex numbers" in capsys.readouterr().out


def test_other_right_answers(capsys):
    assert ex.check_kalman_decision(1 + 0j, False)   # complex dtype, zero imaginary part (issue 35)
    assert ex.check_pendulum_f(_pendulum_f)
    assert ex.check_pendulum_f(lambda x, u: np.array(_pendulum_f(x, np.atleast_1d(u))))  # u as a number
    assert ex.check_kalman_decision(1, False) and ex.check_kalman_decision(np.int64(1), "no")
    assert ex.check_stability([True, False, False, True]) and ex.check_stability(np.array([1, 0, 0, 1]) == 1)
    assert ex.check_vehicle_observability(sp.Integer(1), np.False_)
    assert ex.check_separation_poles(sorted(_sep().real)) and ex.check_separation_poles(sp.Matrix(_sep().real))
    v, delta = _car()
    assert ex.check_car_flatness(-v, -delta)   # driving backwards along the same path
    assert ex.check_car_flatness([v], np.array([delta]))
    assert ex.check_ctrb_matrix(sp.Matrix(_ctrb().astype(int)))
    assert capsys.readouterr().out.count("Correct:") == 13


def _swap(a):
    a = np.array(a, dtype=float)
    return a[::-1].copy()


def _neg_entry(a, index):
    a = np.array(a, dtype=float)
    a[index] = -a[index]
    return a


msd_A, msd_B, msd_C = _msd()
K_ccf, K_gen, L_obs = _K(ex.PLACE_CCF), _K(ex.PLACE_GENERAL), _L()
v_car, delta_car = _car()

#: (checker, arguments, words the feedback must contain)
WRONG = [
    ("check_msd_state_space", (np.array(msd_A).T, msd_B, msd_C), "transposed"),
    ("check_msd_state_space", (msd_A, [[0, 1 / MSD["m"]]], msd_C), "must be a column"),
    ("check_msd_state_space", (msd_A, msd_B, [[0, 1]]), "velocity"),
    ("check_msd_state_space", ([[0, 1], [-MSD["k"], -MSD["d"]]], msd_B, msd_C), "divided by m"),
    ("check_msd_state_space", (_neg_entry(msd_A, (1, 0)), msd_B, msd_C), "wrong sign"),
    ("check_msd_state_space", ([[0, 1, 0], [1, 1, 1]], msd_B, msd_C), "wrong shape"),
    ("check_compartment_state_space", (_compartment()[0], _compartment()[1], [[1, 0]]), "y = c2"),
    ("check_compartment_state_space", ([[-0.8, 0.6], [0.6, -0.6]], *_compartment()[1:]), "volume"),
    ("check_pendulum_f", (lambda x, u: [x[1], -PEN["g"] / PEN["l"] * x[0] - PEN["d_theta"] / PEN["m"] * x[1]
                                        + u[0] / (PEN["m"] * PEN["l"] ** 2)],), "sin(theta)"),
    ("check_pendulum_f", (lambda x, u: [x[1], -PEN["g"] / PEN["l"] * np.sin(x[0])
                                        - PEN["d_theta"] / PEN["m"] * x[1] + u[0]],), "divided by m l^2"),
    ("check_pendulum_f", (lambda x, u: [x[0], 0.0],), "first entry"),
    ("check_pendulum_f", (lambda x, u: 1 / 0,), "ZeroDivisionError"),
    ("check_pendulum_f", ("f",), "must be a Python function"),
    ("check_ode_realization", (np.vstack([np.eye(3)[1:], ex.ODE["a"]]), *_ode()[1:]), "minus"),
    ("check_ode_realization", (np.vstack([np.eye(3)[1:], -np.array(ex.ODE["a"])[::-1]]), *_ode()[1:]),
     "reverse order"),
    ("check_ode_realization", (_ode()[0], [[0], [0], [1]], [[ex.ODE["b"], 0, 0]]), "belongs in B"),
    ("check_euler_discretization", (ex.EULER["Ts"] * np.array(ex.EULER["A"]), _euler()[1]), "Ad = I + Ts A"),
    ("check_euler_discretization", (_euler()[0], ex.EULER["B"]), "multiplied by Ts"),
    ("check_ctrb_matrix", (_ctrb()[:, ::-1],), "reverse order"),
    ("check_ctrb_matrix", (_ctrb().T,), "transposed"),
    ("check_ctrb_matrix", (np.hstack([ex.CTRB["A"], _ctrb()[:, 1:]]),), "wrong shape"),
    ("check_kalman_decision", (3, True), "rank is off"),
    ("check_kalman_decision", (1, "maybe"), "True or False"),
    ("check_ccf_transform", (np.linalg.inv(_ccf_T()),), "inverted"),
    ("check_ccf_transform", (_swap(_ccf_T()),), "wrong order"),
    ("check_car_flatness", (v_car, np.degrees(delta_car)), "degrees"),
    ("check_car_flatness", (v_car, -delta_car), "wrong sign"),
    ("check_car_flatness", (v_car, delta_car * 0 + np.arctan(np.tan(delta_car) / ex.CAR["L"])), "wheelbase"),
    ("check_car_flatness", (v_car ** 2, delta_car), "v is off"),
    ("check_trajectory_coefficients", (_alpha()[::-1],), "descending"),
    ("check_trajectory_coefficients", (_alpha()[:3],), "wrong shape"),
    ("check_stability", ([True, True, False, True],), "matrix A2"),
    ("check_stability", ([True, False, True, True],), "real part 0"),
    ("check_stability", ([True, False],), "4 entries"),
    ("check_gain_ccf", (-K_ccf,), "MATLAB sign"),
    ("check_gain_ccf", (K_ccf.T,), "transposed"),
    ("check_gain_ccf", (K_ccf + [[1, 0, 0]],), "eigenvalues"),
    ("check_gain_general", (-K_gen,), "MATLAB sign"),
    ("check_gain_general", (_K(ex.PLACE_GENERAL) @ np.linalg.inv(_ccf_T()),), "off"),
    ("check_pendulum_linearization", ([[0, 1], [-LIN["g"] / LIN["l"], -LIN["d_theta"] / LIN["m"]]],
                                      _lin()[1]), "hanging"),
    ("check_pendulum_linearization", (_lin()[0], [[0, 1]]), "column"),
    ("check_obsv_matrix", (_obsv().T,), "transposed"),
    ("check_obsv_matrix", (_obsv()[::-1],), "reverse order"),
    ("check_vehicle_observability", (2, True), "rank is off"),
    ("check_observer_gain", (-L_obs,), "A - L C"),
    ("check_observer_gain", (L_obs.T,), "must be a column"),
    ("check_observer_gain", (L_obs + [[1], [0]],), "eigenvalues"),
    ("check_separation_poles", (_sep()[:2],), "4 states"),
    ("check_separation_poles", (_sep() + 1,), "do not match"),
]


def _solution_numbers(name) -> set[str]:
    """The entries of the solution (as printed with up to 3 significant digits) that are not trivial."""
    if name in RIGHT:
        values = np.concatenate([np.ravel(np.asarray(a, dtype=float)) for a in RIGHT[name]()])
    elif name == "check_separation_poles":
        values = _sep().real
    else:
        return set()
    out = set()
    for v in values:
        if abs(v) > 1e-9 and abs(abs(v) - 1) > 1e-9:
            out |= {f"{v:.3g}", f"{v:.4g}", repr(round(float(v), 4))}
    return out


def _numbers_in(text: str) -> set[str]:
    """Numbers in the feedback, leaving out equation and section numbers, shapes, powers and indices."""
    text = re.sub(r"\(\d\.\d+\)|section \d(\.\d)+|\d+ x \d+|\(\d+, \d+\)", " ", text)
    return set(re.findall(r"(?<![\w^.])-?\d+(?:\.\d+)?(?:e-?\d+)?", text))


WRONG += [case for module in CHAPTER_CASES for case in getattr(module, "WRONG_ANSWERS", [])]   # a chapter's own


@pytest.mark.parametrize("name, args, words", WRONG, ids=[f"{w[0]}-{w[2]}" for w in WRONG])
def test_wrong_answer_is_named_and_solution_not_printed(name, args, words, capsys):
    assert _verdict(getattr(ex, name)(*args)) is False
    out = capsys.readouterr().out
    assert out.startswith("Not yet"), out
    assert words in out, out
    leaked = _numbers_in(out) & _solution_numbers(name)
    assert not leaked, f"feedback prints solution numbers {leaked}: {out}"


GARBAGE = ["abc", None, {"a": 1}, [[1, 2], [3]], float("nan"), sp.Matrix([[sp.Symbol("k"), 1]])]


@pytest.mark.parametrize("garbage", GARBAGE, ids=["str", "None", "dict", "ragged", "nan", "symbol"])
@pytest.mark.parametrize("name", [n for n in ex.__all__ if n.startswith("check_")])
def test_garbage_never_raises(name, garbage, capsys):
    func = getattr(ex, name)
    nargs = len(inspect.signature(func).parameters)   # the checks are wrapped (they record answers)
    assert _verdict(func(*([garbage] * nargs))) is False
    out = capsys.readouterr().out
    assert out.startswith("Not yet") and len(out.splitlines()) >= 2, out


def test_garbage_messages_say_what_to_type(capsys):
    ex.check_gain_ccf("K")
    ex.check_gain_ccf(sp.Matrix([[sp.Symbol("k1"), 1, 2]]))
    ex.check_gain_ccf(None)
    ex.check_gain_ccf(np.zeros((2, 2, 2)))
    out = capsys.readouterr().out
    assert "not a string" in out and "symbols" in out and "placeholder" in out and "dimensions" in out


def test_exercises_module_is_not_loaded_by_import_coursekit_and_sympy_stays_lazy():
    import subprocess
    import sys
    code = ("import sys, coursekit, coursekit.exercises; "
            "print('sympy' in sys.modules, 'matplotlib' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_leak_detector_sees_numbers_but_not_equation_references():
    assert {"-9", "-6", "0.5"} <= _numbers_in("K = [[-9, -6]], T = [[0.5, 0]]")
    assert _numbers_in("see (3.47) and section 2.2.3; entries (2, 1); A^2 B is 3 x 3") == set()
    assert "-9" in _solution_numbers("check_gain_general")


def test_every_checker_has_wrong_answer_cases():
    checkers = {n for n in ex.__all__ if n.startswith("check_")}
    assert len([n for m in chapter_modules("exercises")[:4] for n in m.__all__ if n.startswith("check_")]) == 18
    assert checkers == {case[0] for case in WRONG}


from hypothesis import given, strategies as st  # noqa: E402
from hypothesis.extra.numpy import arrays  # noqa: E402

from coursekit.exercises._feedback import Report, matrix_feedback  # noqa: E402

# entries of 0.51 to 50 either sign, drawn so, not filtered: hypothesis 6.80 (the oldest supported)
# draws arrays' entries near 0 so often that a filter failed its health check
_entries = st.tuples(st.sampled_from([-1.0, 1.0]), st.floats(0.51, 50.0)).map(lambda p: round(p[0] * p[1], 2))


@given(expected=st.integers(2, 4).flatmap(lambda n: arrays(float, (n, n), elements=_entries)),
       data=st.data())
def test_feedback_names_the_one_changed_entry(expected, data):
    n = expected.shape[0]
    i, j = data.draw(st.integers(0, n - 1)), data.draw(st.integers(0, n - 1))
    answer = expected.copy()
    answer[i, j] += data.draw(st.sampled_from([1.0, -2.5, 10.0]))
    report = Report("t")
    assert matrix_feedback(expected.copy(), expected, "M", report) and report.ok
    assert not matrix_feedback(answer, expected, "M", report)
    message = report.problems[-1]
    if "transposed" not in message:
        assert f"({i + 1}, {j + 1})" in message


@given(expected=arrays(float, (3, 1), elements=_entries))
def test_feedback_flags_a_whole_sign_flip_and_a_transposed_column(expected):
    report = Report("t")
    assert not matrix_feedback(-expected, expected, "B", report)
    assert "opposite sign in every entry" in report.problems[-1]
    assert not matrix_feedback(expected.T, expected, "B", report)
    assert "transposed" in report.problems[-1] and "column (3 x 1)" in report.problems[-1]


def _complex_right_real(a):
    """The right answer plus a small imaginary part: its real part is exactly right."""
    return np.asarray(a, dtype=float) + 1e-2j


def _sympy_complex(a):
    arr = np.atleast_2d(np.asarray(a, dtype=float))
    return sp.Matrix(arr) + sp.I * sp.ones(*arr.shape)


def _with_nan(a):
    arr = np.array(a, dtype=float)
    arr.flat[0] = np.nan
    return arr


#: how a bad answer is made from the right one, and what the feedback must say about it
BAD_FORMS = {
    "complex, right real part": (_complex_right_real, "complex"),
    "complex list": (lambda a: (np.asarray(a, dtype=float) + 0.5j).tolist(), "complex"),
    "sympy complex": (_sympy_complex, "complex"),
    "NaN entry": (_with_nan, "NaN"),
    "text": (lambda a: str(np.asarray(a).tolist()), "not a string"),
    "list of text": (lambda a: [str(v) for v in np.ravel(a)], "text"),
    "None": (lambda a: None, "None"),
    "stacked twice": (lambda a: np.stack([np.asarray(a, dtype=float)] * 2), "shape|dimensions|must list"),
}


@pytest.mark.parametrize("form", BAD_FORMS)
@pytest.mark.parametrize("name", RIGHT)
def test_bad_answer_gets_feedback_naming_the_problem(name, form, capsys):
    """Each argument in turn made bad, the others right: "Not yet" and why, never "Correct" or an error."""
    make, says = BAD_FORMS[form]
    right = RIGHT[name]()
    for i in range(len(right)):
        args = list(right)
        args[i] = make(right[i])
        assert _verdict(getattr(ex, name)(*args)) is False, (i, args[i])
        out = capsys.readouterr().out
        assert out.startswith("Not yet") and re.search(says, out), out


@pytest.mark.parametrize("call, says", [
    (lambda: ex.check_kalman_decision(1 + 1e-3j, False), "complex"),
    (lambda: ex.check_kalman_decision(1.5, False), "whole number"),
    (lambda: ex.check_kalman_decision(np.nan, False), "NaN"),
    (lambda: ex.check_vehicle_observability(1 + 1j, False), "complex"),
    (lambda: ex.check_vehicle_observability([1, 1], False), "whole number"),
    (lambda: ex.check_stability([True, 1j, False, True]), "True or False"),
    (lambda: ex.check_separation_poles([np.nan] * 4), "NaN"),
    (lambda: ex.check_separation_poles("-1, -2, -3, -4"), "not a string"),
    (lambda: ex.check_pendulum_f(lambda x, u: np.asarray(_pendulum_f(x, u)) + 1e-3j), "complex"),
    (lambda: ex.check_pendulum_f(lambda x, u: [np.nan, 0.0]), "NaN"),
    (lambda: ex.check_pendulum_f(lambda x, u: [x[1]]), "returned 1 numbers, expected 2"),
    (lambda: ex.check_pendulum_f(lambda x, u: None), "forget the return"),
    (lambda: ex.check_car_flatness(_car()[0] + 1e-3j, _car()[1]), "complex"),
])
def test_bad_answers_of_the_other_checks_get_feedback(call, says, capsys):
    assert _verdict(call()) is False
    out = capsys.readouterr().out
    assert out.startswith("Not yet") and says in out, out


# ---------------------------------------------------------------------------
# what a check returns and how the exercise data look


def test_check_result_is_truthy_exactly_when_correct_and_reads_well_in_a_plain_repl(capsys):
    right, wrong = ex.check_stability([True, False, False, True]), ex.check_stability(None)
    assert bool(right) is True and bool(wrong) is False
    assert repr(right) == "CheckResult(exercise='stability', correct=True)"
    assert repr(wrong) == "CheckResult(exercise='stability', correct=False)"
    capsys.readouterr()


def test_check_result_shows_nothing_in_ipython():
    """IPython formats it to an empty bundle, so a kernel sends no execute_result (no Out[n])."""
    from IPython.core.formatters import DisplayFormatter
    result = ex.check_stability([True, False, False, True])
    assert DisplayFormatter().format(result) == ({}, {})
    # a plain object on the same path does produce an Out line: the test can fail
    assert DisplayFormatter().format(True)[0] == {"text/plain": "True"}


def test_exercise_data_index_like_a_dict_and_stay_read_only():
    assert ex.MSD["m"] == 2.0 and dict(ex.MSD) == {"m": 2.0, "d": 0.4, "k": 8.0}
    assert np.array(ex.EULER["A"]).shape == (2, 2) and np.array(ex.EULER["B"]).shape == (2, 1)
    assert list(ex.STABILITY) == ["A1", "A2", "A3", "A4"]
    from coursekit import models
    assert models.compartment(**ex.COMPARTMENT).n == 2
    with pytest.raises(TypeError):
        ex.MSD["m"] = 3.0


def test_exercise_data_print_one_line_per_entry_with_matrices_as_aligned_rows():
    assert str(ex.MSD) == "m = 2\nd = 0.4\nk = 8"
    assert str(ex.ODE) == "a = [3, 5, 2]\nb = 4"
    assert str(ex.CTRB) == ("A = [[1,  2,  0],\n"
                            "     [0, -1,  1],\n"
                            "     [1,  0, -2]]\n"
                            "B = [[0],\n"
                            "     [1],\n"
                            "     [1]]")
    assert repr(ex.OBSV).splitlines()[-1] == "C = [[1, 0, 1]]"   # a row stays a row
    # what is printed reads back as the data
    for name in ("CTRB", "SEPARATION", "STABILITY"):
        data = getattr(ex, name)
        namespace = {}
        exec(str(data), namespace)
        for key in data:
            assert np.allclose(namespace[key], data[key]), (name, key)


def test_exercise_data_typeset_matrices_in_jupyter():
    markdown = ex.SEPARATION._repr_markdown_()
    assert r"`A` $= \begin{bmatrix} 0 & 1 \\ 3 & -2 \end{bmatrix}$" in markdown
    assert r"`C` $= \begin{bmatrix} 1 & 0 \end{bmatrix}$" in markdown
    assert "`x_eq` $= [{3.14159},\\ {0}]$" in ex.LINEARIZE._repr_markdown_()


def test_exercise_data_reject_what_is_not_a_mapping_of_names():
    from coursekit.exercises._data import ExerciseData
    with pytest.raises(TypeError, match="items must be a mapping"):
        ExerciseData([("m", 1.0)])
    with pytest.raises(TypeError, match="every name must be a string"):
        ExerciseData({1: 1.0})
