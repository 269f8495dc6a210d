"""Chapter 4 explorers: observer speed vs noise, Kalman Q/R tuning."""

import numpy as np
import pytest

import coursekit as ck
from coursekit.explorers.ch4 import (KALMAN_TRUE_Q, KALMAN_TRUE_R, kalman_tuning_compute,
                                     kalman_tuning_explorer, observer_noise_compute,
                                     observer_noise_explorer)


def test_observer_noise_places_the_poles():
    r = observer_noise_compute(3.0, 0.05)
    np.testing.assert_allclose(np.sort(r["poles"].real), [-3, -3], atol=1e-6)
    # vehicle m = d = 1: a = [0, 1], p = (s + 3)^2 = s^2 + 6 s + 9 -> OCF gains [9, 5], L = V L~
    sys = ck.models.vehicle(1, 1)
    np.testing.assert_allclose(r["L"], ck.place_observer(sys.A, sys.C, [-3, -3]))
    np.testing.assert_allclose(r["L"], [[5], [4]], atol=1e-12)   # A - L C: s^2 + (1 + l1) s + (l1 + l2)


def test_fast_observer_converges_faster_but_amplifies_noise():
    slow, fast = observer_noise_compute(1.5, 0.05), observer_noise_compute(15.0, 0.05)
    assert fast["settle"] < slow["settle"]
    assert fast["rms_late"][1] > 5 * slow["rms_late"][1]      # velocity estimate much noisier


def test_observer_noise_without_noise_is_exact_late():
    r = observer_noise_compute(5.0, 0.0)
    assert r["rms_late"].max() < 1e-4      # only the O(dt^2) interpolation of y remains
    np.testing.assert_allclose(r["y"], r["x"][:, 0], atol=1e-12)


def test_kalman_matched_tuning_is_the_reference():
    r = kalman_tuning_compute(np.log10(KALMAN_TRUE_Q), np.log10(KALMAN_TRUE_R))
    np.testing.assert_allclose(r["L"], r["L_matched"], rtol=1e-9)
    np.testing.assert_allclose(r["rms"], r["rms_matched"])
    for q in (-3.0, 2.5):
        mistuned = kalman_tuning_compute(q, np.log10(KALMAN_TRUE_R))
        assert mistuned["rms"][1] > 1.3 * r["rms_matched"][1]


def test_kalman_only_the_ratio_matters():
    a, b = kalman_tuning_compute(0.0, -4.0), kalman_tuning_compute(1.0, -3.0)
    np.testing.assert_allclose(a["L"], b["L"], rtol=1e-8)
    assert np.all(a["poles"].real < 0)


def test_bad_parameters():
    with pytest.raises(ValueError, match=r"speed must be positive"):
        observer_noise_compute(0.0, 0.1)
    with pytest.raises(ValueError, match=r"log10_q contains NaN"):
        kalman_tuning_compute(np.nan, -4)


def test_explorers_build_without_a_browser():
    for make in (observer_noise_explorer, kalman_tuning_explorer):
        e = make()
        assert e.result is not None and e.png.startswith(b"\x89PNG")
        assert e.fig.axes[0].get_title()


def test_the_observer_readout_shows_its_double_pole_as_one_real_pole_over_the_slider():
    """Both observer poles sit at -s: the readout says "-s (double)", never eig's rounding noise
    ("-17 ± 2.38e-07j")."""
    explorer = observer_noise_explorer()
    slider = explorer.controls["speed"]
    for speed in np.arange(slider.min, slider.max + slider.step / 2, slider.step):
        slider.value = float(round(speed, 6))
        explorer.refresh()
        shown = explorer.text.split(",")[0]
        assert shown == f"observer poles {-slider.value:.3g} (double)", shown
        assert "j" not in explorer.alt.split("L =")[0]
