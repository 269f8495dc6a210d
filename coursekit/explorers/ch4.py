"""Explorers of chapter 4: observer speed against measurement noise, and Kalman Q/R tuning.

Both use the vehicle with GPS (4.1)-(4.2) with m = 1 kg, d = 1 N s/m: the
position is measured with noise, the velocity has to be estimated.
Each explorer is a pure ``*_compute`` function (numbers only, unit-tested)
and a ``*_explorer()`` factory that wires it to sliders.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import models
from .._validation import as_integer, as_scalar, time_grid
from .. import kalman_gain, simulate_with_noise, white_noise
from ..observability import place_observer
from ..observers import observer_system
from ..simulation import simulate
from ..stability import format_poles
from ..style import PALETTE, course_subplots, curve_style
from ._base import Explorer, slider
from .limits import rescale

__all__ = ["KALMAN_TRUE_Q", "KALMAN_TRUE_R", "observer_noise_compute", "observer_noise_explorer", "kalman_tuning_compute",
           "kalman_tuning_explorer"]


def _vehicle_setup(t_end: float, samples: int):
    sys = models.vehicle(m=1.0, d=1.0, sensor="gps")
    t = time_grid(t_end, samples)
    # a traction force that speeds up, coasts and brakes [N]
    u = (np.sin(0.6 * t) + 0.5 * np.cos(1.7 * t))[:, None]
    return sys, t, u


def _rms(e: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(e ** 2, axis=0))


def observer_noise_compute(speed: float, noise_std: float, *, seed: int = 0, t_end: float = 10.0,
                           samples: int = 1001) -> dict:
    """A pole-placement observer on GPS data with noise: speed against noise.

    The observer poles are both placed at ``-speed`` (rad/s, (4.46)); the
    GPS samples carry Gaussian noise of standard deviation `noise_std` [m]
    (per sample; intensity R = noise_std^2 dt). The observer starts at
    x̂(0) = 0 while the vehicle starts at x(0) = [1 m, 0.5 m/s].

    Returns ``t, x`` (true state), ``x_hat``, ``y`` (noisy GPS), ``L``,
    ``poles``, ``rms_late`` (RMS error per state over the second half, the
    noise-driven part) and ``settle`` (time for |x̃| to fall below 5 % of
    its initial size in the noise-free case).
    """
    speed = as_scalar(speed, "speed", positive=True)
    # its square, the intensity R = noise_std^2 dt, must stay in the float range
    noise_std = as_scalar(noise_std, "noise_std", limit=1e6, limit_why="metres of GPS noise")
    if noise_std < 0:
        raise ValueError(f"noise_std must be >= 0: received {noise_std!r} (a standard deviation in m).")
    seed = as_integer(seed, "seed", minimum=0)
    sys, t, u = _vehicle_setup(t_end, samples)
    x0, xhat0 = np.array([1.0, 0.5]), np.zeros(2)
    L = place_observer(sys.A, sys.C, [-speed, -speed])
    truth = simulate(sys, t, u=u, x0=x0)
    dt = t[1] - t[0]
    y = truth.y + white_noise(t, noise_std ** 2 * dt, seed)
    est = simulate(observer_system(sys, L), t, u=np.hstack([u, y]), x0=xhat0)
    err = est.x - truth.x
    half = t.size // 2
    # noise-free error: e^{(A - L C) t} x̃(0), with norm against its start
    clean = simulate(observer_system(sys, L), t, u=np.hstack([u, truth.y]), x0=xhat0).x - truth.x
    size = np.linalg.norm(clean, axis=1)
    above = np.nonzero(size > 0.05 * size[0])[0]
    settle = float(t[above[-1] + 1]) if above.size and above[-1] + 1 < t.size else float(t[-1])
    return dict(t=t, x=truth.x, x_hat=est.x, y=y[:, 0], L=L, speed=speed, noise_std=noise_std,
                poles=np.linalg.eigvals(sys.A - L @ sys.C), rms_late=_rms(err[half:]), settle=settle)


def _two_state_axes(fig):
    """Position (with the noisy GPS samples) above velocity: truth and estimate."""
    ax_p, ax_v = course_subplots(fig, 2, 1, sharex=True)
    truth, estimate = dict(color=PALETTE["black"], linewidth=1.5), dict(linewidth=1.2, **curve_style(1))
    meas, = ax_p.plot([], [], ".", markersize=2, color="0.5", label="GPS y (noisy)")
    true_p, = ax_p.plot([], [], label="true position x1", **truth)
    est_p, = ax_p.plot([], [], label="estimate x̂1", **estimate)
    true_v, = ax_v.plot([], [], label="true velocity x2", **truth)
    est_v, = ax_v.plot([], [], label="estimate x̂2", **estimate)
    ax_p.set_ylabel("position [m]")
    ax_p.set_title("true state and estimate")
    ax_v.set_ylabel("velocity [m/s]")
    ax_v.set_xlabel("time t [s]")
    for ax in (ax_p, ax_v):
        ax.grid(True, alpha=0.4)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return dict(ax_p=ax_p, ax_v=ax_v, meas=meas, true_p=true_p, est_p=est_p, true_v=true_v, est_v=est_v)


def _set_two_state(h, r):
    h["meas"].set_data(r["t"], r["y"])
    h["true_p"].set_data(r["t"], r["x"][:, 0])
    h["est_p"].set_data(r["t"], r["x_hat"][:, 0])
    h["true_v"].set_data(r["t"], r["x"][:, 1])
    h["est_v"].set_data(r["t"], r["x_hat"][:, 1])
    for ax in (h["ax_p"], h["ax_v"]):
        ax.set_xlim(r["t"][0], r["t"][-1])
    rescale(h["ax_p"])
    # velocity axis: the truth with a margin, so a very noisy estimate is clipped, not squashing it
    v = r["x"][:, 1]
    span = max(float(np.ptp(v)), 0.5)
    h["ax_v"].set_ylim(v.min() - 0.6 * span, v.max() + 0.6 * span)


def observer_noise_explorer() -> Explorer:
    """Sliders for the observer pole and the GPS noise: fast observers amplify noise."""
    def readout(r):
        L = r["L"].ravel()
        return (f"observer poles {format_poles(r['poles'])}, L = [{L[0]:.3g}, {L[1]:.3g}]; "
                f"error below 5 % after {r['settle']:.2g} s\n"
                f"RMS error over the second half: position {r['rms_late'][0]:.3g} m, "
                f"velocity {r['rms_late'][1]:.3g} m/s")

    return Explorer(
        title="Observer speed vs measurement noise (4.25)-(4.27): vehicle with GPS",
        controls=dict(speed=slider(2.0, 0.2, 20.0, 0.2, "observer pole -s, s [rad/s]"),
                      noise_std=slider(0.05, 0.0, 0.3, 0.01, "GPS noise std [m]")),
        compute=observer_noise_compute, draw=_two_state_axes, update=_set_two_state, readout=readout, figsize=(8, 6))


#: The true noise intensities of the Kalman explorer's data: force noise on the
#: velocity [(m/s)^2/s] and GPS noise [m^2 s] (std 0.1 m per sample at dt = 0.01 s). Both are
#: powers of ten, so that the log10 sliders start at them on a grid of round values.
KALMAN_TRUE_Q, KALMAN_TRUE_R = 1.0, 1e-4


def _kalman_run(sys, t, record, x_true, Q, R):
    """Steady-state Kalman gain for (Q, R), its estimate on the record, RMS over the 2nd half."""
    L, _ = kalman_gain(sys.A, sys.C, Q, R)
    x_hat = simulate(observer_system(sys, L), t, u=record, x0=[0.0, 0.0]).x
    half = t.size // 2
    return L, x_hat, _rms(x_hat[half:] - x_true[half:])


@lru_cache(maxsize=8)
def _kalman_data(seed: int, t_end: float, samples: int):
    """The noisy data set and the matched filter's result, computed once per seed."""
    sys, t, u = _vehicle_setup(t_end, samples)
    Q_true = np.diag([0.0, KALMAN_TRUE_Q])
    data = simulate_with_noise(sys, t, u, x0=[0.0, 0.0], Q=Q_true, R=[[KALMAN_TRUE_R]], seed=seed)
    record = np.hstack([u, data.y])
    L_m, _, rms_m = _kalman_run(sys, t, record, data.x, Q_true, [[KALMAN_TRUE_R]])
    return sys, t, data, record, L_m, rms_m


def kalman_tuning_compute(log10_q: float, log10_r: float, *, seed: int = 0, t_end: float = 10.0,
                          samples: int = 1001) -> dict:
    """Steady-state Kalman observer with the tuning Q = diag(0, 10^log10_q), R = 10^log10_r.

    The data come from the vehicle with GPS driven by a known force plus a
    random force of intensity `KALMAN_TRUE_Q` on the velocity, with GPS
    noise of intensity `KALMAN_TRUE_R` (see `coursekit.kalman` for units).
    Only the ratio Q/R changes L. The filter tuned with the true intensities
    is computed too, as the reference: no tuning beats it on average.

    Returns ``t, x, x_hat, y, L, poles`` (eig(A - L C)), ``rms`` (RMS error
    per state over the second half), ``rms_matched`` (the same for the
    matched filter) and ``L_matched``.
    """
    q, r = (10.0 ** _exponent(value, name) for value, name in ((log10_q, "log10_q"), (log10_r, "log10_r")))
    # validated before the cache, so that the cache key is the checked value
    t_end = float(time_grid(t_end, samples)[-1])
    seed, samples = as_integer(seed, "seed", minimum=0), as_integer(samples, "samples")
    sys, t, data, record, L_m, rms_m = _kalman_data(seed, t_end, samples)
    L, x_hat, rms = _kalman_run(sys, t, record, data.x, np.diag([0.0, q]), [[r]])
    return dict(t=t.copy(), x=data.x.copy(), x_hat=x_hat, y=data.y[:, 0].copy(), L=L, q=q, r=r,
                poles=np.linalg.eigvals(sys.A - L @ sys.C), rms=rms, rms_matched=rms_m, L_matched=L_m)


def _exponent(value, name: str) -> float:
    """A base-10 exponent of a noise intensity, checked to give a finite, nonzero intensity."""
    value = as_scalar(value, name)
    if abs(value) > 100:
        raise ValueError(f"{name} must lie in [-100, 100]: received {value:g}, an intensity of 10^{value:g}; "
                         "the slider's range is a few decades around the true intensity.")
    return value


def kalman_tuning_explorer() -> Explorer:
    """Sliders for log10 Q and log10 R of a Kalman observer on the same noisy data."""
    def readout(r):
        return (f"Q = diag(0, {r['q']:.2g}), R = {r['r']:.2g}: eig(A - L C) = {format_poles(r['poles'], 2)}\n"
                f"RMS velocity error {r['rms'][1]:.3g} m/s (with the true Q, R: {r['rms_matched'][1]:.3g} m/s)")

    return Explorer(
        title="Kalman filter tuning (4.87)-(4.88): only Q/R matters",
        # both start at the true intensities, powers of ten: on the sliders' grids of round values
        controls=dict(log10_q=slider(float(np.log10(KALMAN_TRUE_Q)), -4.0, 3.0, 0.1, "log10 Q (velocity)"),
                      log10_r=slider(float(np.log10(KALMAN_TRUE_R)), -6.0, 0.0, 0.1, "log10 R (GPS)")),
        compute=kalman_tuning_compute, draw=_two_state_axes, update=_set_two_state, readout=readout, figsize=(8, 6))
