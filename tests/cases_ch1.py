"""Chapter 1's own test cases: the bad inputs of its explorer functions (read by tests/bad_input_cases.py)."""

import numpy as np

from bad_input_cases import bad, scalar_cases, span_cases

from coursekit.explorers import ch1 as xp1

scalar_cases("explorers.euler_compute", "Ts", lambda Ts: xp1.euler_compute(Ts), 0.1, positive=True)
bad("explorers.euler_compute", "example unknown", lambda: xp1.euler_compute(0.1, example="cubic"), "example")
bad("explorers.euler_compute", "samples 1", lambda: xp1.euler_compute(0.1, samples=1), "samples")
bad("explorers.euler_compute", "samples 10**12", lambda: xp1.euler_compute(0.1, samples=10**12), "samples")
bad("explorers.euler_compute", "Ts 1e-300", lambda: xp1.euler_compute(1e-300), "Ts")
bad("explorers.msd_compute", "m tiny, k huge", lambda: xp1.msd_compute(1e-300, 0.5, 1e300), "m")
bad("explorers.euler_compute", "samples fractional", lambda: xp1.euler_compute(0.1, samples=10.5), "samples")
scalar_cases("explorers.msd_compute", "m", lambda m: xp1.msd_compute(m, 0.5, 2.0), 1.0, positive=True)
bad("explorers.msd_compute", "d NaN", lambda: xp1.msd_compute(1.0, np.nan, 2.0), "d")
bad("explorers.msd_compute", "t_end negative", lambda: xp1.msd_compute(1.0, 0.5, 2.0, t_end=-1.0), "t_end")
bad("explorers.msd_compute", "t_end NaN", lambda: xp1.msd_compute(1.0, 0.5, 2.0, t_end=np.nan), "t_end")
bad("explorers.msd_compute", "samples 0", lambda: xp1.msd_compute(1.0, 0.5, 2.0, samples=0), "samples")
bad("explorers.msd_compute", "experiment unknown", lambda: xp1.msd_compute(1.0, 0.5, 2.0, experiment="ramp"), "experiment")
span_cases("explorers.msd_compute", lambda **kw: xp1.msd_compute(1.0, 0.5, 2.0, **kw))
