"""The chapter 2 explorers: pure compute functions, and that the widgets build."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp
from scipy.special import fresnel

import coursekit as ck
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


@pytest.mark.parametrize("T, r", [(3.1, 2), (0.7, 2), (5.5, 3)])
def test_planner_matches_an_ode_solver_before_and_after_the_jump_of_u_at_T(T, r):
    """The plant with a 10 % mass error, driven by u_d (2.30) up to T and by k * target after:
    against solve_ivp run in two parts on the exact input. The cubic's u_d jumps at T (r = 2),
    which one simulation over the whole grid would smear over the interval around T."""
    m0, d, k = ch2.PLANNER_PLANT["m"], ch2.PLANNER_PLANT["d"], ch2.PLANNER_PLANT["k"]
    m, target = 1.1 * m0, 1.5
    got = ch2.planner_compute(T=T, target=target, mass_error=10.0, r=r)
    zeros = [0.0] * (r - 1)
    traj = ck.poly_trajectory(T, [0.0] + zeros, [target] + zeros)
    ud = ck.feedforward([k / m0, d / m0], 1.0 / m0, traj)     # planned for the nominal mass

    def plant(u):
        return lambda t, x: [x[1], (u(t) - d * x[1] - k * x[0]) / m]

    t = got["t"]
    plan = solve_ivp(plant(lambda s: float(ud(s))), (0.0, T), [0.0, 0.0], rtol=1e-11, atol=1e-13,
                     dense_output=True)
    held = solve_ivp(plant(lambda s: k * target), (T, t[-1]), plan.y[:, -1], rtol=1e-11, atol=1e-13,
                     dense_output=True)
    expected = np.where(t <= T, plan.sol(np.minimum(t, T))[0], held.sol(np.maximum(t, T))[0])
    assert t[-1] == pytest.approx(ch2.time_shown(T)) and T in t
    np.testing.assert_allclose(got["y"], expected, atol=2e-5)
    assert got["end_error"] == pytest.approx(abs(plan.y[0, -1] - target), abs=2e-5)
    assert got["end_error"] > 1e-3                           # the mass error shows


def test_time_shown_is_two_to_three_horizons_and_changes_at_ten_of_the_slider_s_values():
    Ts = np.round(np.arange(0.5, 10.05, 0.1), 1)
    ends = np.array([ch2.time_shown(T) for T in Ts])
    assert np.all((2 * Ts <= ends + 1e-12) & (ends <= 3 * Ts))
    assert sorted(set(ends)) == [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0, 20.0]
    assert ch2.time_shown(3.0) == 6.0 and ch2.time_shown(3.1) == 8.0
    with pytest.raises(ValueError, match="T must be positive"):
        ch2.time_shown(0.0)


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
    assert explorer.result is not None and explorer.png.startswith(b"\x89PNG")
    before = explorer.result
    explorer.widget  # wires the sliders
    first = next(iter(explorer.controls.values()))
    first.value = first.min
    assert explorer.params[next(iter(explorer.controls))] == first.min
    assert explorer.result is not before


def test_drive_robot_follows_a_circle_and_a_clothoid_exactly():
    t = np.linspace(0.0, 7.0, 301)
    v, w = 1.5, 0.8                        # constant speed and turn rate: a circle of radius v / w
    x = ch2.drive_robot(t, np.column_stack([np.full_like(t, v), np.full_like(t, w)]), np.zeros(3))
    np.testing.assert_allclose(x, np.column_stack([v / w * np.sin(w * t), v / w * (1 - np.cos(w * t)), w * t]),
                               atol=1e-12)
    a = 0.3                                # turn rate 2 a t: theta = a t^2, a clothoid (Fresnel integrals)
    x = ch2.drive_robot(t, np.column_stack([np.full_like(t, v), 2 * a * t]), np.zeros(3))
    S, C = fresnel(t * np.sqrt(2 * a / np.pi))
    scale = v * np.sqrt(np.pi / (2 * a))
    np.testing.assert_allclose(x, np.column_stack([scale * C, scale * S, a * t**2]), atol=1e-12)


def _ode_interval_by_interval(t, u, x0):
    """(1.10) by an ODE solver restarted at every sample, so that no step straddles a kink of
    the piecewise-linear input (stepping across kinks, solve_ivp can miss them by 1e-6)."""
    f = ck.models.two_wheeled_robot().f
    x = [np.asarray(x0, float)]
    for k in range(t.size - 1):
        slope = (u[k + 1] - u[k]) / (t[k + 1] - t[k])
        sol = solve_ivp(lambda tk, xk: f(xk, u[k] + slope * (tk - t[k])), (t[k], t[k + 1]), x[-1],
                        method="DOP853", rtol=1e-12, atol=1e-12)
        x.append(sol.y[:, -1])
    return np.array(x)


@settings(max_examples=15, deadline=None)
@given(st.integers(10, 80), st.floats(0.5, 10.0), st.integers(0, 10_000))
def test_drive_robot_agrees_with_an_ode_solver_on_random_sampled_inputs(samples, T, seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, T, samples)
    u = np.column_stack([1.0 + 0.3 * rng.normal(size=samples).cumsum() / np.sqrt(samples),
                         rng.normal(size=samples).cumsum() / np.sqrt(samples)])
    x0 = rng.normal(size=3)
    ode = _ode_interval_by_interval(t, u, x0)
    np.testing.assert_allclose(ch2.drive_robot(t, u, x0), ode, atol=1e-10 * max(1.0, np.abs(ode).max()))


def test_the_robot_planner_s_path_is_on_one_scale_with_limits_a_draw_keeps_and_labels_whole_on_the_site():
    """Issue 34: the path's equal aspect without a full draw at every frame. Its limits are set
    by the update from the settings (x1 and x2 on one scale in a box of fixed aspect), so a draw
    does not move them (matplotlib's equal aspect did, from where the layout put the axes), and
    the website's column shows every label whole."""
    from layout_check import text_problems

    from coursekit.tools.site_figures import drawn_for_the_column
    e = ch2.robot_planner_explorer()
    ax = e.handles["ax"]
    for moved in ({}, {"x_T": -6.0, "y_T": 6.0}, {"T": 20.0, "speed": 2.0}, {"heading_deg": -180.0}):
        for name, value in moved.items():
            e.controls[name].value = value
        limits = ax.get_xlim(), ax.get_ylim()
        e.frames.reset()
        e.frames.frame()                                          # a full draw
        assert (ax.get_xlim(), ax.get_ylim()) == limits, moved
        box = ax.get_window_extent()
        metre_x, metre_y = box.width / np.ptp(limits[0]), box.height / np.ptp(limits[1])
        assert metre_x == pytest.approx(metre_y, rel=1e-3), moved
        with drawn_for_the_column(e.fig, e.natural_dpi):
            assert text_problems(e.fig) == [], moved


def test_the_robot_planner_s_plane_holds_every_target_so_a_target_step_keeps_its_limits():
    """Issue 34: every step of a target moved the plane's limits, so each key step drew the whole
    figure. The plane holds the square of the targets the sliders offer: a step is blitted."""
    e = ch2.robot_planner_explorer()
    ax = e.handles["ax"]
    shown = ax.get_xlim(), ax.get_ylim()
    box = e.controls["x_T"].min, e.controls["x_T"].max
    assert shown[0][0] <= box[0] and box[1] <= shown[0][1] and shown[1][0] <= box[0] and box[1] <= shown[1][1]
    for name, values in (("x_T", (3.5, 3.0, 2.5, 6.0, 5.5)), ("y_T", (2.5, 3.0, 1.5, -2.0))):
        for value in values:
            e.controls[name].value = value
            assert (ax.get_xlim(), ax.get_ylim()) == shown, (name, value)
    e.controls["y_T"].value, e.controls["x_T"].value = 2.0, 4.0
    draws = e.frames.full_draws
    for value in (3.5, 3.0, 2.5):          # the inputs stay in their limits here too: blitted
        e.controls["x_T"].value = value
    assert e.frames.full_draws == draws
