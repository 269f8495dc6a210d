"""Chapter 2's own test cases: the bad inputs of its explorer functions (read by tests/bad_input_cases.py)."""

import numpy as np

from bad_input_cases import T11, bad, ok, scalar_cases

from coursekit.explorers import ch2 as xp2

scalar_cases("explorers.planner_compute", "T", lambda T: xp2.planner_compute(T=T), 3.0, positive=True)
scalar_cases("explorers.time_shown", "T", xp2.time_shown, 3.0, positive=True)
bad("explorers.time_shown", "T 1e308", lambda: xp2.time_shown(1e308), "T")
bad("explorers.planner_compute", "r 1", lambda: xp2.planner_compute(r=1), "r")
bad("explorers.planner_compute", "mass_error -100", lambda: xp2.planner_compute(mass_error=-100.0), "mass_error")
bad("explorers.planner_compute", "samples 1", lambda: xp2.planner_compute(samples=1), "samples")
scalar_cases("explorers.robot_planner_compute", "x_T", lambda x: xp2.robot_planner_compute(x_T=x), 4.0)
bad("explorers.robot_planner_compute", "T zero", lambda: xp2.robot_planner_compute(T=0.0), "T")
bad("explorers.robot_planner_compute", "samples 1", lambda: xp2.robot_planner_compute(samples=1), "samples")
ok("explorers.drive_robot", "good", lambda: xp2.drive_robot(T11, np.ones((11, 2)), np.zeros(3)))
bad("explorers.drive_robot", "u wrong shape", lambda: xp2.drive_robot(T11, np.ones((11, 3)), np.zeros(3)), "u")
bad("explorers.drive_robot", "x0 complex", lambda: xp2.drive_robot(T11, np.ones((11, 2)), np.zeros(3) + 1j), "x0")
bad("explorers.drive_robot", "t NaN", lambda: xp2.drive_robot(T11 * np.nan, np.ones((11, 2)), np.zeros(3)), "t")
for _label, _call in (("planner_compute", xp2.planner_compute), ("robot_planner_compute", xp2.robot_planner_compute)):
    bad(f"explorers.{_label}", "T 1e300", lambda _call=_call: _call(T=1e300), "T")
    bad(f"explorers.{_label}", "samples 10**12", lambda _call=_call: _call(samples=10**12), "samples")
bad("explorers.planner_compute", "r 10**9", lambda: xp2.planner_compute(r=10**9), "r")
for _arg in ("x_T", "y_T", "speed"):
    bad("explorers.robot_planner_compute", f"{_arg} 1e300", lambda _arg=_arg: xp2.robot_planner_compute(**{_arg: 1e300}), _arg)
