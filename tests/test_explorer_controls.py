"""What every explorer's controls and texts say: sliders that start on a grid of round values,
and units that read as units.

A browser's slider moves in steps from its minimum: a start off that grid is moved to the
nearest step (the figure then shows other settings than the text says), and a grid off round
values shows numbers such as -0.00103 where a reader expects 0 (the Kalman explorer's log10 Q
started at log10 0.5 on the grid -3.901 + 0.1 k). A dimensionless quantity has no unit: the
unit "-" reads as a minus sign, to a reader and to a screen reader ("x1 [-]", "error 0.05 -").
"""

import re

import numpy as np
import pytest

from coursekit.tools.chapters import explorer_factories
from test_figure_layout import settings, undrawn

EXPLORERS = explorer_factories()

#: a unit "-" (or a dash standing for one): in brackets or parentheses, or after a number
DASH_UNIT = re.compile(r"[\[(]\s*[-\u2212\u2013\u2014]\s*[\])]|\d\s+[-\u2212\u2013\u2014](?=$|[\s,;.:)\]])", re.M)


def _steps(number: float, step: float) -> float:
    """How far `number` is from the nearest multiple of `step`, in steps."""
    k = number / step
    return abs(k - round(k))


@pytest.mark.parametrize("name", sorted(EXPLORERS))
def test_every_slider_starts_on_its_grid_and_the_grid_holds_round_values(name):
    """The start is min + k step, and min, start and max are whole multiples of the step, so that
    every value a key step or a drag reaches is a round one (0, not -0.00103)."""
    off = []
    for control, w in EXPLORERS[name]().controls.items():
        if not hasattr(w, "step"):
            continue
        for what, number in (("start", w.value - w.min), ("min", w.min), ("max", w.max)):
            if _steps(number, w.step) > 1e-6:
                off.append(f"{control}: {what} {number:.6g} is not a whole number of steps {w.step:g} "
                           f"(min {w.min:.6g}, start {w.value:.6g}, max {w.max:.6g})")
    assert not off, "\n".join(off)


def _texts(explorer) -> list[str]:
    """Every text of the explorer's figure a reader meets: titles, axis labels, legend entries."""
    found = []
    for ax in explorer.fig.axes:
        found += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        found += [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]
    found += [t.get_text() for legend in explorer.fig.legends for t in legend.get_texts()]
    return found


@pytest.mark.parametrize("name", sorted(EXPLORERS))
def test_no_control_axis_or_readout_gives_a_dimensionless_quantity_the_unit_dash(name):
    explorer = undrawn(EXPLORERS[name]())     # texts only
    shown = [w.description for w in explorer.controls.values()]
    for setting in settings(explorer.controls, every_end=True):
        for control, value in setting.items():
            explorer.controls[control].value = value
        explorer.refresh()
        shown += [explorer.text, explorer.alt, *_texts(explorer)]
    dashes = sorted({text for text in shown if DASH_UNIT.search(text)})
    assert not dashes, "a unit '-' in:\n" + "\n".join(dashes)


@pytest.mark.parametrize("text, dash", [
    ("x1 [-]", True), ("|error| [ - ]", True), ("largest error 0.05 -\nmax", True), ("error 2 \u2212.", True),
    ("x1", False), ("observer poles -17 (double)", False), ("eig(A - L C) = -6 \u00b1 5.9j", False),
    ("closed-loop poles [pole, pole - 1]", False), ("start -30 deg", False), ("u = K(x - x*)", False),
])
def test_the_dash_unit_pattern(text, dash):
    assert bool(DASH_UNIT.search(text)) is dash


def test_the_grid_check_finds_a_grid_off_round_values():
    start = float(np.log10(0.5))
    assert _steps(start - (start - 36 * 0.1), 0.1) < 1e-9      # the start on the grid of its minimum,
    assert _steps(start - 36 * 0.1, 0.1) > 0.01                 # which holds no round values
