"""Shared test settings: hypothesis profiles, small helpers, and the suite's markers
(``browser`` and ``notebooks``: tests/suite_plugin.py)."""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

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
