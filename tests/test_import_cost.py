"""`import coursekit` stays light: the heavy libraries load inside the functions that use them.

The package's promise (README, coursekit/__init__.py) is a fast first cell; a module-level
`from scipy.linalg import ...` in any submodule silently costs every student about half a second.
"""

import subprocess
import sys

HEAVY = ("scipy", "sympy", "matplotlib", "ipywidgets", "control")


def test_import_coursekit_loads_no_heavy_library():
    code = ("import sys, coursekit; "
            f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"import coursekit loaded: {out.stdout.strip()}"
