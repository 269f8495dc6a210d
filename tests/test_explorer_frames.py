"""Explorer frames: a dragged slider gives the same figure as a fresh draw, mostly by blitting,
rendered at the size and pixel ratio the browser reports."""

import io

import numpy as np
import pytest
from matplotlib.figure import Figure

import coursekit as ck
from coursekit.explorers import ch1, ch2, ch3, ch4
from coursekit.explorers._base import MIN_SCALE
from coursekit.explorers._frames import FrameRenderer, snap_limits

FACTORIES = [ch1.euler_explorer, ch1.msd_explorer, ch2.planner_explorer, ch2.robot_planner_explorer,
             ch3.pole_placement_explorer, ch3.upright_pendulum_explorer, ch3.integral_action_explorer,
             ch4.observer_noise_explorer, ch4.kalman_tuning_explorer]


@pytest.fixture(autouse=True)
def _lecture_mode_off():
    yield
    ck.lecture_mode(False)


def _pixels(png: bytes) -> np.ndarray:
    from matplotlib.image import imread
    return imread(io.BytesIO(png), format="png")


def _size(png: bytes) -> tuple[int, int]:
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")


def _sliders(explorer):
    return {name: w for name, w in explorer.controls.items() if hasattr(w, "step") and hasattr(w, "max")}


def _drag_values(widget, moves: int = 12) -> list:
    """Values a hand passes through when dragging `widget` from its value towards its maximum and
    on to its minimum, on the slider's own steps."""
    up = np.linspace(widget.value, widget.max, moves // 2)
    down = np.linspace(widget.max, widget.min, moves - moves // 2)
    values = [widget.min + round((v - widget.min) / widget.step) * widget.step for v in np.r_[up, down]]
    return [type(widget.value)(v) for v in values]


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_dragging_the_first_slider_gives_the_figure_of_a_fresh_draw(factory):
    dragged = factory()
    name, widget = next(iter(_sliders(dragged).items()))
    for value in _drag_values(widget):
        widget.value = value
        dragged.refresh()
    fresh = factory()
    fresh.controls[name].value = widget.value
    fresh.refresh()
    assert dragged.params == fresh.params
    if any(ax.get_aspect() != "auto" for ax in dragged.fig.axes):
        # equal scales that widen the limits to the box (the robot's path): constrained layout
        # and the aspect settle together over a few draws, so the place of the axes can differ
        # by a fraction of a percent; what is drawn must be the same
        for a, b in zip(dragged.fig.axes, fresh.fig.axes):
            for la, lb in zip(a.get_lines(), b.get_lines()):
                np.testing.assert_array_equal(la.get_xydata(), lb.get_xydata())
            assert a.get_title() == b.get_title()
            np.testing.assert_allclose(a.get_position().bounds, b.get_position().bounds, atol=0.01)
    else:
        np.testing.assert_array_equal(_pixels(dragged.png), _pixels(fresh.png))


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_drag_back_over_states_passed_before_reuses_their_backgrounds_and_draws_right(factory):
    dragged = factory()
    if dragged.frames._fixed_aspect():
        pytest.skip("a figure with a fixed-aspect axes (the robot's path) is drawn whole every time")
    name, widget = next(iter(_sliders(dragged).items()))
    there = _drag_values(widget, moves=16)
    path = there + there[::-1][1:]         # to the maximum, the minimum and back again
    checked, states = 0, set()
    for value in path:
        reuses = dragged.frames.reuses
        widget.value = value
        dragged._cache.clear()             # draw each frame (not the explorer's copy of it)
        dragged.refresh()
        states.add(dragged.frames._key)
        if dragged.frames.reuses > reuses and checked < 3:   # a frame on a background kept
            checked += 1
            fresh = factory()
            fresh.controls[name].value = value
            fresh.refresh()
            np.testing.assert_array_equal(_pixels(dragged.png), _pixels(fresh.png), err_msg=f"{name} = {value}")
    assert checked > 0 or len(states) == 1, "the way back drew every state whole again"
    assert dragged.frames.full_draws <= len(states) + 1


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_hand_moving_a_slider_step_by_step_draws_the_whole_figure_only_when_it_changed(factory):
    e = factory()
    if e.frames._fixed_aspect():
        pytest.skip("a figure with a fixed-aspect axes (the robot's path) is drawn whole every time")
    for name, widget in _sliders(e).items():
        direction = 1 if widget.value + 8 * widget.step <= widget.max else -1
        for _ in range(8):
            key, moving, draws = e.frames._key, set(e.frames._moving), e.frames.full_draws
            widget.value = type(widget.value)(widget.value + direction * widget.step)
            e.refresh()
            if e.frames.full_draws > draws:
                assert e.frames._key != key or e.frames._moving != moving, (
                    f"{name} = {widget.value}: the whole figure was drawn although its axes, "
                    "labels and moving artists stayed the same")
    assert e.frames.blits > 0


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_slider_moves_the_figure(factory):
    e = factory()
    for name, widget in _sliders(e).items():
        before = e.png
        widget.value = widget.max if widget.value != widget.max else widget.min
        e.refresh()
        assert e.png != before, f"moving {name} did not change the figure"


def test_a_small_move_blits_and_a_move_past_a_tick_draws_again():
    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    line, = ax.plot([0, 1], [0, 1])
    title = ax.set_title("a = 1")
    frames = FrameRenderer(fig)
    line.set_data([0, 1], [0, 0.9])
    title.set_text("a = 0.9")
    frames.frame()                      # what changed since the renderer was made moves
    assert frames.full_draws == 1 and set(frames._moving) == {line, title}
    line.set_data([0, 1], [0, 0.95])    # the view stays [0, 1] plus margins: reuse the background
    frames.frame()
    assert (frames.full_draws, frames.blits) == (1, 1)
    line.set_data([0, 1], [0, 3.3])     # past a tick: the axis changes, draw everything again
    ax.relim()
    ax.autoscale_view()
    frames.frame()
    assert (frames.full_draws, frames.blits) == (2, 1)
    ax.set_ylabel("y [m]")              # a new axis label is part of the background too
    frames.frame()
    assert (frames.full_draws, frames.blits) == (3, 1)


def test_snap_limits_puts_an_autoscaled_view_on_round_numbers_plus_margins():
    ax = Figure().subplots()
    ax.plot([0, 6], [0.03, 0.97])
    snap_limits(ax)
    lo, hi = ax.get_ylim()
    assert (lo, hi) == pytest.approx((0 - 0.05, 1 + 0.05))
    assert ax.get_xlim() == pytest.approx((-0.3, 6.3))
    assert ax.get_autoscaley_on()          # still autoscaled: the next rescale may change it


def test_snap_limits_widens_limits_set_by_hand_to_round_numbers_and_keeps_an_inverted_axis():
    ax = Figure().subplots()
    ax.set_xlim(-11.3, 4.0)
    ax.set_ylim(7.3, -7.3)
    snap_limits(ax)
    lo, hi = ax.get_xlim()
    # not on ticks: round numbers about a quarter of the range apart (here 5), plus the margin
    assert (lo, hi) == pytest.approx((-15 - 0.05 * 20, 5 + 0.05 * 20))
    ax.set_xlim(0.0, 12.0)                                                   # a time axis [0, T]
    snap_limits(ax)
    assert ax.get_xlim() == pytest.approx((-0.6, 12.6))
    lo, hi = ax.get_ylim()
    assert lo > hi and lo > 7.3 and hi < -7.3


def test_snap_limits_on_a_log_axis_stays_finite():
    ax = Figure().subplots()
    ax.semilogy([0, 1, 2], [1e-3, 2e-2, 0.7])
    snap_limits(ax)
    lo, hi = ax.get_ylim()
    assert lo <= 1e-3 and hi >= 1.0 and np.isfinite([lo, hi]).all()


def _shown(explorer, **screen):
    view = explorer.widget.children[-1]
    view.screen = screen                 # what the browser reports
    return view


def test_the_figure_is_rendered_at_the_pixel_size_it_is_shown_with():
    e = ch1.euler_explorer()
    natural = _size(e.png)
    view = _shown(e, width=2000, height=2000, ratio=2.0)
    assert _size(e.png) == (2 * natural[0], 2 * natural[1])      # crisp on a high-density screen
    assert (view.css_width, view.css_height) == (natural[0], natural[1])
    assert view.png == e.png
    view = _shown(e, width=natural[0] // 2, height=2000, ratio=1.0)   # a narrow output area
    width, height = _size(e.png)
    assert width <= natural[0] // 2 + 1 and (view.css_width, view.css_height) == (width, height)
    _shown(e, width=50, height=50, ratio=1.0)                       # never smaller than MIN_SCALE
    assert _size(e.png)[0] >= MIN_SCALE * natural[0] - 1


def test_the_static_figure_keeps_its_natural_size_after_the_browser_reports():
    import base64
    e = ch1.msd_explorer()
    natural = _size(e.png)
    _shown(e, width=500, height=300, ratio=2.0)
    static = base64.b64decode(e._repr_mimebundle_()["image/png"])
    assert _size(static) == natural and _size(e.png) != natural


def test_lecture_mode_grows_the_figure_to_the_room_and_marks_the_widget():
    ck.lecture_mode()
    e = ch1.euler_explorer()
    natural = _size(e.png)
    _shown(e, width=3 * natural[0], height=3 * natural[1], ratio=1.0)
    assert _size(e.png)[0] > 1.5 * natural[0]
    assert "ck-lecture" in e.widget._dom_classes and "ck-explorer" in e.widget._dom_classes
    ck.lecture_mode(False)
    plain = ch1.euler_explorer()
    _shown(plain, width=3 * natural[0], height=3 * natural[1], ratio=1.0)
    assert _size(plain.png)[0] <= natural[0] + 1         # outside lecture mode: natural size at most
    assert "ck-lecture" not in plain.widget._dom_classes


def test_sliders_follow_the_hand():
    e = ch3.pole_placement_explorer()
    assert all(w.continuous_update for w in _sliders(e).values())


def test_encode_png_drops_alpha_only_when_every_pixel_is_opaque():
    from coursekit.explorers._frames import encode_png
    rgba = np.full((6, 5, 4), 255, dtype=np.uint8)
    rgba[2, 3] = [10, 20, 30, 255]
    opaque = _pixels(encode_png(rgba, 100))
    assert opaque.shape == (6, 5, 3)
    np.testing.assert_array_equal(np.round(opaque * 255), rgba[..., :3])
    rgba[0, 0, 3] = 0
    see_through = _pixels(encode_png(rgba, 100))
    assert see_through.shape == (6, 5, 4) and see_through[0, 0, 3] == 0


def test_a_shared_time_axis_set_by_hand_keeps_its_limits_plus_margins():
    # the second axes of a shared time axis snapped it again: [0, 10] was shown as [-6, 16]
    fig = Figure(figsize=(6, 4))
    top, bottom = fig.subplots(2, 1, sharex=True)
    t = np.linspace(0, 10, 50)
    lines = top.plot([], []) + bottom.plot([], [])
    frames = FrameRenderer(fig)
    for k in range(3):
        for line in lines:
            line.set_data(t, np.sin(t + k))
        top.set_xlim(0, 10)
        frames.frame()
        assert top.get_xlim() == bottom.get_xlim() == pytest.approx((-0.5, 10.5))


@pytest.mark.parametrize("factory", [ch1.euler_explorer, ch2.planner_explorer, ch4.observer_noise_explorer,
                                     ch4.kalman_tuning_explorer], ids=lambda f: f.__name__)
def test_the_explorers_time_axes_show_the_simulated_time(factory):
    e = factory()
    widget = next(iter(_sliders(e).values()))
    for value in _drag_values(widget, moves=4):
        widget.value = value
        e._cache.clear()                   # draw the frame (a frame kept is not drawn again)
        e.refresh()
        # the axes share their time axis: the simulated time is that of all their curves
        times = np.concatenate([line.get_xdata() for ax in e.fig.axes for line in ax.get_lines()
                                if len(line.get_xdata()) > 1])
        lo, hi = times.min(), times.max()
        for ax in e.fig.axes:
            assert ax.get_xlim() == pytest.approx((lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))), value


def test_snapping_limits_set_by_hand_again_does_not_widen_them():
    ax = Figure().subplots()
    ax.set_xlim(-8.0, 8.0)
    done = snap_limits(ax)
    for _ in range(3):
        assert snap_limits(ax, done=done) == done
    ax.set_xlim(-8.0, 8.0)              # set again by hand (an update): snapped again, alike
    assert snap_limits(ax, done=done) == done


def test_settings_shown_before_come_from_the_frame_cache_and_the_artists_follow():
    e = ch1.msd_explorer()
    m = e.controls["m"]
    first = e.png
    m.value = 2.0
    e.refresh()
    second, draws = e.png, (e.frames.full_draws, e.frames.blits)
    m.value = 1.0                        # dragged back: the frame is not drawn again
    e.refresh()
    assert e.png == first and (e.frames.full_draws, e.frames.blits) == draws
    np.testing.assert_allclose(e.handles["y"].get_ydata(), ch1.msd_compute(m=1.0, d=0.5, k=2.0)["y"])
    assert e.result["m"] == 1.0
    m.value = 2.0
    e.refresh()
    assert e.png == second


def test_the_frame_cache_is_bounded_and_dropped_when_the_resolution_changes():
    from coursekit.explorers._base import FRAME_CACHE_SIZE
    e = ch1.euler_explorer()
    ts = e.controls["Ts"]
    for k in range(FRAME_CACHE_SIZE + 5):
        ts.value = round(ts.min + (k % 90) * ts.step, 2)
        e.refresh()
    assert len(e._cache) <= FRAME_CACHE_SIZE
    _shown(e, width=300, height=300, ratio=1.0)
    assert len(e._cache) == 1 and next(iter(e._cache))[1] == e.fig.dpi


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_slider_starts_on_one_of_its_steps(factory):
    # a browser's slider moves a value between steps to the nearest step, so an explorer would
    # show other settings than its defaults as soon as it is displayed
    for name, w in _sliders(factory()).items():
        steps = (w.value - w.min) / w.step
        assert abs(steps - round(steps)) < 1e-6, (
            f"{factory.__name__}: slider {name} starts at {w.value}, between the steps "
            f"{w.min} + k * {w.step}")
