"""plotting: figures build without error and carry titles, axis labels, units and legends."""

import numpy as np
import pytest

import coursekit as ck
from coursekit import models


@pytest.fixture
def msd_result():
    t = np.linspace(0, 10, 201)
    return ck.simulate(models.mass_spring_damper(), t, u=np.ones((t.size, 1)))


def _labels(fig):
    return [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes]


def test_plot_response_stacks_states_and_inputs(msd_result):
    fig = ck.plot_response(msd_result, which="xu", state_names=["y", "y'"], state_units=["m", "m/s"],
                           input_units="N")
    assert len(fig.axes) == 2
    top, bottom = fig.axes
    assert [line.get_label() for line in top.get_lines()] == ["y [m]", "y' [m/s]"]
    assert bottom.get_ylabel() == "input u [N]"
    assert bottom.get_xlabel() == "time t [s]"
    assert "mass-spring-damper" in fig._suptitle.get_text()
    np.testing.assert_allclose(top.get_lines()[0].get_ydata(), msd_result.x[:, 0])


def test_result_plot_calls_plot_response(msd_result):
    fig = msd_result.plot(which="y", output_units="m", title="step")
    assert len(fig.axes) == 1
    assert fig.axes[0].get_ylabel() == "output y [m]"
    assert fig._suptitle.get_text() == "step"


def test_plot_response_skips_missing_input_and_marks_discrete_samples():
    res = ck.simulate(models.fibonacci(), np.arange(8.0), x0=[0, 1])
    fig = ck.plot_response(res, which="xu", time_unit="step")
    assert len(fig.axes) == 1
    assert fig.axes[0].get_xlabel() == "time t [step]"
    assert fig.axes[0].get_lines()[0].get_marker() == "o"


def test_plot_state_plane_numbers_points_like_figure_1_18():
    res = ck.simulate(models.state_example(), np.arange(4.0), x0=[1.0, 0.0])
    fig = ck.plot_state_plane(res, equal_axes=True)
    ax = fig.axes[0]
    texts = sorted(t.get_text() for t in ax.texts if t.get_text())
    arrows = [t for t in ax.texts if not t.get_text()]
    assert len(arrows) == 3  # 0 -> 1 -> 2 -> 3
    # the points repeat: x(0) = x(2) = [1, 0], x(1) = x(3) = [0, 1]
    assert texts == ["t = 0, 2", "t = 1, 3"]
    assert ax.get_xlabel() == "x1 [-]" and ax.get_ylabel() == "x2 [-]"
    assert ax.get_title() and ax.get_legend() is not None


def test_plot_state_plane_long_trajectory_and_given_axes(msd_result):
    from matplotlib.figure import Figure
    fig = Figure()
    ax = fig.subplots()
    out = ck.plot_state_plane([msd_result, msd_result.x * 0.5], ax=ax, state_names=["y", "y'"],
                              state_units=["m", "m/s"], labels=["full", "half"])
    assert out is fig
    assert ax.get_xlabel() == "y [m]"
    assert [t.get_text() for t in ax.texts].count("t = 0") == 2


def test_plot_euler_comparison_labels_and_errors():
    sys = ck.StateSpace([[-3.0]])
    t = np.linspace(0, 3, 301)
    exact = ck.simulate(sys, t, x0=[6.0])
    approx = [ck.simulate(ck.euler_discretize(sys, Ts), np.arange(int(3 / Ts) + 1) * Ts, x0=[6.0])
              for Ts in (0.1, 0.8)]
    fig = ck.plot_euler_comparison(exact, approx, unit="m")
    ax, ax_err = fig.axes
    assert [line.get_label() for line in ax.get_lines()] == ["exact", "Euler, Ts = 0.1", "Euler, Ts = 0.8"]
    assert ax_err.get_yscale() == "log"
    assert ax.get_ylabel() == "x1 [m]" and ax_err.get_xlabel() == "time t [s]"
    assert fig._suptitle.get_text()
    # the plotted error of Ts = 0.1 at t = 1 is |(1 - 0.3)^10 - e^{-3}| * 6
    err_line = ax_err.get_lines()[0]
    k = np.argmin(np.abs(err_line.get_xdata() - 1.0))
    assert np.isclose(err_line.get_ydata()[k], 6 * abs(0.7**10 - np.exp(-3)), rtol=1e-6)


@pytest.mark.parametrize("call, match", [
    (lambda r: ck.plot_response(r, which="xz"), "which must be a string"),
    (lambda r: ck.plot_response(r, which="xx"), "which must be a string"),
    (lambda r: ck.plot_response(r.x), "result must be a SimulationResult"),
    (lambda r: ck.plot_response(r, state_names=["a"]), "state_names has the wrong length"),
    (lambda r: ck.plot_response(r, state_units=["m"] * 3), "state_units has the wrong length"),
    (lambda r: ck.plot_state_plane(r.x[:, :1]), r"trajectories\[0\] must be"),
    (lambda r: ck.plot_state_plane(r, states=(0, 1, 2)), "states must name two"),
    (lambda r: ck.plot_euler_comparison(r.x, r), "exact must be a SimulationResult"),
])
def test_bad_input_raises_value_error(msd_result, call, match):
    with pytest.raises(ValueError, match=match):
        call(msd_result)


def test_plotting_does_not_import_matplotlib_at_package_import():
    import subprocess
    import sys
    code = "import sys, coursekit; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("ax", ["ax", 3, np.zeros(2)])
def test_plot_state_plane_refuses_what_is_not_an_axes(ax):
    # issue 25: AttributeError: 'str' object has no attribute 'figure'
    with pytest.raises(ValueError, match=r"^ax must be a matplotlib Axes: received"):
        ck.plot_state_plane([np.zeros((3, 2))], ax=ax)
