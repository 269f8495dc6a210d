"""A screen report (the browser's room for the figure and its pixel ratio) changes only the
resolution of an explorer's figure: the view limits, and so what the figure shows, stay those of
the settings shown. Window resizes send such reports; the figure after a resize and back must be
the figure before it."""

import io

import numpy as np
import pytest

from coursekit.explorers import ch1, ch2, ch3, ch4

FACTORIES = [ch1.euler_explorer, ch1.msd_explorer, ch2.planner_explorer, ch3.pole_placement_explorer,
             ch3.upright_pendulum_explorer, ch3.integral_action_explorer, ch4.observer_noise_explorer,
             ch4.kalman_tuning_explorer]

WIDE = {"width": 1500, "height": 900, "ratio": 1}      # room for the natural size: the dpi stays
NARROW = {"width": 650, "height": 900, "ratio": 1}     # a narrower window: the figure shrinks


def _pixels(png: bytes) -> np.ndarray:
    from matplotlib.image import imread
    return imread(io.BytesIO(png), format="png")


def _limits(explorer):
    return [tuple(round(float(v), 6) for v in (*ax.get_xlim(), *ax.get_ylim())) for ax in explorer.fig.axes]


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_screen_reports_without_a_new_setting_leave_the_view_limits(factory):
    explorer = factory()
    explorer._on_screen({"new": WIDE})
    before = _limits(explorer)
    for screen in (NARROW, WIDE, NARROW, WIDE):
        explorer._on_screen({"new": screen})
    assert _limits(explorer) == before, (
        f"{factory.__name__}: after a resize and back the view limits went from {before} to "
        f"{_limits(explorer)} (the settings did not change)")


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_repeated_screen_report_sends_the_same_figure(factory):
    explorer = factory()
    explorer._on_screen({"new": WIDE})
    first = explorer.png
    explorer._on_screen({"new": dict(WIDE, height=WIDE["height"] - 50)})   # same dpi, new report
    assert np.array_equal(_pixels(explorer.png), _pixels(first)), (
        f"{factory.__name__}: a second screen report at the same resolution changed the figure "
        f"of unchanged settings (view limits now {_limits(explorer)})")


def test_the_robot_planner_keeps_the_start_of_the_path_in_view_after_screen_reports():
    explorer = ch2.robot_planner_explorer()
    ax = explorer.fig.axes[0]
    for screen in (WIDE, dict(WIDE, height=WIDE["height"] - 20), NARROW, WIDE):
        explorer._on_screen({"new": screen})
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 <= 0.0 <= x1 and y0 <= 0.0 <= y1, (
            f"after the screen report {screen} the path's start (0, 0) is outside the view "
            f"x {x0:.2f}..{x1:.2f}, y {y0:.2f}..{y1:.2f}")


@pytest.mark.parametrize("target", [(4.0, 2.0, 90.0), (-6.0, 6.0, 90.0), (6.0, 0.5, 90.0), (0.0, -6.0, -90.0),
                                    (-6.0, -6.0, 180.0), (6.0, 6.0, 0.0)])
def test_the_robot_planners_view_holds_the_start_and_the_whole_target_arrow(target):
    explorer = ch2.robot_planner_explorer()
    controls = explorer.controls
    controls["x_T"].value, controls["y_T"].value, controls["heading_deg"].value = target
    explorer.refresh()
    ax = explorer.fig.axes[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    tx, ty, heading = target
    length = (x1 - x0) / 12.0           # the quiver's arrow: a twelfth of the view's width
    tip = (tx + length * np.cos(np.deg2rad(heading)), ty + length * np.sin(np.deg2rad(heading)))
    for name, (x, y) in {"start": (0.0, 0.0), "target": (tx, ty), "arrow tip": tip}.items():
        assert x0 <= x <= x1 and y0 <= y <= y1, (
            f"target {target}: the {name} ({x:.2f}, {y:.2f}) is outside the view "
            f"x {x0:.2f}..{x1:.2f}, y {y0:.2f}..{y1:.2f}")
