"""Every explorer's plotted responses start where its controls and its text say they start.

A student reads the initial condition off a slider ("initial angle from upright [deg]"), a
title ("response from x0 = [1, 0, 0]"), a dropdown ("initial": y(0) = 1 m) or the notebook's
text ("from rest at 0"); the first sample of each curve drawn (the data of the figure's own
lines, found by their axes and legend label) must equal it, in sign and unit, for the default
settings and each end of every control. The website and the slides draw their frames with
the same compute, draw and update, so a start right here is right there.
"""

import re

import numpy as np
import pytest

from coursekit.explorers.ch1 import EULER_EXAMPLES
from coursekit.tools.chapters import explorer_factories
from bad_input_cases import CHAPTER_CASES
from test_figure_layout import settings, undrawn

EXPLORERS = explorer_factories()


def _title_vector(fig, pattern: str) -> list[float]:
    """The numbers of ``x0 = [a, b, ...]`` in the title of the axes whose title matches `pattern`."""
    title = next(ax.get_title() for ax in fig.axes if re.search(pattern, ax.get_title()))
    found = re.search(r"x0 = \[([^\]]+)\]", title)
    assert found, f"the title {title!r} no longer states x0 = [...]"
    return [float(v) for v in found.group(1).split(",")]


def _pole_placement(p, fig):
    x0 = _title_vector(fig, "response from")
    return {("response from", f"x{i + 1}"): (0.0, v) for i, v in enumerate(x0)}


#: for each explorer, from its settings (and its figure's text): {(axes title pattern, curve label):
#: (first x, first y)} — time curves start at t = 0
STATED = {
    # the exact solution and the Euler samples start at the example's x0 (y(0) = 6 for (1.12))
    "ch1.euler_explorer": lambda p, fig: {
        ("first state", label): (0.0, EULER_EXAMPLES[p["example"]][1][0]) for label in ("exact", "Euler (1.43)")},
    # "step": from rest; "initial": from y(0) = 1 m, y'(0) = 0
    "ch1.msd_explorer": lambda p, fig: {
        ("response", "position y [m]"): (0.0, 1.0 if p["experiment"] == "initial" else 0.0),
        ("response", "velocity y' [m/s]"): (0.0, 0.0)},
    # "moved from rest at 0 to rest at the target"
    "ch2.planner_explorer": lambda p, fig: {
        ("planned and simulated", label): (0.0, 0.0) for label in ("planned y_d", "simulated y")},
    # "from (0, 0, 0°)": both paths start at the origin of the plane
    "ch2.robot_planner_explorer": lambda p, fig: {
        ("path in the plane", label): (0.0, 0.0) for label in ("planned path F_d", "driven (model 1.10)")},
    "ch3.pole_placement_explorer": _pole_placement,
    # the slider "initial angle from upright [deg]" against the curves of theta - pi [deg]
    "ch3.upright_pendulum_explorer": lambda p, fig: {
        ("angle from upright", label): (0.0, p["theta0_deg"])
        for label in ("linear u = K(x - x*) (3.92)", "feedback linearizing (3.154)")},
    # at rest until the disturbance at t = 1 s
    "ch3.integral_action_explorer": lambda p, fig: {
        ("output after", label): (0.0, 0.0) for label in ("state feedback u = K x (offset 3.109)",
                                                          "with integral action u = K x + k_I int x1 (3.117)")},
    # the vehicle starts at x(0) = [1 m, 0.5 m/s], the observer at x̂(0) = 0
    "ch4.observer_noise_explorer": lambda p, fig: {
        ("", "true position x1"): (0.0, 1.0), ("", "true velocity x2"): (0.0, 0.5),
        ("", "estimate x̂1"): (0.0, 0.0), ("", "estimate x̂2"): (0.0, 0.0)},
    # the data start at rest at 0, and so does the filter
    "ch4.kalman_tuning_explorer": lambda p, fig: {
        ("", label): (0.0, 0.0) for label in ("true position x1", "true velocity x2", "estimate x̂1", "estimate x̂2")},
}
STATED.update({name: stated for module in CHAPTER_CASES for name, stated in getattr(module, "STATED", {}).items()})


def _first_sample(fig, title_pattern: str, label: str) -> tuple[float, float]:
    """The first (x, y) of the line labelled `label` in an axes whose title matches `title_pattern`."""
    lines = [line for ax in fig.axes if re.search(title_pattern, ax.get_title())
             for line in ax.get_lines() if line.get_label() == label]
    assert len(lines) == 1, f"no single curve {label!r} under a title matching {title_pattern!r}"
    x, y = (np.asarray(v, dtype=float) for v in lines[0].get_data())
    return float(x[0]), float(y[0])


def test_every_explorer_states_its_initial_conditions_here():
    assert sorted(STATED) == sorted(EXPLORERS), "add the new explorer's stated initial conditions to STATED"


@pytest.mark.parametrize("name", EXPLORERS)
def test_each_curve_starts_at_the_initial_condition_its_control_or_text_states(name):
    explorer = undrawn(EXPLORERS[name]())     # the curves' data only
    found = []
    for setting in settings(explorer.controls, every_end=True):
        for control, value in setting.items():
            explorer.controls[control].value = value
        explorer.refresh()
        assert explorer.error is None, f"{setting}: {explorer.error}"
        for (where, label), expected in STATED[name](explorer.params, explorer.fig).items():
            first = _first_sample(explorer.fig, where, label)
            if not np.allclose(first, expected, atol=1e-9):
                found.append(f"{setting}: {label!r} starts at {first}, stated {expected}")
    assert not found, "\n".join(found)


def test_the_upright_pendulum_starts_on_its_slider_s_side_and_says_so():
    """The issue's case: slider at -115 deg, curve at +115 deg; the readout states the same angle."""
    explorer = EXPLORERS["ch3.upright_pendulum_explorer"]()
    for angle in (-115.0, 30.0):
        explorer.controls["theta0_deg"].value = angle
        explorer.refresh()
        for label in ("linear u = K(x - x*) (3.92)", "feedback linearizing (3.154)"):
            assert _first_sample(explorer.fig, "angle from upright", label) == pytest.approx((0.0, angle))
        assert explorer.text.startswith(f"start {angle:g} deg from upright")
