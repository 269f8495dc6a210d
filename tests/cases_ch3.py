"""Chapter 3's own test cases: the bad inputs of its explorer functions (read by tests/bad_input_cases.py)."""

import numpy as np

from bad_input_cases import bad, ok, scalar_cases, span_cases

from coursekit.explorers import ch3 as xp3

bad("explorers.pole_placement_compute", "wn 1e300", lambda: xp3.pole_placement_compute(wn=1e300), "wn")
scalar_cases("explorers.pair_poles", "zeta", lambda z: xp3.pair_poles(2.0, z), 0.7, positive=True)
scalar_cases("explorers.pole_placement_compute", "wn", lambda w: xp3.pole_placement_compute(wn=w), 2.0, positive=True)
bad("explorers.pole_placement_compute", "p3 NaN", lambda: xp3.pole_placement_compute(p3=np.nan), "p3")
bad("explorers.pole_placement_compute", "p3 complex", lambda: xp3.pole_placement_compute(p3=-3 + 1j), "p3")
bad("explorers.pole_placement_compute", "t_end zero", lambda: xp3.pole_placement_compute(t_end=0.0), "t_end")
bad("explorers.pole_placement_compute", "samples 1", lambda: xp3.pole_placement_compute(samples=1), "samples")
scalar_cases("explorers.upright_pendulum_compute", "theta0_deg", lambda th: xp3.upright_pendulum_compute(theta0_deg=th), 30.0)
bad("explorers.upright_pendulum_compute", "pole positive", lambda: xp3.upright_pendulum_compute(pole=1.0), "pole")
bad("explorers.upright_pendulum_compute", "u_max negative", lambda: xp3.upright_pendulum_compute(u_max=-1.0), "u_max")
bad("explorers.upright_pendulum_compute", "pole NaN", lambda: xp3.upright_pendulum_compute(pole=np.nan), "pole")
scalar_cases("explorers.integral_action_compute", "d", lambda d: xp3.integral_action_compute(d=d), 1.0)
bad("explorers.integral_action_compute", "integral_pole positive", lambda: xp3.integral_action_compute(integral_pole=1.0), "integral_pole")
bad("explorers.integral_action_compute", "t_end inf", lambda: xp3.integral_action_compute(t_end=np.inf), "t_end")
ok("explorers.pair_poles", "zeta 1e300 (zeta**2 overflowed)", lambda: xp3.pair_poles(2.0, 1e300))
bad("explorers.pole_placement_compute", "zeta 1e300", lambda: xp3.pole_placement_compute(zeta=1e300), "zeta")
span_cases("explorers.pole_placement_compute", xp3.pole_placement_compute)
span_cases("explorers.upright_pendulum_compute", xp3.upright_pendulum_compute)
span_cases("explorers.integral_action_compute", xp3.integral_action_compute)
