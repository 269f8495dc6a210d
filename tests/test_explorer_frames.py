"""Explorer frames: blitted frames show what a full draw shows, full draws happen only when the
axes change, the axes hold their data, and the figure is rendered at the size it is shown with."""

import io

import numpy as np
import pytest
from matplotlib.figure import Figure

import coursekit as ck
from coursekit.tools.chapters import explorer_factories
from coursekit.explorers import ch1, ch2, ch3, limits, rescale
from coursekit.explorers._base import MIN_SCALE
from coursekit.explorers._frames import FrameRenderer, encode_png

from test_figure_layout import undrawn  # an explorer whose refreshes draw no frame

#: every explorer of the course (a new chapter's too)
FACTORIES = list(explorer_factories().values())


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


def _drawn_whole(fig) -> bytes:
    """`fig` drawn whole, animated artists included, with the axes where they are (a layout
    engine run again would move them by a fraction of a pixel)."""
    animated = [a for a in fig.findobj() if a.get_animated()]
    engine = fig.get_layout_engine()
    fig.set_layout_engine("none")
    try:
        for artist in animated:
            artist.set_animated(False)
        fig.canvas.draw()
        return encode_png(fig.canvas.buffer_rgba(), fig.dpi)
    finally:
        for artist in animated:
            artist.set_animated(True)
        fig.set_layout_engine(engine)


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_blitted_frame_of_a_drag_is_the_full_draw_of_the_same_figure(factory):
    e = factory()
    widget = next(iter(_sliders(e).values()))
    blits = 0
    for value in _drag_values(widget):
        widget.value = value
        before = e.frames.blits
        e.refresh()
        if e.frames.blits > before and blits < 3:
            blits += 1
            np.testing.assert_array_equal(_pixels(e.png), _pixels(_drawn_whole(e.fig)), err_msg=f"{value}")
    if not any(ax.get_aspect() != "auto" for ax in e.fig.axes):
        assert blits > 0, "no frame of the drag was blitted"


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_drag_draws_the_whole_figure_only_when_its_axes_changed(factory):
    e = factory()
    for name, widget in list(_sliders(e).items())[:2]:
        for value in _drag_values(widget, moves=8):
            state, moving, draws = e.frames.state(), set(e.frames.moving), e.frames.full_draws
            widget.value = value
            e.refresh()
            if e.frames.full_draws > draws and not any(ax.get_aspect() != "auto" for ax in e.fig.axes):
                assert e.frames.state() != state or e.frames.moving != moving, (
                    f"{name} = {value}: the whole figure was drawn although its axes and its moving "
                    "artists stayed the same")


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_slider_changes_the_figure_or_the_readout(factory):
    e = factory()
    for name, widget in _sliders(e).items():
        before = e.png, e.text
        widget.value = widget.max if widget.value != widget.max else widget.min
        e.refresh()
        assert e.error is None and (e.png, e.text) != before, f"moving {name} changed nothing"


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_the_time_axes_show_the_simulated_time_and_nothing_more(factory):
    # a newcomer saw the pendulum's time axis run to 6.3 s with data to 5 s
    e = undrawn(factory())      # the limits are set by the update, before any frame is drawn
    widget = next(iter(_sliders(e).values()))
    for value in [widget.value, *_drag_values(widget, moves=6)]:
        widget.value = value
        e.refresh()
        for ax in e.fig.axes:
            if ax.get_xlabel().startswith("time"):
                lo, hi = ax.get_xlim()
                end = e.result["t"][-1]
                assert -0.02 * end - 1e-9 <= lo <= 0.0, (value, ax.get_xlim())
                # exactly [0, t_end], or (a horizon that moves with a slider) filled half at least
                assert end <= hi <= 2 * end + 1e-9, (value, ax.get_xlim(), end)


@pytest.fixture
def fitted(monkeypatch):
    """The axes and axis names whose limits `rescale` has fitted since the test began, with
    the smallest span asked for."""
    seen, original = {}, limits._fit

    def spy(ax, name, min_span, *args):
        seen[ax, name] = min_span
        return original(ax, name, min_span, *args)
    monkeypatch.setattr(limits, "_fit", spy)
    return seen


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_the_axes_fitted_to_the_data_hold_them_and_are_half_filled_at_least(factory, fitted):
    e = undrawn(factory())      # `rescale` fits the limits in the update, before any frame is drawn
    for widget in _sliders(e).values():
        for value in _drag_values(widget, moves=4):
            widget.value = value
            e.refresh()
            filled = {}
            for (ax, name), min_span in fitted.items():
                scale = getattr(ax, f"{name}axis").get_transform()
                # the data limits rescale measured (relim)
                lo, hi = scale.transform(getattr(ax.dataLim, f"interval{name}"))
                view = sorted(scale.transform(getattr(ax, f"get_{name}lim")()))
                assert view[0] <= lo + 1e-9 and hi <= view[1] + 1e-9, (name, value, view, (lo, hi))
                # else the view is the smallest span, centred on the data
                half = hi - lo <= min_span or hi - lo >= (view[1] - view[0]) / 2 - 1e-9
                filled.setdefault(ax, []).append(half)
            for ax, halves in filled.items():
                # axes of a fixed shape with x and y on one scale (the robot's path) are widened
                # along one of them: the other is half filled
                assert (any if ax.get_box_aspect() else all)(halves), (value, ax.get_title(), halves)


def test_a_small_move_blits_and_a_change_of_the_axes_draws_again():
    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    line, = ax.plot([0, 1], [0, 1])
    frames = FrameRenderer(fig)
    frames.frame()
    line.set_data([0, 1], [0, 0.9])
    frames.frame()                      # what changed since the first frame moves from now on
    assert frames.full_draws == 2 and frames.moving == {line}
    line.set_data([0, 1], [0, 0.95])    # the axes stay: the background is reused
    frames.frame()
    assert (frames.full_draws, frames.blits) == (2, 1)
    ax.set_ylim(0, 3)                   # new limits: draw everything again
    frames.frame()
    assert (frames.full_draws, frames.blits) == (3, 1)
    ax.set_ylabel("y [m]")              # a new axis label is part of the background too
    frames.frame()
    assert (frames.full_draws, frames.blits) == (4, 1)


def test_an_artist_drawn_over_a_moving_one_is_drawn_again_with_it():
    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    line, = ax.plot([0, 1], [0, 1], lw=8)
    legend = ax.legend(["a line"], loc="center")
    ax.set_title("a title that no curve can reach")
    frames = FrameRenderer(fig)
    frames.frame()
    line.set_data([0, 1], [1, 0])
    frames.frame()
    assert legend.get_animated() and line.get_animated()
    assert not ax.title.get_animated()                 # above the axes: it stays in the background
    line.set_data([0, 1], [0.5, 0.5])   # right under the legend
    np.testing.assert_array_equal(_pixels(frames.frame()), _pixels(_drawn_whole(fig)))


def test_an_artist_placed_in_data_coordinates_is_measured_again_when_the_limits_move():
    """Which artists can meet a moving one is measured once while the text and layout stay (a
    legend's extent costs a tenth of a full draw), except for those placed in data coordinates:
    new limits can bring them onto the data, where they must be drawn again over the moving curve."""
    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    line, = ax.plot([0, 1], [0, 1], lw=8)
    ax.set_ylim(0, 1)
    label = ax.text(0.5, 5.0, "MMMM", fontsize=30, zorder=5, ha="center", va="center")   # above the view
    frames = FrameRenderer(fig)
    frames.frame()
    line.set_data([0, 1], [0, 0.9])
    frames.frame()
    assert not label.get_animated()
    ax.set_ylim(0, 10)                   # the label is on the data now: a full draw
    line.set_data([0, 1], [5.0, 5.0])
    frames.frame()
    assert label.get_animated()
    line.set_data([0, 1], [5.1, 5.1])    # a blit: the curve right under the label
    blits = frames.blits
    np.testing.assert_array_equal(_pixels(frames.frame()), _pixels(_drawn_whole(fig)))
    assert frames.blits == blits + 1


def test_rescale_at_rest_depends_on_the_data_alone_rounded_out_to_a_round_step():
    ax = Figure().subplots()
    line, = ax.plot([0, 1], [0, 1])
    rescale(ax)
    first = ax.get_ylim()
    # padded to fill 80 % (0.125 each side), each end out to a multiple of 0.1 (<= the padding),
    # then 5 % of that span more (no tick on the frame's corner)
    assert first == pytest.approx((-0.27, 1.27))
    line.set_data([0, 1], [0, 1.05])                         # the padded top stays below 1.2
    rescale(ax)
    assert ax.get_ylim() == first
    line.set_data([0, 1], [0, 2.0])
    rescale(ax)
    assert ax.get_ylim() == pytest.approx((-0.54, 2.54))     # padding 0.25: a step of 0.2
    line.set_data([0, 1], [0, 1.0])                          # back: the limits of these data again,
    rescale(ax)                                              # whatever came before
    assert ax.get_ylim() == pytest.approx(first)
    assert ax.get_xlim() != pytest.approx(first)             # x left to matplotlib
    fresh = Figure().subplots()
    fresh.plot([0, 1], [0, 1.0])
    rescale(fresh)
    assert fresh.get_ylim() == ax.get_ylim()
    rescale(ax, fill=1.0)                                    # fill=1: the data exactly
    assert ax.get_ylim() == (0.0, 1.0)
    with pytest.raises(ValueError, match="fill must be a number in"):
        rescale(ax, fill=0.0)


def test_rescale_only_grows_the_limits_while_a_control_moves():
    ax = Figure().subplots()
    line, = ax.plot([0, 1], [0, 1])
    rescale(ax)
    assert not limits.is_moving()
    with limits.moving():
        assert limits.is_moving()
        line.set_data([0, 1], [0, 0.2])                      # 14 % of the view: kept while moving
        rescale(ax)
        assert ax.get_ylim() == pytest.approx((-0.27, 1.27))
        line.set_data([0, 1], [1.5, 2.0])                    # out at the top: grown, bottom kept
        rescale(ax)
        low, high = ax.get_ylim()
        assert low == pytest.approx(-0.27) and high == pytest.approx(2.0 + 0.5 * (1 / 0.6 - 1) / 2)
    assert not limits.is_moving()
    rescale(ax)                                              # at rest: fitted to the data
    assert ax.get_ylim() == pytest.approx((1.365, 2.135))


def test_while_a_control_moves_data_near_the_frame_grow_the_limits():
    """Data that still fit the view but reach within Y_EDGE / 2 of its frame are drawn with grown
    limits: kept, a curve's end sat on the frame (the upright pendulum's start after a key step)."""
    ax = Figure().subplots()
    line, = ax.plot([0, 1], [0, 1])
    rescale(ax)                                              # (-0.27, 1.27)
    with limits.moving():
        line.set_data([0, 1], [0, 1.25])                     # 1.3 % of the view below the top
        rescale(ax)
        low, high = ax.get_ylim()
        assert low <= -0.27 and high - 1.25 >= limits.Y_EDGE * (high - low) - 1e-12   # only grown
        grown = ax.get_ylim()
        rescale(ax)                                          # the same data again: kept
        assert ax.get_ylim() == grown


def _first_samples(explorer) -> list[tuple[str, float]]:
    """(curve, how far its first sample lies inside its axes' y limits, as a part of their span)
    for every curve of the explorer's figure (in the axis' scale: decades on a log axis)."""
    found = []
    for k, ax in enumerate(explorer.fig.axes):
        scale = ax.yaxis.get_transform()
        low, high = np.sort(scale.transform(ax.get_ylim()))
        for line in ax.get_lines():
            if line.get_transform() != ax.transData:
                continue                                 # a marker line in axes coordinates (axvline)
            y = np.asarray(line.get_ydata(), dtype=float)
            if y.size and np.isfinite(y[0]):
                first = float(scale.transform([y[0]])[0])
                found.append((f"axes {k} {line.get_label()!r}", min(first - low, high - first) / (high - low)))
    return found


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_key_step_right_after_another_keeps_each_curve_s_start_off_the_frame(factory):
    """A key step less than SETTLE_S after the frame of the one before is drawn while `moving`
    (the limits only grow): each curve's first sample stays Y_EDGE / 2 of the span inside the
    vertical limits, or as far inside as the same settings' figure at rest puts it."""
    e, near = undrawn(factory()), []     # limits and data only: no frame drawn (a tenth of the time)
    for name, widget in _sliders(e).items():
        default = widget.value
        for start in sorted(set(_drag_values(widget, moves=8))):
            for step in (widget.step, -widget.step):
                if not widget.min <= start + step <= widget.max:
                    continue
                widget.value = start                     # no event loop: drawn at rest
                with limits.moving():
                    widget.value = type(default)(start + step)
                moving = _first_samples(e)
                e.refresh()                              # the same settings at rest
                for (curve, inside), (_, at_rest) in zip(moving, _first_samples(e)):
                    if inside < min(at_rest, limits.Y_EDGE / 2) - 1e-9:
                        near.append(f"{name} {start:g} -> {start + step:g}: {curve} starts {inside:.1%} "
                                    f"inside the limits (at rest {at_rest:.1%})")
        widget.value = default
    assert not near, "\n".join(near[:10])


def test_an_explorer_in_a_kernel_grows_its_limits_during_a_drag_and_fits_them_once_at_rest():
    import asyncio

    async def drag_then_rest():
        e = ch1.euler_explorer()            # built where an event loop runs, as in a kernel
        e.widget                             # shown
        ts, ax = e.controls["Ts"], e.handles["ax_err"]
        ts.value = 0.02                      # the error axis (log) fitted to a small error
        await asyncio.sleep(limits.SETTLE_S + 0.2)
        small = ax.get_ylim()
        for value in (0.3, 0.6, 0.3, 0.02):  # out and back: the error grows, then shrinks again
            ts.value = value
        during = ax.get_ylim()
        await asyncio.sleep(limits.SETTLE_S + 0.2)
        return small, during, ax.get_ylim(), e

    small, during, rested, e = asyncio.run(drag_then_rest())
    assert during[1] > 10 * small[1]         # grown on the way out, not shrunk on the way back
    assert rested == small                   # fitted again once the slider rested, as before the drag
    assert e.png == e.frames.frame()         # and the rested frame is the one sent


def test_an_explorer_in_a_kernel_fits_a_single_step_at_once_in_one_frame():
    import asyncio

    async def steps():
        e = ch1.euler_explorer()
        e.widget
        sent, send = [], e._send
        e._send = lambda: (sent.append(e.png), send())
        counts = []
        for value in (0.3, 0.02, 0.6):       # key presses, each after the figure has settled
            before = len(sent)
            e.controls["Ts"].value = value
            await asyncio.sleep(limits.SETTLE_S + 0.2)
            counts.append(len(set(sent[before:])))
        return counts, e

    counts, e = asyncio.run(steps())
    assert counts == [1, 1, 1]               # one frame per step: no second one to fit the limits
    ax = e.handles["ax_err"]
    data, view = np.log10(ax.dataLim.intervaly), np.log10(ax.get_ylim())
    assert np.ptp(data) >= np.ptp(view) / 2  # and that frame's limits are fitted (half filled at least)


def test_rescale_stops_at_sticky_edges_keeps_a_minimum_span_and_works_on_log_axes():
    ax = Figure().subplots()
    line, = ax.plot(np.linspace(0, 5, 11), np.full(11, 3.0))
    line.sticky_edges.x.append(0.0)
    rescale(ax, axis="both", min_span=2.0)
    assert ax.get_xlim() == pytest.approx((0.0, 6.0))        # no room before t = 0
    assert ax.get_ylim() == pytest.approx((1.46, 4.54))      # a flat line is drawn flat
    log = Figure().subplots()
    log.semilogy([0, 1, 2], [1e-3, 2e-2, 10.0])
    rescale(log)
    lo, hi = log.get_ylim()
    assert np.log10(hi) - np.log10(lo) == pytest.approx(5 * 1.1)   # decades -3.5 to 1.5, and 5 %
    with pytest.raises(ValueError, match="axis must be"):
        rescale(ax, axis="z")


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


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_resize_changes_the_resolution_and_not_what_the_figure_shows(factory):
    e = factory()
    _shown(e, width=1500, height=900, ratio=1)
    before = [(ax.get_xlim(), ax.get_ylim()) for ax in e.fig.axes], _size(e.png)
    for width in (650, 1500):
        _shown(e, width=width, height=900, ratio=1)
    assert ([(ax.get_xlim(), ax.get_ylim()) for ax in e.fig.axes], _size(e.png)) == before


def test_sliders_follow_the_hand():
    e = ch3.pole_placement_explorer()
    assert all(w.continuous_update for w in _sliders(e).values())


def test_encode_png_drops_alpha_only_when_every_pixel_is_opaque():
    rgba = np.full((6, 5, 4), 255, dtype=np.uint8)
    rgba[2, 3] = [10, 20, 30, 255]
    opaque = _pixels(encode_png(rgba, 100))
    assert opaque.shape == (6, 5, 3)
    np.testing.assert_array_equal(np.round(opaque * 255), rgba[..., :3])
    rgba[0, 0, 3] = 0
    see_through = _pixels(encode_png(rgba, 100))
    assert see_through.shape == (6, 5, 4) and see_through[0, 0, 3] == 0


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_slider_starts_on_one_of_its_steps(factory):
    # a browser's slider moves a value between steps to the nearest step, so an explorer would
    # show other settings than its defaults as soon as it is displayed
    for name, w in _sliders(factory()).items():
        steps = (w.value - w.min) / w.step
        assert abs(steps - round(steps)) < 1e-6, (
            f"{factory.__name__}: slider {name} starts at {w.value}, between the steps "
            f"{w.min} + k * {w.step}")


def _limits(e) -> list:
    return [(ax.get_xlim(), ax.get_ylim()) for ax in e.fig.axes]


def _fresh_limits(factory, name: str, value) -> list:
    """Every axes' limits of a fresh explorer after one move of `name` to `value`."""
    e = factory()
    e.controls[name].value = value           # no event loop here: drawn at rest
    return _limits(e)


def _drag_in_a_kernel(factory, name: str, values, steps=()) -> tuple:
    """A fresh explorer shown where an event loop runs (as in a kernel): control `name` dragged
    through `values` (moves a few milliseconds apart), then set to each of `steps` after the
    figure rested (key steps). Returns the explorer and, after the drag and after each step,
    every axes' limits and the time its result ends at."""
    import asyncio

    async def run():
        e = factory()
        e.widget
        seen = []
        for value in values:
            e.controls[name].value = value
            await asyncio.sleep(0.005)
        for value in (None, *steps):
            if value is not None:
                e.controls[name].value = value
            await asyncio.sleep(limits.SETTLE_S + 0.2)
            seen.append((_limits(e), e.result["t"][-1] if "t" in e.result else None))
        return e, seen

    return asyncio.run(run())


def test_the_planner_s_time_axis_ends_with_its_data_after_a_drag_and_after_key_steps():
    """Issue 32: a drag of T to 8.6 s left the time axis at ~23 s with data to 17.2 s, and key
    steps after it kept it there. At rest it is [0, time_shown(T)] (2 T to 3 T), as in a fresh
    explorer."""
    drag = [round(v, 1) for v in np.arange(3.0, 8.65, 0.1)]
    e, seen = _drag_in_a_kernel(ch2.planner_explorer, "T", drag, steps=(8.5, 8.4))
    for (shown, end), T in zip(seen, (8.6, 8.5, 8.4)):
        assert end == pytest.approx(ch2.time_shown(T))
        assert shown[1][0] == pytest.approx((0.0, end)), (T, shown[1][0])     # the time axis
        assert shown == _fresh_limits(ch2.planner_explorer, "T", T), T       # and every limit



@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_after_a_drag_out_and_back_every_limit_is_that_of_a_fresh_explorer(factory):
    """The limits at rest depend on the settings alone: a drag to the slider's top and back
    down to its bottom ends on the limits a fresh explorer shows after one move there."""
    e = factory()
    name, widget = next(iter(_sliders(e).items()))
    values = _drag_values(widget, moves=10)
    _, seen = _drag_in_a_kernel(factory, name, values)
    assert seen[0][0] == _fresh_limits(factory, name, values[-1])


def test_a_drag_whose_frames_take_longer_than_the_settling_time_is_still_drawn_as_a_drag():
    """On a busy machine a frame can take longer than SETTLE_S: the next move, coming right after
    it, belongs to the same drag (drawn while `moving`), not a single step fitted at rest."""
    import asyncio
    import time

    from coursekit.explorers import Explorer, slider
    states = []

    def update(h, r):
        states.append(limits.is_moving())
        time.sleep(limits.SETTLE_S * 1.3)           # a slow frame
        h.set_data([0, 1], [0, r])
        rescale(h.axes)

    async def drag():
        e = Explorer(title="slow", controls=dict(a=slider(1.0, 0.0, 5.0, 0.5, "a [1]")),
                     compute=lambda a: a, draw=lambda fig: fig.subplots().plot([], [])[0], update=update)
        e.widget
        states.clear()
        for value in (1.5, 2.0, 2.5, 3.0):
            e.controls["a"].value = value
            await asyncio.sleep(0.005)
        await asyncio.sleep(limits.SETTLE_S * 1.5)

    asyncio.run(drag())
    assert states[:4] == [False, True, True, True]     # a first step, then the drag


def test_scope_range_takes_its_ends_from_the_1_2_5_series_and_moves_three_times_a_decade():
    ax = Figure().subplots()
    edge = limits.Y_EDGE
    ch2._scope_range(ax, [0.0, 0.3, 83.1, -1.35])          # 1.05 x 83.1 -> 100; below 0 a tenth
    assert ax.get_ylim() == pytest.approx((-10 - edge * 110, 100 + edge * 110))
    ch2._scope_range(ax, [0.0, 83.1, -12.0])               # -12.6 -> -20
    assert ax.get_ylim() == pytest.approx((-20 - edge * 120, 100 + edge * 120))
    ch2._scope_range(ax, [0.0, 1.0, 0.5])                  # 1.05 -> 2; nothing below 0: a tenth
    assert ax.get_ylim() == pytest.approx((-0.2 - edge * 2.2, 2 + edge * 2.2))
    ch2._scope_range(ax, [-3.0, -0.01])                    # all below 0: the top a tenth of 5
    assert ax.get_ylim() == pytest.approx((-5 - edge * 5.5, 0.5 + edge * 5.5))
    ends = []
    for peak in np.geomspace(1.0, 1000.0, 61):               # three decades in steps of 12 %
        ch2._scope_range(ax, [0.0, peak])
        ends.append(ax.get_ylim())
    assert sum(a != b for a, b in zip(ends, ends[1:])) == 9
    kept = ax.get_ylim()
    ch2._scope_range(ax, [np.nan, np.inf])                 # nothing finite: kept
    assert ax.get_ylim() == kept
    ch2._scope_range(ax, [0.0, 0.0])                       # all zero: -1 to 1
    assert ax.get_ylim() == pytest.approx((-1 - edge * 2, 1 + edge * 2))
    with limits.moving():                                    # a hand moves: rescale's growing limits
        line, = ax.plot([0, 1], [0, 0.5])
        ch2._scope_range(ax, [0.0, 0.5])
        assert ax.get_ylim() == pytest.approx((-1 - edge * 2, 1 + edge * 2))


def test_a_key_step_of_the_robot_planner_s_target_rarely_moves_its_input_axis():
    """Its turn rate spans 0.5 to 83 rad/s over x_T's 25 values: the limits moved at 18 steps of 24
    (a full draw each), they move at 5 now, and at rest they are a fresh explorer's."""
    e = ch2.robot_planner_explorer()
    seen = []
    for x in np.arange(-6.0, 6.01, 0.5):
        e.controls["x_T"].value = float(x)
        seen.append(e.handles["ax_u"].get_ylim())
    assert sum(a != b for a, b in zip(seen, seen[1:])) <= 6
    assert seen[-1] == _fresh_limits(ch2.robot_planner_explorer, "x_T", 6.0)[1][1]
