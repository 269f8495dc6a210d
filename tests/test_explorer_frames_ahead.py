"""Frames ahead of the hand: the kernel's side of the browser's requests for the frames of
slider positions next to the current settings (`Explorer.frame_for`, `Explorer._on_view_msg`).

A frame asked for ahead must be the frame the explorer shows when the slider gets there (pixel
for pixel, like a fresh draw), must leave the controls and the figure shown alone, and a request
that does not fit the controls must be refused, never raise in the kernel."""

import io
import math

import numpy as np
import pytest

from coursekit.explorers import ch1, ch2, ch3, ch4
from coursekit.explorers._base import requested_params, settings_now

FACTORIES = [ch1.euler_explorer, ch1.msd_explorer, ch2.planner_explorer, ch3.pole_placement_explorer,
             ch3.upright_pendulum_explorer, ch3.integral_action_explorer, ch4.observer_noise_explorer,
             ch4.kalman_tuning_explorer]


def _pixels(png: bytes) -> np.ndarray:
    from matplotlib.image import imread
    return imread(io.BytesIO(png), format="png")


class _Replies:
    """Stands in for the view's comm: keeps what the explorer sends to the browser."""

    def __init__(self, explorer):
        self.view = explorer.widget.children[-1]
        self.sent = []
        self.view.send = lambda content, buffers=None: self.sent.append((content, buffers))

    def ask(self, explorer, values, generation=None):
        generation = self.view.generation if generation is None else generation
        explorer._on_view_msg(self.view, {"type": "frame", "values": values, "generation": generation,
                                          "view": "v1"}, [])
        return self.sent.pop()


def _sliders(explorer):
    return [name for name, w in explorer.controls.items() if hasattr(w, "step") and hasattr(w, "max")]


def _step_up(widget):
    """The slider's next position up (down at the top of the range), as the browser computes it."""
    value = widget.value + widget.step if widget.value + widget.step <= widget.max else widget.value - widget.step
    return float(f"{value:.12g}") if isinstance(widget.value, float) else int(value)


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_frame_asked_for_ahead_is_the_frame_shown_when_the_slider_gets_there(factory):
    explorer = factory()
    replies = _Replies(explorer)
    shown_png, shown_params, shown_view = explorer.png, explorer.params, replies.view.png
    for name in _sliders(explorer):
        values = {**settings_now(explorer.controls)[0], name: _step_up(explorer.controls[name])}
        content, buffers = replies.ask(explorer, values)
        assert content == {"type": "frame", "values": values, "generation": replies.view.generation,
                           "view": "v1"}
        fresh = factory()
        fresh.controls[name].value = values[name]
        fresh.refresh()
        np.testing.assert_array_equal(_pixels(buffers[0]), _pixels(fresh.png), err_msg=name)
        # nothing shown changed, and the figure is back at the settings shown
        assert (explorer.params, explorer.png, replies.view.png) == (shown_params, shown_png, shown_view)
        np.testing.assert_array_equal(_pixels(explorer.frames.frame()), _pixels(shown_png))
    explorer.controls[name].value = values[name]      # the hand gets there: no new draw
    draws = explorer.frames.full_draws + explorer.frames.blits
    explorer.refresh()
    assert explorer.frames.full_draws + explorer.frames.blits == draws
    assert explorer.png == buffers[0]


def test_the_robot_planners_frame_ahead_holds_the_path_of_its_settings():
    # its equal-aspect axes settle over draws (see test_explorer_frames), so its data, not pixels
    explorer = ch2.robot_planner_explorer()
    replies = _Replies(explorer)
    values = {**settings_now(explorer.controls)[0], "x_T": 4.5}
    content, buffers = replies.ask(explorer, values)
    assert content["type"] == "frame" and buffers[0].startswith(b"\x89PNG")
    fresh = ch2.robot_planner_explorer()
    fresh.controls["x_T"].value = 4.5
    fresh.refresh()
    explorer.controls["x_T"].value = 4.5
    explorer.refresh()
    assert explorer.png == buffers[0]
    for a, b in zip(explorer.fig.axes, fresh.fig.axes):
        for la, lb in zip(a.get_lines(), b.get_lines()):
            np.testing.assert_array_equal(la.get_xydata(), lb.get_xydata())


def test_a_value_the_slider_reaches_by_another_rounding_finds_the_frame_asked_for():
    explorer = ch1.msd_explorer()
    replies = _Replies(explorer)
    values = {**settings_now(explorer.controls)[0], "d": 0.1 + 0.2}      # 0.30000000000000004
    assert replies.ask(explorer, values)[0]["type"] == "frame"
    draws = explorer.frames.full_draws + explorer.frames.blits
    explorer.controls["d"].value = 0.3
    assert explorer.frames.full_draws + explorer.frames.blits == draws


def _bad_requests(explorer):
    values = settings_now(explorer.controls)[0]
    return {
        "a control missing": {k: v for k, v in values.items() if k != "m"},
        "an unknown control": {**values, "mass": 1.0},
        "not a number": {**values, "m": "2"},
        "a bool": {**values, "m": True},
        "NaN": {**values, "m": math.nan},
        "above the range": {**values, "m": 5.2},
        "below the range": {**values, "k": 0.0},
        "another choice than the one shown": {**values, "experiment": 1 - values["experiment"]},
        "not a dict": [1.0, 0.5, 2.0],
    }


@pytest.mark.parametrize("case", list(_bad_requests(ch1.msd_explorer())))
def test_a_request_that_does_not_fit_the_controls_is_refused(case):
    explorer = ch1.msd_explorer()
    replies = _Replies(explorer)
    values = _bad_requests(explorer)[case]
    assert requested_params(explorer.controls, values) is None
    content, buffers = replies.ask(explorer, values)
    assert content["type"] == "no-frame" and not buffers
    assert len(explorer._cache) == 1


def test_a_request_for_an_old_resolution_is_refused_and_a_new_resolution_raises_the_generation():
    explorer = ch1.msd_explorer()
    replies = _Replies(explorer)
    before = replies.view.generation
    replies.view.screen = {"width": 400, "height": 300, "ratio": 2.0}
    assert replies.view.generation == before + 1
    values = {**settings_now(explorer.controls)[0], "m": 1.1}
    assert replies.ask(explorer, values, generation=before)[0]["type"] == "no-frame"
    assert replies.ask(explorer, values)[0]["type"] == "frame"


def test_an_int_slider_takes_whole_numbers_only():
    explorer = ch2.planner_explorer()
    replies = _Replies(explorer)
    values = settings_now(explorer.controls)[0]
    assert replies.ask(explorer, {**values, "r": 2.5})[0]["type"] == "no-frame"
    content, buffers = replies.ask(explorer, {**values, "r": 3.0})
    assert content["type"] == "frame"
    assert requested_params(explorer.controls, {**values, "r": 3.0})["r"] == 3
    assert isinstance(requested_params(explorer.controls, {**values, "r": 3.0})["r"], int)


@pytest.mark.parametrize("fails_in", ["compute", "update"])
def test_settings_that_cannot_be_computed_or_drawn_are_refused_and_the_figure_stays(fails_in):
    explorer = ch1.msd_explorer()
    replies = _Replies(explorer)
    shown = explorer.png
    compute, update = explorer._compute, explorer._update

    def failing_compute(**params):
        if params["m"] != 1.0:
            raise ValueError("m: no solution for this mass")
        return compute(**params)

    def failing_update(handles, result):
        update(handles, result)              # halfway: some artists already moved
        if result is not explorer.result:
            raise ValueError("cannot draw these settings")

    if fails_in == "compute":
        explorer._compute = failing_compute
    else:
        explorer._update = failing_update
    content, buffers = replies.ask(explorer, {**settings_now(explorer.controls)[0], "m": 1.1})
    assert content["type"] == "no-frame" and not buffers
    assert explorer.png == shown
    np.testing.assert_array_equal(_pixels(explorer.frames.frame()), _pixels(shown))


def test_messages_that_are_not_requests_are_ignored():
    explorer = ch1.msd_explorer()
    replies = _Replies(explorer)
    for content in ({"type": "hello"}, "frame", None, {"values": {}}):
        explorer._on_view_msg(replies.view, content, [])
    assert replies.sent == []


def test_the_view_knows_the_controls_and_the_settings_of_its_frame():
    explorer = ch1.msd_explorer()
    view = explorer.widget.children[-1]
    assert view.controls == explorer.controls
    assert view.values == {"m": 1.0, "d": 0.5, "k": 2.0, "experiment": 0}
    explorer.controls["experiment"].value = "initial"
    assert view.values["experiment"] == 1
    explorer.controls["m"].value = 2.0
    assert view.values["m"] == 2.0


def test_frames_ahead_can_be_switched_off_for_the_explorers_built_after():
    from coursekit.explorers import Explorer
    assert ch1.msd_explorer().widget.children[-1].ahead is True
    Explorer.frames_ahead = False
    try:
        assert ch1.msd_explorer().widget.children[-1].ahead is False
    finally:
        Explorer.frames_ahead = True
