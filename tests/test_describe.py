"""describe_figure: the words a screen reader says for a figure, computed from its data."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import coursekit as ck


def test_a_curve_is_told_by_its_start_extremes_and_end():
    fig, ax = ck.new_figure()
    t = np.linspace(0, 4, 401)
    ax.plot(t, 1 - np.exp(-t) * np.cos(3 * t), label="x1")
    ax.axhline(1.0, color="0.5")                         # a reference line: not data
    ax.set(xlabel="time t [s]", ylabel="position [m]", title="step response")
    fig.suptitle("A damped oscillator")
    text = ck.describe_figure(fig)
    peak = int(np.argmax(1 - np.exp(-t) * np.cos(3 * t)))
    assert text.startswith("A damped oscillator. The plot (step response) shows position [m] against time t [s]")
    assert f"highest {1 - np.exp(-t[peak]) * np.cos(3 * t[peak]):.3g} at time t [s] = {t[peak]:.3g}" in text
    assert "x1: starts at 0," in text and "constant" not in text


def test_points_log_axes_and_shared_time_axes():
    fig = Figure()
    top, bottom = fig.subplots(2, 1, sharex=True)
    top.plot([-1, -2], [1, -1], "x", label="poles")
    bottom.semilogy([0, 1, 2], [1, 0.1, 0.01], label="error")
    bottom.set_xlabel("time t [s]")
    text = ck.describe_figure(fig)
    assert "Plot 1 of 2 shows y against time t [s]" in text        # the label of the shared axis
    assert "poles: points at (−1, 1), (−2, −1)." in text
    assert "on a logarithmic scale" in text and "error: starts at 1, highest 1" in text


def test_an_empty_figure_and_a_wrong_argument():
    assert ck.describe_figure(Figure()) == "An empty figure."
    with pytest.raises(ValueError, match="fig must be a matplotlib Figure"):
        ck.describe_figure(Figure().subplots())
