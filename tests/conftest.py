"""Shared test settings: hypothesis profiles, small helpers, and the suite's markers
(``browser`` and ``notebooks``: tests/suite_plugin.py)."""

import os

# One BLAS thread per process (unless the environment says otherwise): the run spreads over the
# cores by processes (xdist's workers, the kernels they start, Chromium), and OpenBLAS's own
# threads on top of them, for the course's small matrices, only wait on each other for a core
# (about 15 % of the CPU of a sweep of explorers on 2 cores). Set before numpy loads OpenBLAS
# here, and inherited by every worker and kernel started from here.
for _threads in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_threads, "1")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

# pytester: tests/test_suite_plugin.py runs small test sessions of its own
pytest_plugins = ["pytester", "suite_plugin"]

settings.register_profile("default", deadline=None, max_examples=60,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("ci", parent=settings.get_profile("default"), derandomize=True)
settings.load_profile("ci" if os.environ.get("CI") else "default")


def sorted_eig(values):
    """Eigenvalues sorted by real then imaginary part, for comparisons."""
    values = np.asarray(values, dtype=complex)
    return values[np.lexsort((values.imag.round(8), values.real.round(8)))]


@pytest.fixture(scope="session")
def executed_chapters(tmp_path_factory, worker_id):
    """The chapters executed once per session for the tests that read them (tests/executed_chapters.py)."""
    from executed_chapters import ExecutedChapters
    return ExecutedChapters(tmp_path_factory, worker_id)


@pytest.fixture(scope="session")
def course_builds(tmp_path_factory, worker_id, executed_chapters):
    """The website and the slides built once per session for the tests that read them (tests/course_builds.py)."""
    from course_builds import CourseBuilds
    return CourseBuilds(tmp_path_factory, worker_id, executed_chapters)
