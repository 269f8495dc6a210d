"""Every figure coursekit draws, in four styles: no text outside the figure, no text on another
axes' text (checked by `layout_check.text_problems`, drawn with Agg).

The styles: matplotlib's defaults, lecture mode, a serif font and font size 18. The figures:
each plotting helper, the `.plot()` of the result and plan objects, and every explorer at its
default slider values, at each control's extremes and with all controls at their minima or
maxima at once.
"""

import contextlib

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import coursekit as ck  # noqa: E402
from coursekit.tools.chapters import explorer_factories  # noqa: E402
from coursekit.explorers import ch1  # noqa: E402
from layout_check import legend_problems, text_problems  # noqa: E402

#: a legend inside its axes may hide at most this fraction of the points of a curve
COVERED = 0.2

STYLES = {"default": {}, "lecture mode": None, "serif": {"font.family": "serif"},
          "font size 18": {"font.size": 18}}


@contextlib.contextmanager
def style(name):
    """Apply one of STYLES for the body; restore every setting afterwards."""
    with matplotlib.rc_context(STYLES[name] or {}):
        if STYLES[name] is None:
            ck.lecture_mode()
        try:
            yield
        finally:
            ck.lecture_mode(False)


# --- the plotting helpers and the .plot() methods ------------------------------------------

def _msd_step():
    sys = ck.models.mass_spring_damper(m=1.0, d=0.5, k=2.0)
    t = np.linspace(0, 20, 401)
    return ck.simulate(sys, t, u=np.ones((t.size, 1)))


def response_states_and_input():
    return _msd_step().plot(state_names=["position y", "velocity y'"], state_units=["m", "m/s"],
                            title="Mass-spring-damper (1.3): step in the force\n"
                                  "m = 1 kg, d = 0.5 N s/m, k = 2 N/m")


def response_default_labels():
    return ck.plot_response(_msd_step(), which="xyu")


def response_discrete():
    t = np.arange(0, 31)
    saving = ck.simulate(ck.models.bank_account(rate=0.03), t, u=np.full((t.size, 1), 1000.0),
                         x0=[10000.0])
    return saving.plot(which="yu", output_names=["balance y"], output_units="DKK", input_units="DKK",
                       time_unit="year",
                       title="Bank account (1.2): 3 % interest and a yearly deposit of 1000 DKK")


def state_plane_numbered():
    sys = ck.StateSpace([[0.5, -0.5], [0.5, 0.5]], dt=1)
    runs = [ck.simulate(sys, np.arange(4), x0=x0) for x0 in ([1, 0], [1, -1])]
    return ck.plot_state_plane(runs, equal_axes=True, title="Example (1.15) at t = 0, 1, 2, 3")


def state_plane_long():
    t = np.linspace(0, 20, 400)
    run = ck.simulate(ck.StateSpace([[0, 1], [-2, -0.5]]), t, x0=[1, 0])
    return ck.plot_state_plane(run, state_names=["position y", "velocity y'"], state_units=["m", "m/s"])


def euler_comparison():
    sys = ck.StateSpace([[-3.0]])
    exact = ck.simulate(sys, np.linspace(0, 3, 301), x0=[6.0])
    runs = [ck.simulate(ck.euler_discretize(sys, Ts), np.arange(0, 3 + 1e-9, Ts), x0=[6.0])
            for Ts in (0.05, 0.5, 0.8)]
    return ck.plot_euler_comparison(
        exact, runs, unit="-",
        title="y' = -3y (1.12): Euler with Ts = 0.05, 0.5 (sign flips) and 0.8 s (unstable)")


def poles_continuous():
    fig, _ = ck.plot_poles({"open loop": [1.0, -2.0 + 3j, -2.0 - 3j], "closed loop": [-1.0, -2.0, -3.0]})
    return fig


def poles_discrete():
    fig, _ = ck.plot_poles([0.5 + 0.5j, 0.5 - 0.5j, -0.9], dt=0.1)
    return fig


def open_loop_plan():
    A, B = [[0.0, 1.0], [-2.0, -0.5]], [[0.0], [1.0]]
    return ck.open_loop_control(A, B, [0.0, 0.0], [1.0, 0.0], 3.0).plot()


def flat_plan():
    return ck.plan_robot([0.0, 0.0, 0.0], [4.0, 2.0, np.pi / 2], 6.0).plot()


FIGURES = {f.__name__: f for f in (response_states_and_input, response_default_labels,
                                   response_discrete, state_plane_numbered, state_plane_long,
                                   euler_comparison, poles_continuous, poles_discrete,
                                   open_loop_plan, flat_plan)}


def _report(problems, where):
    return f"{where}:\n  " + "\n  ".join(problems)


@pytest.mark.parametrize("style_name", STYLES)
@pytest.mark.parametrize("name", FIGURES)
def test_plotting_helper_figure_has_no_text_problems(name, style_name):
    with style(style_name):
        fig = FIGURES[name]()
        problems = text_problems(fig) + legend_problems(fig, covered=COVERED)
    assert not problems, _report(problems, f"{name}, {style_name}")


# --- the explorers --------------------------------------------------------------------------

#: every explorer of the course (a new chapter's too)
EXPLORERS = {f.__name__: f for f in explorer_factories().values()}


def undrawn(explorer):
    """`explorer`, its refreshes computing and updating the artists without drawing a frame: for
    the sweeps that read texts and data, or draw the figure themselves. Returns it."""
    explorer.frames.frame = lambda: explorer.png
    return explorer


def settings(controls, *, every_end: bool):
    """Control settings to check: the defaults, and all sliders at their minima, then at their
    maxima, at once; with `every_end` also each control at each end (each option of a dropdown)
    with the others at their defaults."""
    defaults = {name: w.value for name, w in controls.items()}
    ends = {name: ([w.min, w.max] if hasattr(w, "min") else list(w.options)) for name, w in controls.items()}
    sliders = [name for name, w in controls.items() if hasattr(w, "min")]
    out = [defaults] + [{**defaults, **{name: ends[name][k] for name in sliders}} for k in (0, 1)]
    if every_end:
        out += [{**defaults, name: value} for name, values in ends.items() for value in values
                if value != defaults[name]]
    return out


#: the style with the largest text in the explorers' fixed-size figures (titles 21.6 pt, labels
#: and tick labels 18 pt; lecture mode has 20, 18 and 15 pt) goes through every end of every
#: control; the others through the defaults and both corners
EVERY_END = "font size 18"


@pytest.mark.parametrize("style_name", STYLES)
@pytest.mark.parametrize("name", EXPLORERS)
def test_explorer_figure_has_no_text_problems_over_its_slider_range(name, style_name):
    found = []
    with style(style_name):
        explorer = undrawn(EXPLORERS[name]())     # text_problems draws the figure itself
        for setting in settings(explorer.controls, every_end=style_name == EVERY_END):
            for control, value in setting.items():
                explorer.controls[control].value = value
            explorer.refresh()
            problems = text_problems(explorer.fig) + legend_problems(explorer.fig, covered=COVERED)
            if problems:
                found.append(_report(problems, f"{name} at {setting}, {style_name}"))
    assert not found, "\n".join(found)


def test_settings_cover_defaults_each_end_and_both_corners():
    explorer = ch1.euler_explorer()
    assert settings(explorer.controls, every_end=False) == [
        {"Ts": 0.1, "example": "first order (1.12)"}, {"Ts": 0.01, "example": "first order (1.12)"},
        {"Ts": 1.0, "example": "first order (1.12)"}]
    got = settings(explorer.controls, every_end=True)
    assert got[0] == {"Ts": 0.1, "example": "first order (1.12)"}
    assert {"Ts": 0.01, "example": "first order (1.12)"} in got
    assert {"Ts": 1.0, "example": "first order (1.12)"} in got
    assert {"Ts": 0.1, "example": "mass-spring-damper (1.57)"} in got
    assert len(got) == 1 + 2 + 3
