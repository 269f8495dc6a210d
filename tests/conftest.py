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
def executed_chapters(tmp_path_factory):
    """edition ("instructor" or "student") -> its chapter notebooks executed, once per session
    (tests/executed_chapters.py says with what and who reads them)."""
    from executed_chapters import execute_edition
    done = {}

    def executed(edition: str):
        if edition not in done:
            try:
                done[edition] = execute_edition(edition, tmp_path_factory.mktemp(edition) / "edition")
            except Exception as error:     # said once in full; the other tests say it again in short
                done[edition] = f"executing the {edition} edition failed: {type(error).__name__}: " \
                                f"{str(error)[:2000]}"
                raise
        if isinstance(done[edition], str):
            pytest.fail(done[edition])
        return done[edition]

    return executed
