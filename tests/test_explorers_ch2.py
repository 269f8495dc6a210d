"""The chapter 2 explorers: pure compute functions, and that the widgets build."""

import numpy as np
import pytest

from coursekit.explorers import ch2


def test_planner_reaches_the_target_with_the_exact_model():
    r = ch2.planner_compute(T=2.0, target=1.5)
    assert r["end_error"] < 1e-5
    np.testing.assert_allclose(r["y"], r["yd"], atol=1e-5)
    # u_d starts at m y_d''(0) (the cubic's jump) and ends at k * target
    assert r["ud"][-1] == pytest.approx(2.0 * 1.5)


def test_planner_quintic_has_a_continuous_input_and_mass_error_drifts():
    r = ch2.planner_compute(T=2.0, target=1.0, r=3)
    assert abs(r["ud"][0]) < 1e-9
    wrong = ch2.planner_compute(T=2.0, target=1.0, mass_error=10.0)
    assert wrong["end_error"] > 1e-3


def test_robot_planner_drives_the_plan_and_reports_singular_plans():
    r = ch2.robot_planner_compute(x_T=3.0, y_T=2.0, heading_deg=45.0, T=5.0, speed=1.0)
    assert r["end_error"] < 1e-3
    np.testing.assert_allclose(r["driven"][:, :2], r["path"][:, :2], atol=1e-3)
    bad = ch2.robot_planner_compute(speed=0.0)
    assert bad["path"].shape == (0, 3) and "speed must be nonzero" in bad["message"]


def test_bad_input():
    with pytest.raises(ValueError, match=r"r must be >= 2"):
        ch2.planner_compute(r=1)
    with pytest.raises(ValueError, match=r"T must be positive"):
        ch2.robot_planner_compute(T=0.0)


@pytest.mark.parametrize("factory", [ch2.planner_explorer, ch2.robot_planner_explorer])
def test_explorers_build_and_update(factory):
    explorer = factory()
    assert explorer.result is not None and explorer._png.startswith(b"\x89PNG")
    before = explorer.result
    explorer.widget  # wires the sliders
    first = next(iter(explorer.controls.values()))
    first.value = first.min
    assert explorer.params[next(iter(explorer.controls))] == first.min
    assert explorer.result is not before
