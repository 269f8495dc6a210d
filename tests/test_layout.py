"""fit_margins (constrained layout with the course's pads) and the layout checker of the tests."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine  # noqa: E402

import coursekit as ck  # noqa: E402
from layout_check import legend_problems, text_problems  # noqa: E402


def _crowded(fit: bool):
    """A 2 x 2 grid with big labels, long tick labels, a suptitle, a colorbar and titles."""
    fig = Figure(figsize=(6, 4))
    if fit:
        ck.fit_margins(fig)
    axes = fig.subplots(2, 2)
    t = np.linspace(0, 10, 50)
    for ax in axes.flat:
        ax.plot(t, 13439.16 * t, label="balance")
        ax.set(xlabel="time t [s]", ylabel="balance [DKK]", title="a title")
        ax.xaxis.label.set_size(16)
        ax.yaxis.label.set_size(16)
    image = axes[1, 1].imshow(np.eye(3))
    fig.colorbar(image, ax=axes[1, 1], label="value")
    fig.suptitle("A suptitle over the grid", fontsize=20)
    return fig


def test_the_checker_flags_text_outside_and_overlapping_without_layout():
    problems = text_problems(_crowded(fit=False))
    assert any(p.startswith("outside the figure") for p in problems), problems
    assert any(p.startswith("overlap") for p in problems), problems


def test_fit_margins_lays_the_same_figure_out_without_problems():
    assert text_problems(_crowded(fit=True)) == []


def test_the_checker_flags_two_titles_running_into_each_other():
    fig = Figure(figsize=(6, 3), layout="constrained")    # matplotlib's, which does not wrap titles
    for ax in fig.subplots(1, 2):
        ax.set_title("a title much wider than its own axes")
    problems = text_problems(fig)
    assert any("overlap" in p and "title much wider" in p for p in problems), problems


def test_the_checker_flags_crowded_tick_labels_of_one_axis():
    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.set_xticks(np.arange(10), [f"label {k}" for k in range(10)])
    assert any(p.startswith("overlap") for p in text_problems(fig))


def test_the_checker_flags_a_legend_that_hides_a_curve():
    fig = ck.fit_margins(Figure(figsize=(4, 3)))
    ax = fig.subplots()
    ax.plot(np.linspace(0, 1, 100), np.full(100, 0.5), label="a long legend entry over the line")
    ax.set_ylim(0, 1)
    ax.legend(loc="center")
    text_problems(fig)
    assert legend_problems(fig, covered=0.2)


def test_fit_margins_sets_constrained_layout_and_returns_the_figure():
    fig = Figure()
    assert ck.fit_margins(fig) is fig
    engine = fig.get_layout_engine()
    assert isinstance(engine, ConstrainedLayoutEngine)
    assert engine.get()["w_pad"] == pytest.approx(4 / 72)
    ck.fit_margins(fig)
    assert fig.get_layout_engine() is engine


def test_new_figure_and_explorers_use_it():
    from coursekit.explorers import ch1
    assert isinstance(ck.new_figure()[0].get_layout_engine(), ConstrainedLayoutEngine)
    assert isinstance(ch1.euler_explorer().fig.get_layout_engine(), ConstrainedLayoutEngine)


def test_a_layout_engine_set_on_the_figure_is_kept():
    fig = Figure(layout="tight")
    ck.fit_margins(fig)
    assert isinstance(fig.get_layout_engine(), TightLayoutEngine)


def test_colorbars_added_after_fit_margins_are_laid_out():
    fig, axes = ck.new_figure(1, 2, figsize=(8, 3))
    for ax in axes:
        fig.colorbar(ax.imshow(np.eye(3) * 1000), ax=ax, label="value [units]")
        ax.set(title="image", xlabel="x", ylabel="y")
    assert text_problems(fig) == []


def test_a_colorbar_split_cell_before_fit_margins_is_refused_with_the_remedy():
    fig = Figure()
    ax = fig.subplots()
    fig.colorbar(ax.imshow(np.eye(3)), ax=ax)
    with pytest.raises(ValueError, match="call ck.fit_margins\\(fig\\) first"):
        ck.fit_margins(fig)


def test_lecture_mode_figures_are_laid_out_too():
    ck.lecture_mode()
    try:
        fig = _crowded(fit=True)
        assert text_problems(fig) == []
    finally:
        ck.lecture_mode(False)
