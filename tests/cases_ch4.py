"""Chapter 4's own test cases: the bad inputs of its explorer functions (read by tests/bad_input_cases.py)."""

import numpy as np

from bad_input_cases import bad, scalar_cases, span_cases

from coursekit.explorers import ch4 as xp4

bad("explorers.kalman_tuning_compute", "log10_q 400", lambda: xp4.kalman_tuning_compute(400.0, 0.0), "log10_q")
scalar_cases("explorers.observer_noise_compute", "noise_std", lambda s: xp4.observer_noise_compute(1.0, s), 0.1)
bad("explorers.observer_noise_compute", "noise_std negative", lambda: xp4.observer_noise_compute(1.0, -0.1), "noise_std")
bad("explorers.observer_noise_compute", "speed NaN", lambda: xp4.observer_noise_compute(np.nan, 0.1), "speed")
bad("explorers.observer_noise_compute", "samples 1", lambda: xp4.observer_noise_compute(1.0, 0.1, samples=1), "samples")
scalar_cases("explorers.kalman_tuning_compute", "log10_q", lambda q: xp4.kalman_tuning_compute(q, 0.0), 0.0)
bad("explorers.kalman_tuning_compute", "log10_r inf", lambda: xp4.kalman_tuning_compute(0.0, np.inf), "log10_r")
bad("explorers.kalman_tuning_compute", "t_end zero", lambda: xp4.kalman_tuning_compute(0.0, 0.0, t_end=0.0), "t_end")
bad("explorers.kalman_tuning_compute", "seed text", lambda: xp4.kalman_tuning_compute(0.0, 0.0, seed="a"), "seed")
bad("explorers.observer_noise_compute", "seed 10**400", lambda: xp4.observer_noise_compute(1.0, 0.1, seed=10**400), "seed")
bad("explorers.observer_noise_compute", "noise_std 1e300", lambda: xp4.observer_noise_compute(1.0, 1e300), "noise_std")
span_cases("explorers.observer_noise_compute", lambda **kw: xp4.observer_noise_compute(1.0, 0.1, **kw))
span_cases("explorers.kalman_tuning_compute", lambda **kw: xp4.kalman_tuning_compute(0.0, 0.0, **kw))
