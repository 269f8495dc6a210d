"""fit_margins (constrained layout with the course's pads) and the layout checker of the tests."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine  # noqa: E402

import coursekit as ck  # noqa: E402
from layout_check import drawn_strings, legend_problems, text_problems  # noqa: E402


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


def test_a_title_wider_than_the_figure_wraps_inside_it():
    fig, ax = ck.new_figure(figsize=(4, 3))
    ax.set_title("a title far wider than this small figure can hold on one line " * 2)
    fig.suptitle("a suptitle far wider than this small figure can hold on one line " * 2)
    assert text_problems(fig) == []


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


MATH_TITLE = (r"closed loop $\dot x = (A - B K)\, x$ with $K = [k_1 \quad k_2]$ "
              r"from $x_0 = [1 \quad 0]^T$ for two gains")


@pytest.mark.parametrize("lecture", [False, True], ids=["font size 18", "lecture mode"])
def test_a_wrapped_title_with_mathtext_breaks_only_outside_the_math(lecture):
    if lecture:
        ck.lecture_mode()
    try:
        with matplotlib.rc_context({} if lecture else {"font.size": 18}):
            fig, ax = ck.new_figure(figsize=(6, 4.5))
            ax.plot(np.linspace(0, 10, 50), np.sin(np.linspace(0, 10, 50)))
            ax.set_title(MATH_TITLE)
            fig.suptitle(MATH_TITLE)
            drawn = drawn_strings(fig)
            problems = text_problems(fig)
    finally:
        ck.lecture_mode(False)
    titles = [s for s, _ in drawn if "gains" in s or "closed" in s]
    assert len(titles) >= 4, drawn                 # both titles wrapped onto several lines
    assert not [s for s, math in drawn if "$" in s and not math], drawn
    assert problems == []


@pytest.mark.parametrize("line, words", [
    ("gain $k = 2$ and $x_0 = [1\\ 0]$ now", ["gain", "$k = 2$", "and", "$x_0 = [1\\ 0]$", "now"]),
    (r"costs \$5 or \$6 a day", [r"costs", r"\$5", "or", r"\$6", "a", "day"]),
    ("one $ sign only", ["one", "$", "sign", "only"]),
])
def test_titles_break_only_at_spaces_outside_formulas(line, words):
    from coursekit.layout import _words_outside_math
    assert _words_outside_math(line) == words


def _greedy_lines(words, width, measure):
    """The reference fill: add words one at a time while the line still fits."""
    lines, line = [], words[0]
    for word in words[1:]:
        if measure(f"{line} {word}") > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}"
    return lines + [line]


_WORDS = ["a", "gain", "$k_1 = 2.35$", "poles", "at", "$-3 \\pm 4j$", "W", "observer", "-12.5",
          "iii", "$\\omega_n = 10$ rad/s", "MMMM", "noise", "$R = 0.01$"]


@pytest.mark.parametrize("size", [10, 18])
def test_titles_fill_their_lines_as_adding_words_one_at_a_time_would(size):
    from hypothesis import given, settings, strategies as st

    from coursekit.layout import _words_that_fit
    fig = Figure(figsize=(6, 4))
    text = fig.text(0.5, 0.5, "x", fontsize=size)
    FigureCanvasAgg(fig).draw()      # gives the text its renderer, which measures
    measure = text._get_rendered_text_width

    @settings(max_examples=150, deadline=None)
    @given(st.lists(st.sampled_from(_WORDS), min_size=1, max_size=25), st.floats(5, 700))
    def fill(words, width):
        lines, rest = [], list(words)
        while rest:
            count = _words_that_fit(rest, width, measure)
            lines.append(" ".join(rest[:count]))
            rest = rest[count:]
        assert lines == _greedy_lines(words, width, measure)

    fill()


@pytest.mark.parametrize("measure", [
    lambda s: 7 * len(s) + 10 * s.count(" ") ** 2,        # a line wider than its words and spaces
    lambda s: 7 * len(s) - 3 * s.count(" "),             # narrower (kerning, a thin space)
], ids=["lines wider than their words", "lines narrower than their words"])
def test_the_fill_corrects_its_guess_from_the_single_words(measure):
    from coursekit.layout import _words_that_fit
    words = "the observer poles at -3.5 and -4 with measurement noise 0.01 and a long tail".split()
    for width in range(1, 700, 7):
        lines, rest = [], list(words)
        while rest:
            count = _words_that_fit(rest, width, measure)
            lines.append(" ".join(rest[:count]))
            rest = rest[count:]
        assert lines == _greedy_lines(words, width, measure), width
