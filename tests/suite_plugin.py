"""The test suite's markers (a pytest plugin that tests/conftest.py loads).

* ``browser`` (set by the browser tests' modules): when Chromium or Playwright is missing, every
  such test is skipped, and the run ends with one line that says why and how to get it;
* ``notebooks`` (set here, on collection): the tests that execute notebooks in a Jupyter kernel,
  nbval's cells of ``notebooks/`` and the tests `NOTEBOOK_TESTS` and `NOTEBOOK_FIXTURES` name;
* ``sweeps`` (set here): the tests of `SWEEP_MODULES` run once for each explorer of the course
  (parametrized over them), which move every slider over its range or drag it, in several styles;
* ``slow`` (set here): any of the three. ``python -m pytest -m "not slow"`` is the contributors'
  fast loop.

The run is spread over the machine's cores by pytest-xdist (``-n logical --dist loadfile`` in
pyproject.toml; one worker more than the cores, `pytest_xdist_auto_num_workers`): each test module
goes to one worker as a whole (nbval's cells share their notebook's kernel, module fixtures are
made once). The modules are handed out longest first: those that read the run's executed chapters
and builds (`SESSION_FIXTURES`, made once per run: tests/run_once.py), then those with a slow test,
then the rest, each in its own order.
"""

from __future__ import annotations

import os

import pytest

import lab_harness

__all__ = ["NOTEBOOK_TESTS", "NOTEBOOK_FIXTURES", "SWEEP_MODULES", "SESSION_FIXTURES", "browser_skip_line",
           "pytest_collection_modifyitems", "pytest_xdist_auto_num_workers", "pytest_collection_finish",
           "pytest_terminal_summary"]

#: the tests that execute notebooks besides nbval's, as "module::test" (every parametrization)
NOTEBOOK_TESTS = {
    "test_figure_style.py::test_every_figure_a_notebook_shows_is_readable_by_everyone",
    "test_site.py::test_the_site_builds_with_every_outside_connection_refused",
    "test_slides.py::test_small_build_from_the_command_line_needs_no_network",
    "test_tools_notebooks.py::test_execute_all_shuts_down_every_kernel_it_started",
}
#: fixtures that execute notebooks (or hand out executed ones): every test using one is marked
NOTEBOOK_FIXTURES = {"executed_chapters", "course_builds", "release", "graded", "extended", "built", "small_site"}

#: the modules whose tests parametrized over the course's explorers are sweeps
SWEEP_MODULES = {"test_explorer_frames.py", "test_figure_layout.py", "test_figure_style.py"}

#: the session fixtures whose work is made once per run: their modules are handed out first
SESSION_FIXTURES = {"executed_chapters", "course_builds"}


def _executes_notebooks(item) -> bool:
    if item.path.suffix == ".ipynb":
        return True
    name = getattr(item, "originalname", item.name)
    return (f"{item.path.name}::{name}" in NOTEBOOK_TESTS
            or bool(NOTEBOOK_FIXTURES & set(getattr(item, "fixturenames", ()))))


def _sweeps(item, explorers: list) -> bool:
    """Whether `item` is a test of `SWEEP_MODULES` run for one of `explorers` (factory or name)."""
    if item.path.name not in SWEEP_MODULES or not hasattr(item, "callspec"):
        return False
    names = {f.__name__ for f in explorers}
    return any(any(value is f for f in explorers) or (isinstance(value, str) and value in names)
               for value in item.callspec.params.values())


def _rank(items) -> dict:
    """{module path: 0 when a test of it reads a session fixture, 1 when one is slow, else 2}."""
    rank: dict = {}
    for item in items:
        mine = 0 if SESSION_FIXTURES & set(getattr(item, "fixturenames", ())) else \
            1 if item.get_closest_marker("slow") else 2
        rank[item.path] = min(rank.get(item.path, 2), mine)
    return rank


@pytest.hookimpl(tryfirst=True)      # before -m deselects by these markers
def pytest_collection_modifyitems(config, items):
    """Mark the notebook tests, the sweeps and all slow tests; put the modules in the order xdist
    hands them out (see the module's doc)."""
    from coursekit.tools.chapters import explorer_factories
    explorers = list(explorer_factories().values())
    for item in items:
        if _executes_notebooks(item):
            item.add_marker(pytest.mark.notebooks)
        if _sweeps(item, explorers):
            item.add_marker(pytest.mark.sweeps)
        if any(item.get_closest_marker(name) for name in ("notebooks", "sweeps", "browser")):
            item.add_marker(pytest.mark.slow)
    rank = _rank(items)
    items.sort(key=lambda item: rank[item.path])    # a stable sort: each module keeps its order


@pytest.hookimpl(hookwrapper=True)
def pytest_xdist_auto_num_workers(config):
    """How many workers ``-n logical`` (pyproject.toml) starts: one more than pytest-xdist's own
    count of the CPUs. Part of a run waits rather than computes (Chromium's timers and animations,
    a kernel's answer, the grader's time limit, a build another worker is making): on two cores
    with two workers the cores stood idle 13 % of the run (vmstat), with three 4 %, and the whole
    run took 626 s instead of 759 s. PYTEST_XDIST_AUTO_NUM_WORKERS, when set, is taken as it is
    (pytest-xdist's own rule)."""
    outcome = yield
    if not os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        outcome.force_result(outcome.get_result() + 1)


def pytest_collection_finish(session):
    """Skip the browser tests that are to run when no browser is here (in each xdist worker)."""
    browser = [item for item in session.items if item.get_closest_marker("browser")]
    reason = lab_harness.missing_reason() if browser else None
    if reason:
        for item in browser:
            item.add_marker(pytest.mark.skip(reason=reason))


def browser_skip_line(reason: str, count: int) -> str:
    """The one line that ends a run whose browser tests were skipped."""
    return f"{count} browser tests skipped: {reason}"


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    """Say once why the browser tests were skipped (read from the reports: the workers skipped them)."""
    skipped = [report for report in terminalreporter.stats.get("skipped", []) if "browser" in report.keywords]
    reason = lab_harness.missing_reason() if skipped else None
    count = sum(reason in str(report.longrepr) for report in skipped) if reason else 0
    if count:
        terminalreporter.write_line(browser_skip_line(reason, count), yellow=True)
