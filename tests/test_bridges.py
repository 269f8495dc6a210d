"""Bridges to python-control and SciPy: exact round trips, time bases, clear refusals.

The bridges copy matrices, they compute nothing, so every round trip is compared bit for
bit (`_same`): any difference at all would mean a value was recomputed or rounded.
"""

import subprocess
import sys

import numpy as np
import pytest
import scipy.signal as signal
from hypothesis import given, settings
from hypothesis import strategies as st

import coursekit as ck

control = pytest.importorskip("control")


def _same(a, b):
    """Bit-for-bit equal float64 arrays of the same shape (-0.0 and 0.0 differ here)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype == np.float64 and a.shape == b.shape and a.tobytes() == b.tobytes()


def _assert_same_system(got, expected_matrices, expected_dt):
    for label, expected in zip("ABCD", expected_matrices):
        assert _same(getattr(got, label), expected), label
    assert got.dt == expected_dt


# entries over many magnitudes and both signs, zeros included (a random change of units)
_entry = st.one_of(
    st.just(0.0), st.just(-0.0),
    st.builds(lambda mant, exp: mant * 10.0 ** exp,
              st.floats(-10, 10, allow_nan=False), st.integers(-4, 4)),
)


@st.composite
def systems(draw, discrete=None, inputs=None):
    """A random coursekit StateSpace: n 1..5 states, m 0..3 inputs, p 1..3 outputs."""
    n = draw(st.integers(1, 5))
    m = draw(st.integers(0, 3)) if inputs is None else (draw(st.integers(1, 3)) if inputs else 0)
    p = draw(st.integers(1, 3))
    mat = lambda r, c: np.array(draw(st.lists(_entry, min_size=r * c, max_size=r * c)),  # noqa: E731
                                dtype=float).reshape(r, c)
    is_discrete = draw(st.booleans()) if discrete is None else discrete
    dt = draw(st.floats(1e-4, 1e4)) if is_discrete else None
    return ck.StateSpace(mat(n, n), mat(n, m), mat(p, n), mat(p, m), dt=dt)


def _matrices(s):
    return (s.A, s.B, s.C, s.D)


def _control_can_hold(ck_sys):
    """python-control 0.10 turns an empty 1x0 B or D into 0x0 and then rejects the system."""
    return ck_sys.m > 0 or min(ck_sys.n, ck_sys.p) >= 2


@settings(max_examples=40)
@given(systems())
def test_control_round_trip_is_exact(ck_sys):
    if not _control_can_hold(ck_sys):
        with pytest.raises(ValueError, match=r"python-control \S+ cannot hold this system without inputs"):
            ck_sys.to_control()
        return
    there = ck_sys.to_control()
    # python-control's time base: 0 is continuous, a period stays itself
    assert there.dt == (0 if ck_sys.dt is None else ck_sys.dt)
    assert (there.nstates, there.ninputs, there.noutputs) == (ck_sys.n, ck_sys.m, ck_sys.p)
    _assert_same_system(there, _matrices(ck_sys), there.dt)
    _assert_same_system(ck.StateSpace.from_control(there), _matrices(ck_sys), ck_sys.dt)


@settings(max_examples=40)
@given(systems())
def test_scipy_round_trip_is_exact(ck_sys):
    there = ck_sys.to_scipy()
    assert isinstance(there, signal.dlti if ck_sys.is_discrete else signal.lti)
    assert there.dt == ck_sys.dt  # SciPy: None is continuous, a period stays itself
    _assert_same_system(there, _matrices(ck_sys), ck_sys.dt)
    _assert_same_system(ck.StateSpace.from_scipy(there), _matrices(ck_sys), ck_sys.dt)


@settings(max_examples=20)
@given(systems(discrete=True, inputs=True), systems(discrete=False, inputs=False))
def test_round_trips_from_the_other_side_are_exact(discrete, no_input):
    for ck_sys in (discrete, no_input):
        sp = signal.StateSpace(*_matrices(ck_sys), **({} if ck_sys.dt is None else {"dt": ck_sys.dt}))
        back = ck.StateSpace.from_scipy(sp).to_scipy()
        _assert_same_system(back, _matrices(sp), sp.dt)
        if not _control_can_hold(ck_sys):
            continue
        ctrl = control.StateSpace(*_matrices(ck_sys), 0 if ck_sys.dt is None else ck_sys.dt)
        back = ck.StateSpace.from_control(ctrl).to_control()
        _assert_same_system(back, _matrices(ctrl), ctrl.dt)


def test_systems_without_inputs_convert_where_python_control_can_hold_them():
    ck_sys = ck.StateSpace([[0.0, 1.0], [-1.0, 0.0]], C=[[1.0, 0.0], [0.0, 2.0]])
    _assert_same_system(ck.StateSpace.from_control(ck_sys.to_control()), _matrices(ck_sys), None)
    with pytest.raises(ValueError, match=r"1 output\(s\).*np\.zeros\(\(n, 1\)\)"):
        ck.StateSpace([[0.0, 1.0], [-1.0, 0.0]], C=[[1.0, 0.0]]).to_control()


def test_conversions_copy_the_matrices():
    A = np.array([[0.0, 1.0], [-2.0, -3.0]])
    ck_sys = ck.StateSpace(A, [[0.0], [1.0]])
    for there in (ck_sys.to_control(), ck_sys.to_scipy()):
        there.A[0, 0] = 5.0  # scipy.signal keeps the very arrays it is given unless copied
        assert ck_sys.A[0, 0] == 0.0
    sp = signal.StateSpace(A, [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    ck.StateSpace.from_scipy(sp).A[0, 1] = 7.0
    assert sp.A[0, 1] == 1.0


@pytest.mark.parametrize("dt, expected", [(0, None), (None, None), (True, 1.0), (0.25, 0.25)])
def test_control_time_bases(dt, expected):
    ctrl = control.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[0.0]], dt)
    assert ck.StateSpace.from_control(ctrl).dt == expected


@pytest.mark.parametrize("dt, expected", [(None, None), (True, 1.0), (0.25, 0.25)])
def test_scipy_time_bases(dt, expected):
    sp = signal.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[0.0]], **({} if dt is None else {"dt": dt}))
    assert ck.StateSpace.from_scipy(sp).dt == expected


def test_names_travel_with_python_control_but_generic_ones_do_not():
    tank = ck.StateSpace([[-1.0]], [[1.0]], name="tank")
    assert tank.to_control().name == "tank"
    assert ck.StateSpace.from_control(tank.to_control()).name == "tank"
    generic = control.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    assert generic.name.startswith("sys[")
    assert ck.StateSpace.from_control(generic).name == ""


@pytest.mark.parametrize("make, bridge, message", [
    (lambda: control.tf([1.0], [1.0, 2.0]), "from_control", r"TransferFunction\. .*control\.ss\(G\)"),
    (lambda: control.nlsys(lambda t, x, u, p: -x, states=1, inputs=1, outputs=1), "from_control",
     r"NonlinearIOSystem\. .*linearize"),
    (lambda: signal.TransferFunction([1.0], [1.0, 2.0]), "from_control", r"StateSpace\.from_scipy"),
    (lambda: signal.TransferFunction([1.0], [1.0, 2.0]), "from_scipy", r"sys\.to_ss\(\)"),
    (lambda: signal.ZerosPolesGain([], [-1.0], 1.0, dt=0.1), "from_scipy", r"sys\.to_ss\(\)"),
    (lambda: control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), "from_scipy", r"StateSpace\.from_control"),
    (lambda: ck.StateSpace([[-1.0]]), "from_scipy", r"already is a coursekit object"),
    (lambda: np.eye(2), "from_control", r"numpy\.ndarray\. Build one with control\.ss"),
])
def test_what_cannot_be_converted_is_refused_with_the_way_out(make, bridge, message):
    with pytest.raises(TypeError, match=r"sys must be a .* state-space system: received .*" + message):
        getattr(ck.StateSpace, bridge)(make())


# python-control (0.10.2) itself sets array shapes when it builds a static gain; numpy 2.5 warns
@pytest.mark.filterwarnings("ignore:Setting the shape on a NumPy array:DeprecationWarning")
def test_a_static_gain_is_refused():
    gain = control.StateSpace(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[2.0]])
    with pytest.raises(ValueError, match=r"sys has no states \(a static gain D\)"):
        ck.StateSpace.from_control(gain)


def test_missing_python_control_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "control", None)  # makes `import control` raise ImportError
    with pytest.raises(ImportError, match=r"pip install control"):
        ck.StateSpace([[-1.0]]).to_control()
    with pytest.raises(ImportError, match=r"pip install control"):
        ck.StateSpace.from_control(object())
    ck.StateSpace([[-1.0]]).to_scipy()  # the SciPy bridge does not need python-control


def test_import_coursekit_does_not_import_python_control():
    code = "import sys, coursekit; print('control' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_bridge_makes_the_sign_of_K_concrete():
    # chapter 3: coursekit's u = K x (3.17) against python-control's u = -K x
    plant = ck.StateSpace([[0.0, 1.0], [-2.0, -0.5]], [[0.0], [1.0]])
    poles = [-2.0, -3.0]
    K_ck = ck.place(plant.A, plant.B, poles)
    ctrl = plant.to_control()
    K_ctrl = control.place(ctrl.A, ctrl.B, poles)
    # both solve the same 2x2 problem; 1e-9 leaves room for the two algorithms' rounding
    np.testing.assert_allclose(K_ck, -K_ctrl, rtol=1e-9)


# --- every function that takes a system takes the neighbours' systems (issue 25) ---------

A_2 = np.array([[0.0, 1.0], [-2.0, -3.0]])
B_2, C_2, L_2, K_2 = np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]), np.array([[2.0], [1.0]]), np.array([[-1.0, -2.0]])
T_11 = np.linspace(0.0, 1.0, 11)


def _neighbours(dt=None):
    """The same plant as coursekit, python-control and scipy.signal objects."""
    A = A_2 if dt is None else np.eye(2) + 0.1 * A_2
    return (ck.StateSpace(A, B_2, C_2, dt=dt), control.ss(A, B_2, C_2, 0, 0 if dt is None else dt),
            signal.StateSpace(A, B_2, C_2, 0) if dt is None else signal.StateSpace(A, B_2, C_2, 0, dt=dt))


_SYSTEM_CALLS = {
    "simulate": lambda s: ck.simulate(s, T_11, u=np.ones((11, 1))).y,
    "simulate_batch": lambda s: ck.simulate_batch(s, T_11, np.eye(2)),
    "euler_discretize": lambda s: ck.euler_discretize(s, 0.1).A,
    "cascade": lambda s: ck.cascade(s, s).A,
    "feedback": lambda s: ck.feedback(s, s).A,
    "similarity_transform": lambda s: ck.similarity_transform(s, [[1.0, 1.0], [0.0, 1.0]]).A,
    "is_stable": lambda s: ck.is_stable(s),
    "observer_system": lambda s: ck.observer_system(s, L_2).A,
    "plant_with_observer": lambda s: ck.plant_with_observer(s, L_2).A,
    "output_feedback": lambda s: ck.output_feedback(s, K_2, L_2).A,
    "separation_eigenvalues": lambda s: ck.separation_eigenvalues(s, K_2, L_2),
    "kalman_bucy": lambda s: ck.kalman_bucy(s, T_11, None, np.zeros((11, 1)), np.eye(2), [[1.0]],
                                            np.eye(2), [1.0, 0.0]).x,
    "simulate_with_noise": lambda s: ck.simulate_with_noise(s, T_11, Q=np.eye(2), R=[[1.0]], seed=1).y,
    "with_integrators": lambda s: ck.with_integrators(s, C_2).f(np.ones(3), np.ones(1)),
    "linearize": lambda s: np.hstack(ck.linearize(s, [0.0, 0.0], [0.0])),
    "equilibrium_input": lambda s: ck.equilibrium_input(s, [0.0, 0.0]),
}


@pytest.mark.parametrize("call", _SYSTEM_CALLS.values(), ids=_SYSTEM_CALLS.keys())
def test_every_function_taking_a_system_takes_python_control_and_scipy_ones(call):
    ours, theirs_control, theirs_scipy = _neighbours()
    expected = np.asarray(call(ours))
    for other in (theirs_control, theirs_scipy, signal.lti(A_2, B_2, C_2, 0)):
        np.testing.assert_array_equal(np.asarray(call(other)), expected)


def test_discrete_systems_of_the_neighbours_keep_their_period():
    ours, theirs_control, theirs_scipy = _neighbours(dt=0.1)
    y = np.zeros((11, 1))
    args = dict(Q=np.eye(2), R=[[1.0]], P0=np.eye(2), x0=[0.0, 0.0])
    expected = ck.discrete_kalman_filter(ours, y, None, **args).x
    for other in (theirs_control, theirs_scipy):
        np.testing.assert_array_equal(ck.discrete_kalman_filter(other, y, None, **args).x, expected)
        assert ck.simulate(other, np.arange(11) * 0.1).system.dt == 0.1


@pytest.mark.parametrize("make, names", [
    (lambda: control.tf([1], [1, 2]), r"control\.xferfcn\.TransferFunction(?s:.*)control\.ss\(G\)(?s:.*)StateSpace\.from_control"),
    (lambda: signal.lti([1], [1, 2]), r"scipy\.signal\._ltisys\.TransferFunctionContinuous(?s:.*)to_ss(?s:.*)StateSpace\.from_scipy"),
    (lambda: control.ss(A_2, B_2, C_2, 0, True), r"dt=True(?s:.*)StateSpace\.from_control"),
    (lambda: signal.StateSpace(A_2, B_2, C_2, 0, dt=True), r"dt=True(?s:.*)StateSpace\.from_scipy"),
])
def test_what_would_hide_a_choice_is_refused_naming_the_bridge(make, names):
    with pytest.raises(ValueError, match=names):
        ck.simulate(make(), T_11)


@pytest.mark.parametrize("call", [lambda s: ck.place(s, B_2, [-1, -2]), lambda s: ck.ctrb(s, B_2),
                                  lambda s: ck.obsv(s, C_2), lambda s: ck.kalman_gain(s, C_2, np.eye(2), [[1.0]])])
def test_a_system_given_for_a_matrix_names_the_matrix_and_the_bridge(call):
    with pytest.raises(ValueError, match=r"A must be a matrix: received a python-control system "
                                         r"\(control\.statesp\.StateSpace\); pass its matrix, e\.g\. sys\.A, "
                                         r"or convert the system with StateSpace\.from_control"):
        call(_neighbours()[1])


def test_no_refusal_names_the_refused_type_as_the_wanted_one():
    with pytest.raises(ValueError) as info:
        ck.kalman_bucy(ck.models.pendulum(), T_11, None, np.zeros((11, 1)), np.eye(2), [[1.0]], np.eye(2), [0, 0])
    assert "must be a continuous-time StateSpace: received a continuous-time NonlinearSystem" in str(info.value)
    with pytest.raises(ValueError, match=r"received a discrete-time StateSpace \(dt=0\.1\)"):
        ck.observer_system(_neighbours(dt=0.1)[1], L_2)
