"""Chapter 3 explorers: the pure compute functions and the widget factories."""

import numpy as np
import pytest

import coursekit as ck
from conftest import sorted_eig
from coursekit.explorers import ch3


def test_pair_poles():
    np.testing.assert_allclose(ch3.pair_poles(2.0, 0.6), [-1.2 + 1.6j, -1.2 - 1.6j])
    np.testing.assert_allclose(ch3.pair_poles(1.0, 1.25), [-0.5, -2.0])
    with pytest.raises(ValueError, match="zeta must be positive"):
        ch3.pair_poles(1.0, 0.0)


@pytest.mark.parametrize("wn, zeta, p3", [(2.0, 0.7, -3.0), (1.0, 1.0, -0.5), (5.0, 0.2, -8.0)])
def test_pole_placement_compute_places_the_poles(wn, zeta, p3):
    r = ch3.pole_placement_compute(wn=wn, zeta=zeta, p3=p3)
    np.testing.assert_allclose(sorted_eig(r["achieved"]), sorted_eig(r["poles"]), atol=1e-6)
    np.testing.assert_allclose(r["K"], ck.place(ch3.PLACEMENT_A, ch3.PLACEMENT_B, r["poles"]))
    np.testing.assert_allclose(r["u"], r["x"] @ r["K"][0])
    from scipy.linalg import expm
    A_cl = ch3.PLACEMENT_A + ch3.PLACEMENT_B @ r["K"]
    np.testing.assert_allclose(r["x"][-1], expm(A_cl * r["t"][-1]) @ [1, 0, 0], atol=1e-8)
    assert r["max_u"] == pytest.approx(np.abs(r["u"]).max())


def test_upright_pendulum_compute_both_controllers():
    r = ch3.upright_pendulum_compute(theta0_deg=30.0)
    assert r["linear_ok"] and r["fl_ok"]
    assert r["dev_linear"][0] == pytest.approx(30.0)          # theta - pi starts at the slider's angle
    # the feedback-linearized loop is exactly linear: e'' = -6 e - 5 e' from e(0) = 30 deg
    t = r["t"]
    exact = 30.0 * (3 * np.exp(-2 * t) - 2 * np.exp(-3 * t))
    np.testing.assert_allclose(r["dev_fl"], exact, atol=1e-4)
    # a tight torque limit loses the pendulum from 120 degrees
    r = ch3.upright_pendulum_compute(theta0_deg=120.0, u_max=3.0)
    assert not r["fl_ok"] and np.abs(r["u_linear"]).max() <= 3.0 + 1e-12
    with pytest.raises(ValueError, match="pole must be negative"):
        ch3.upright_pendulum_compute(pole=1.0)


def test_integral_action_compute_removes_the_offset():
    r = ch3.integral_action_compute(d=2.0, integral_pole=-1.5, t_end=20.0)
    assert r["offset"] == pytest.approx(1.0)                   # -(A + B K)^-1 B d, first entry
    assert r["y_plain"][-1] == pytest.approx(1.0, abs=1e-5)
    assert abs(r["y_int"][-1]) < 1e-5
    assert r["u_int"][-1] == pytest.approx(-2.0, abs=1e-5)      # it ends by cancelling d
    A_E, B_E = ck.integral_augment(ch3.INTEGRAL_A, ch3.INTEGRAL_B)
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(A_E + B_E @ r["K_E"])), [-2, -1.5, -1], atol=1e-8)
    with pytest.raises(ValueError, match="integral_pole must be negative"):
        ch3.integral_action_compute(integral_pole=0.5)


@pytest.mark.parametrize("factory", [ch3.pole_placement_explorer, ch3.upright_pendulum_explorer,
                                     ch3.integral_action_explorer])
def test_explorers_build_label_and_refresh(factory):
    e = factory()
    assert e.fig.axes and e.png.startswith(b"\x89PNG")
    for ax in e.fig.axes:
        assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title()
    name, widget = next(iter(e.controls.items()))
    before = e.result
    widget.value = widget.max
    e.refresh()
    assert e.params[name] == widget.max and e.result is not before
    assert widget.continuous_update is True   # the figure follows the slider while it is dragged


def test_integral_action_responses_are_linear_in_d_and_the_axes_hold_the_largest_d():
    one = ch3.integral_action_compute(d=1.0, integral_pole=-1.5)
    two = ch3.integral_action_compute(d=-2.5, integral_pole=-1.5)
    for key in ("y_plain", "y_int", "u_plain", "u_int"):
        np.testing.assert_allclose(two[key], -2.5 * one[key], atol=1e-12)
    assert one["y_per_d"] == max(np.abs(one["y_plain"]).max(), np.abs(one["y_int"]).max())
    zero = ch3.integral_action_compute(d=0.0, integral_pole=-1.5)
    assert not np.any(zero["y_plain"]) and zero["y_per_d"] == one["y_per_d"]
    e = ch3.integral_action_explorer()
    limits = e.handles["ax_y"].get_ylim()
    e.controls["d"].value = 0.25
    e.refresh()
    assert e.handles["ax_y"].get_ylim() == limits       # a smaller d draws a smaller response
    assert limits[1] >= ch3.INTEGRAL_D_MAX * e.result["y_per_d"]


def test_the_pendulum_started_upright_is_drawn_flat_not_its_numerical_noise():
    e = ch3.upright_pendulum_explorer()
    e.controls["theta0_deg"].value = 0.0
    e.refresh()
    assert 0 < np.abs(e.result["dev_linear"]).max() < 1e-6        # the integrator's noise only
    low, high = e.handles["ax_th"].get_ylim()
    assert high - low >= 2.0 and low < 0 < high
    low, high = e.handles["ax_u"].get_ylim()
    assert high - low >= 0.2
    e.controls["theta0_deg"].value = 30.0                         # a real response keeps its scale
    e.refresh()
    low, high = e.handles["ax_th"].get_ylim()
    assert high >= 30.0 and high - low < 60.0 + 30.0


def test_a_step_of_the_pendulum_s_initial_angle_keeps_the_limits_within_an_eighth_turn():
    """Issue 34: every 5 degree step moved both axes' limits (each key step drew the whole figure).
    The angle axis holds whole eighth turns from upright, the torque axis the torque limit."""
    e = ch3.upright_pendulum_explorer()
    ax_th, ax_u = e.handles["ax_th"], e.handles["ax_u"]
    shown = ax_th.get_ylim(), ax_u.get_ylim()
    e.controls["theta0_deg"].value = 35.0      # the first frame after the explorer's is drawn whole
    draws = e.frames.full_draws
    for value in (40.0, 45.0, 25.0, 5.0):
        e.controls["theta0_deg"].value = value
        assert (ax_th.get_ylim(), ax_u.get_ylim()) == shown, value
    assert e.frames.full_draws == draws                      # every step blitted
    low, high = ax_th.get_ylim()
    assert low < 0 < 45 < high < 60                            # an eighth turn and a margin
    assert ax_u.get_ylim()[0] <= -e.params["u_max"] and e.params["u_max"] <= ax_u.get_ylim()[1]
    e.controls["theta0_deg"].value = -50.0                     # the other side, past an eighth turn
    low, high = ax_th.get_ylim()
    assert -100 < low < -90 and 0 < high < 10


def test_a_drag_of_the_pendulum_s_initial_angle_only_grows_the_angle_axis_until_it_rests():
    """Issue 34: the angle axis followed each eighth turn both ways while a hand dragged, so a
    drag out and back drew the whole figure about every other frame; it only grows while the hand
    moves (the policy of `rescale`), and at rest it is that of the settings alone."""
    from coursekit.explorers import limits
    e, fresh = ch3.upright_pendulum_explorer(), ch3.upright_pendulum_explorer()
    ax_th, draws, shown = e.handles["ax_th"], e.frames.full_draws, []
    for value in [*range(25, -155, -5), *range(-150, 35, 5)]:
        with limits.moving():
            e.controls["theta0_deg"].value = float(value)
        shown.append(ax_th.get_ylim())
    assert all(a[0] >= b[0] and a[1] <= b[1] for a, b in zip(shown, shown[1:])), "the angle axis shrank"
    assert e.frames.full_draws - draws <= 8
    e.refresh()                                   # at rest
    fresh.controls["theta0_deg"].value = 30.0
    assert ax_th.get_ylim() == fresh.handles["ax_th"].get_ylim()
