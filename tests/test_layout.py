"""fit_margins: every label inside the figure, no two axes' labels overlapping,
and not much more margin than matplotlib's measuring constrained layout."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import coursekit as ck  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402


def _draw(fig):
    """Draw with Agg (figures from coursekit are built outside pyplot); return the renderer."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _response(title="Mass-spring-damper (1.3): step in the force"):
    sys = ck.models.mass_spring_damper(m=1.0, d=0.5, k=2.0)
    t = np.linspace(0, 40, 401)
    return ck.simulate(sys, t, u=np.ones((t.size, 1))).plot(
        state_names=["position y", "velocity y'"], state_units=["m", "m/s"],
        input_names=["force u"], input_units="N", title=title)


def _grid_with_wide_labels():
    fig, axes = plt.subplots(2, 2, figsize=(9, 6), sharey="row")
    t = np.linspace(0, 10, 50)
    axes[0, 0].plot(t, 13439.16 * t)
    axes[0, 0].set(ylabel="balance [DKK]", title="two\nlines")
    axes[0, 1].semilogy(t, 1e-10 + t**4)
    axes[1, 0].plot(t, -1e-5 * t)                 # an offset/exponent text above the axis
    axes[1, 0].set(xlabel="time t [s]", ylabel="tiny\n[m]")
    axes[1, 1].plot(t, np.sin(t))
    axes[1, 1].set(xlabel="time t [s]", title="right column")
    fig.suptitle("A suptitle over a 2 x 2 grid")
    return ck.fit_margins(fig)


def _state_plane():
    x = np.column_stack([np.cos(np.linspace(0, 6, 100)), np.sin(np.linspace(0, 6, 100))])
    return ck.plot_state_plane(x, labels=["circle"], title="State plane")


def _explorer():
    from coursekit.explorers import ch3
    return ch3.pole_placement_explorer().fig


FIGURES = {"response": _response, "grid": _grid_with_wide_labels, "state plane": _state_plane,
           "explorer": _explorer}


_IMAGE = np.random.default_rng(0).normal(size=(20, 20)) * 1000   # tick labels like -3000


def _image_pair(title):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax in axes:
        ax.set(title=title, xlabel="x", ylabel="y")
    return fig, axes, [ax.imshow(_IMAGE) for ax in axes]


def _colorbar_per_axes():
    """fig.colorbar(im, ax=ax) splits each axes' grid cell between the axes and its colorbar."""
    fig, axes, images = _image_pair("colorbar per axes")
    for ax, im in zip(axes, images):
        fig.colorbar(im, ax=ax, label="value [units]")
    return ck.fit_margins(fig)


def _colorbar_below():
    fig, axes = plt.subplots(2, 1, figsize=(6, 6))
    for ax in axes:
        im = ax.pcolormesh(_IMAGE)
        ax.set(title="colorbar under row 2", ylabel="y")
    # the gap inside the split cell is the colorbar's own pad (a fraction of the axes' height);
    # 0.3 leaves room for the second axes' tick labels in lecture mode as well
    fig.colorbar(im, ax=axes[1], orientation="horizontal", label="value", pad=0.3)
    return ck.fit_margins(fig)


def _colorbar_shared():
    """fig.colorbar(im, ax=[...]) shrinks its axes by hand, outside any grid."""
    fig, axes, images = _image_pair("one colorbar for both")
    fig.colorbar(images[-1], ax=axes, label="value")
    return ck.fit_margins(fig)


COLORBAR_FIGURES = {"colorbar per axes": _colorbar_per_axes, "colorbar below": _colorbar_below}


def _drawn_tick_labels(axis, coord):
    """Tick labels inside the view (matplotlib keeps, but does not draw, the others)."""
    lo, hi = sorted(axis.get_view_interval())
    return [t for t in axis.get_ticklabels() if lo <= t.get_position()[coord] <= hi]


def _text_boxes(fig, renderer):
    """Window extents of every visible tick label, axis label, title and suptitle."""
    boxes = []
    for ax in fig.axes:
        texts = [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label,
                 ax.yaxis.get_offset_text(), *_drawn_tick_labels(ax.xaxis, 0), *_drawn_tick_labels(ax.yaxis, 1)]
        boxes += [(ax, t.get_window_extent(renderer)) for t in texts if t.get_visible() and t.get_text()]
        if ax.get_legend() is not None:
            boxes.append((ax, ax.get_legend().get_window_extent(renderer)))
    boxes += [(None, t.get_window_extent(renderer)) for t in fig.texts if t.get_text()]
    return boxes


@pytest.mark.parametrize("lecture", [False, True], ids=["default fonts", "lecture mode"])
@pytest.mark.parametrize("name", {**FIGURES, **COLORBAR_FIGURES})
def test_every_label_fits_inside_the_figure_without_overlapping_another_axes(name, lecture):
    ck.lecture_mode(lecture)
    try:
        fig = {**FIGURES, **COLORBAR_FIGURES}[name]()
        renderer = _draw(fig)
        width, height = fig.canvas.get_width_height()
        for owner, box in _text_boxes(fig, renderer):
            assert box.x0 >= -0.5 and box.y0 >= -0.5, f"{name}: text sticks out left/below: {box}"
            assert box.x1 <= width + 0.5 and box.y1 <= height + 0.5, f"{name}: text sticks out right/above: {box}"
            for ax in fig.axes:
                if owner is not None and ax is not owner:
                    inside = ax.get_window_extent(renderer)
                    assert not box.overlaps(inside), f"{name}: a label of one axes overlaps another axes"
            for other, other_box in _text_boxes(fig, renderer):
                if owner is not None and other is not None and other is not owner:
                    assert not box.overlaps(other_box), f"{name}: labels of two axes overlap: {box}, {other_box}"
    finally:
        ck.lecture_mode(False)
        plt.close("all")


@pytest.mark.parametrize("name", FIGURES)
def test_margins_are_close_to_what_constrained_layout_measures(name):
    fig = FIGURES[name]()
    _draw(fig)
    ours = sum(ax.get_position().width * ax.get_position().height for ax in fig.axes)
    fig.set_layout_engine("constrained")
    _draw(fig)
    measured = sum(ax.get_position().width * ax.get_position().height for ax in fig.axes)
    plt.close("all")
    assert ours >= 0.85 * measured, f"{name}: estimated margins waste space ({ours:.3f} vs {measured:.3f})"


def test_layout_adapts_when_a_title_is_added_after_the_figure_is_built():
    fig = _state_plane()
    fig.axes[0].set_title("")
    _draw(fig)
    top_before = fig.subplotpars.top
    fig.axes[0].set_title("a title\nover two lines")
    _draw(fig)
    assert fig.subplotpars.top < top_before - 0.05
    plt.close("all")


def test_a_suptitle_wider_than_the_figure_is_wrapped_and_given_room():
    fig = _response(title="A very long suptitle " * 6)
    renderer = _draw(fig)
    width, height = fig.canvas.get_width_height()
    box = fig.texts[0].get_window_extent(renderer)
    assert box.x0 >= 0 and box.x1 <= width and box.y1 <= height
    top_axes = max(ax.get_window_extent(renderer).y1 for ax in fig.axes)
    assert box.y0 > top_axes
    plt.close("all")


def test_fit_margins_lays_the_figure_out_in_the_one_draw_that_renders_it(monkeypatch):
    # a matplotlib layout engine would make savefig (and the inline backend) draw twice
    import io
    from coursekit import layout
    calls = []
    monkeypatch.setattr(layout, "_apply", lambda fig: calls.append(fig))
    fig = _grid_with_wide_labels()
    assert fig.get_layout_engine() is None
    fig.savefig(io.BytesIO(), format="png")
    assert calls == [fig]
    plt.close("all")


def test_fit_margins_twice_adds_one_hook_that_tight_bounding_boxes_ignore():
    fig = _grid_with_wide_labels()
    ck.fit_margins(fig)
    assert len(fig.artists) == 1
    assert fig.artists[0] not in fig.get_default_bbox_extra_artists()
    renderer = _draw(fig)
    tight = fig.get_tightbbox(renderer)
    assert tight.x0 > 0 and tight.y0 > 0, "the invisible hook must not pull the tight box to (0, 0)"
    plt.close("all")


@pytest.mark.filterwarnings("error")  # subplots_adjust on a constrained figure only warns
def test_a_layout_engine_set_on_the_figure_takes_precedence():
    fig = _grid_with_wide_labels()
    fig.set_layout_engine("constrained")
    _draw(fig)
    ours = [ax.get_position().bounds for ax in fig.axes]
    reference = _grid_with_wide_labels()
    reference.artists[0].remove()
    reference.set_layout_engine("constrained")
    _draw(reference)
    assert np.allclose(ours, [ax.get_position().bounds for ax in reference.axes])
    plt.close("all")


def test_a_colorbar_that_splits_a_cell_keeps_the_axes_in_that_cell_and_is_laid_out_with_them():
    fig = _colorbar_per_axes()
    renderer = _draw(fig)
    images, colorbars = fig.axes[:2], fig.axes[2:]          # colorbars are added after the grid
    for image, colorbar in zip(images, colorbars):
        cell = image.get_subplotspec().get_topmost_subplotspec().get_position(fig)
        for ax in (image, colorbar):
            assert cell.x0 - 1e-9 <= ax.get_position().x0 and ax.get_position().x1 <= cell.x1 + 1e-9
    # the first colorbar's label ends left of the second axes' tick labels
    label_end = colorbars[0].yaxis.label.get_window_extent(renderer).x1
    tick_start = min(t.get_window_extent(renderer).x0 for t in _drawn_tick_labels(images[1].yaxis, 1))
    assert label_end < tick_start
    plt.close("all")


@pytest.mark.parametrize("lecture", [False, True], ids=["default fonts", "lecture mode"])
def test_axes_moved_by_hand_keep_their_place(lecture):
    ck.lecture_mode(lecture)
    try:
        fig = _colorbar_shared()
        images, colorbar = fig.axes[:2], fig.axes[2]
        _draw(fig)
        renderer = fig.canvas.get_renderer()
        bar = colorbar.get_window_extent(renderer)
        for ax in images:
            assert not ax.get_window_extent(renderer).overlaps(bar)
        if not lecture:          # in lecture mode constrained layout places all three
            placed = [ax.get_position(original=True).bounds for ax in fig.axes]
            assert placed == [ax.get_position(original=True).bounds for ax in _colorbar_shared().axes]
    finally:
        ck.lecture_mode(False)
        plt.close("all")
