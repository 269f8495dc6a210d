"""Chapter 1 explorers: compute functions against closed forms; widgets build without a browser."""

import numpy as np
import pytest

from coursekit.explorers.ch1 import euler_compute, euler_explorer, msd_compute, msd_explorer


def test_euler_compute_first_order_closed_form():
    r = euler_compute(0.1)
    k = np.arange(r["tk"].size)
    np.testing.assert_allclose(r["xk"], 6 * 0.7**k)
    np.testing.assert_allclose(r["xk_exact"], 6 * np.exp(-3 * r["tk"]), rtol=1e-9)
    np.testing.assert_allclose(r["x"], 6 * np.exp(-3 * r["t"]), rtol=1e-9)
    assert np.isclose(r["rho"], 0.7) and r["stable"]
    assert np.isclose(r["Ts_max"], 2 / 3)
    assert np.isclose(r["max_error"], np.max(np.abs(6 * 0.7**k - 6 * np.exp(-3 * r["tk"]))))


def test_euler_compute_is_unstable_beyond_two_over_lambda():
    r = euler_compute(0.8)
    assert not r["stable"] and np.isclose(r["rho"], 1.4)
    assert abs(r["xk"][-1]) > 6


def test_euler_compute_mass_spring_damper_limit():
    # eigenvalues -0.25 +- j sqrt(2 - 1/16): Ts < -2 Re / |lambda|^2 = 0.5 / 2
    r = euler_compute(0.3, example="mass-spring-damper (1.57)")
    assert np.isclose(r["Ts_max"], 0.25)
    assert not r["stable"]
    assert euler_compute(0.2, example="mass-spring-damper (1.57)")["stable"]


def test_euler_compute_error_halves_with_the_step():
    e1 = euler_compute(0.02)["max_error"]
    e2 = euler_compute(0.01)["max_error"]
    assert 1.8 < e1 / e2 < 2.2


def test_msd_compute_damping_ratio_and_steady_state():
    r = msd_compute(m=2.0, d=1.2, k=8.0, t_end=60.0)
    assert np.isclose(r["omega_n"], 2.0)
    assert np.isclose(r["zeta"], 1.2 / (2 * 4.0))
    np.testing.assert_allclose(np.sort_complex(r["poles"]),
                               np.sort_complex(np.roots([2.0, 1.2, 8.0])))
    assert np.isclose(r["y"][-1], 1 / 8.0, atol=1e-4)


def test_msd_compute_initial_condition_undamped():
    r = msd_compute(m=1.0, d=0.0, k=4.0, experiment="initial", t_end=5.0)
    np.testing.assert_allclose(r["y"], np.cos(2 * r["t"]), atol=1e-9)
    np.testing.assert_allclose(r["v"], -2 * np.sin(2 * r["t"]), atol=1e-9)


@pytest.mark.parametrize("call, match", [
    (lambda: euler_compute(0.0), "Ts must be positive"),
    (lambda: euler_compute(0.1, example="rocket"), "example must be one of"),
    (lambda: msd_compute(m=0.0, d=1.0, k=1.0), "m must be positive"),
    (lambda: msd_compute(m=1.0, d=1.0, k=1.0, experiment="ramp"), "experiment must be"),
])
def test_bad_input_raises_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_euler_explorer_builds_and_refreshes():
    ex = euler_explorer()
    assert set(ex.controls) == {"Ts", "example"}
    assert all(getattr(w, "continuous_update", True) is True for w in ex.controls.values()
               if hasattr(w, "continuous_update"))
    ex.widget  # build the live widget (observers attached)
    ex.controls["Ts"].value = 0.8
    assert not ex.result["stable"]
    assert "UNSTABLE" in ex.text and "UNSTABLE" in ex.alt
    np.testing.assert_allclose(ex.handles["approx"].get_xdata(), ex.result["tk"])
    ex.controls["example"].value = "mass-spring-damper (1.57)"
    assert ex.result["example"] == "mass-spring-damper (1.57)"
    assert ex._repr_mimebundle_()["image/png"]


def test_msd_explorer_readout_shows_damping_ratio_and_frequency():
    ex = msd_explorer()
    ex.widget
    ex.controls["d"].value = 2.0
    text = ex.text
    assert "zeta = 0.707" in text and "omega_n = 1.414" in text
    np.testing.assert_allclose(ex.handles["y"].get_ydata(), ex.result["y"])
