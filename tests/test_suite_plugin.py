"""The test suite's own set-up: axe-core from the dev extra, the browser tests skipped with one
line when no Chromium is here (tests/suite_plugin.py), the ``notebooks`` marker's lists, and the
replay of the session's executed chapters into the slides' build (tests/executed_chapters.py)."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest

import lab_harness
import suite_plugin
from executed_chapters import replay_into, replaying

_BROWSER_TESTS = """
import pytest

pytestmark = pytest.mark.browser

def test_{name}_one():
    pass

def test_{name}_two():
    pass
"""


def test_axe_core_comes_with_the_dev_extra(monkeypatch):
    monkeypatch.delenv("AXE_CORE_JS", raising=False)
    assert re.match(r"/\*! axe v4\.\d+", lab_harness.axe_source())


def test_axe_core_js_chooses_another_axe_core(monkeypatch, tmp_path):
    other = tmp_path / "axe.min.js"
    other.write_text("/*! axe v4.99.0 */ window.axe = {};", encoding="utf-8")
    monkeypatch.setenv("AXE_CORE_JS", str(other))
    assert lab_harness.axe_source() == other.read_text(encoding="utf-8")


def test_axe_core_js_naming_no_file_says_so(monkeypatch, tmp_path):
    monkeypatch.setenv("AXE_CORE_JS", str(tmp_path / "missing.js"))
    with pytest.raises(lab_harness.HarnessError, match=r"AXE_CORE_JS is set to .*missing\.js.*not a file"):
        lab_harness.axe_source()


def test_without_chromium_the_browser_tests_skip_with_one_line(pytester, monkeypatch):
    monkeypatch.setattr(lab_harness, "chromium_path", lambda: None)
    pytester.makeini("[pytest]\nmarkers =\n    browser: b\n    notebooks: n\n")
    pytester.makepyfile(test_ck_lab=_BROWSER_TESTS.format(name="lab"), test_ck_site=_BROWSER_TESTS.format(name="site"),
                        test_ck_unit="def test_unit():\n    pass\n")
    result = pytester.runpytest("-p", "suite_plugin")
    result.assert_outcomes(passed=1, skipped=4)
    lines = [line for line in result.outlines if "Chromium" in line]
    assert lines == ["4 browser tests skipped: Chromium is not installed: apt-get install chromium (Debian, "
                     "Ubuntu), or python -m playwright install chromium where downloads are allowed"], lines
    # the count is of the browser tests that were to run
    one = pytester.runpytest("-p", "suite_plugin", "-k", "lab_one or unit")
    one.assert_outcomes(passed=1, skipped=1, deselected=3)
    assert [line for line in one.outlines if "browser tests skipped" in line][0].startswith("1 browser tests")


#: for the runs below that start xdist workers: only the plugins they test. nbval (which imports
#: jupyter_client and nbformat) and hypothesis cost each process about 3 s of a core to load, and
#: these runs start eleven workers
_LEAN = ("-p", "no:nbval", "-p", "no:hypothesispytest")


def _conftest_for_workers(pytester, source: str = "") -> None:
    """A conftest that loads suite_plugin from the suite's folder, which pytest-xdist's workers do
    not have on their path (they start from the path this process started with), then `source`."""
    pytester.makeconftest(f"import sys\nsys.path.insert(0, {str(Path(__file__).parent)!r})\n"
                          f"pytest_plugins = ['suite_plugin']\n{source}")


def test_spread_over_workers_the_skip_line_is_still_written_once(pytester):
    # the workers skip the tests, the controller writes the line (from the reports)
    _conftest_for_workers(pytester, "import lab_harness\nlab_harness.chromium_path = lambda: None\n")
    pytester.makeini("[pytest]\nmarkers =\n    browser: b\n    notebooks: n\n")
    pytester.makepyfile(test_ck_lab=_BROWSER_TESTS.format(name="lab"), test_ck_site=_BROWSER_TESTS.format(name="site"))
    result = pytester.runpytest(*_LEAN, "-n", "2", "--dist", "loadgroup")
    result.assert_outcomes(skipped=4)
    assert len([line for line in result.outlines if line.startswith("4 browser tests skipped: Chromium")]) == 1


def _workers(result) -> int:
    return int(re.search(r"created: (\d+)/\1 worker", result.stdout.str())[1])


def test_logical_starts_one_worker_more_than_the_cores_unless_the_environment_says(pytester, monkeypatch):
    pytester.makepyfile(test_ck_one="def test_one():\n    pass\n")
    monkeypatch.delenv("PYTEST_XDIST_AUTO_NUM_WORKERS", raising=False)
    cores = _workers(pytester.runpytest(*_LEAN, "-n", "logical"))          # pytest-xdist's own count
    _conftest_for_workers(pytester)
    result = pytester.runpytest(*_LEAN, "-n", "logical")
    result.assert_outcomes(passed=1)
    assert _workers(result) == cores + 1
    monkeypatch.setenv("PYTEST_XDIST_AUTO_NUM_WORKERS", "1")
    assert _workers(pytester.runpytest(*_LEAN, "-n", "logical")) == 1


_SESSION_CONFTEST = """
import os, pytest
from run_once import once, shared_folder

def _build(folder):
    with open(os.environ["CK_MADE"], "a") as made:
        made.write(os.environ.get("PYTEST_XDIST_WORKER", "main") + "\\n")
    folder.mkdir()

@pytest.fixture(scope="session")
def executed_chapters(tmp_path_factory, worker_id):
    return once(shared_folder(tmp_path_factory, worker_id) / "chapters", _build)
"""

_MODULE = """
import os

def record(what):
    with open(os.environ["CK_RAN"], "a") as ran:
        ran.write(f"{what} {os.environ.get('PYTEST_XDIST_WORKER', 'main')}\\n")
""" + "".join(f"""
def test_cell_{i}():
    record("NAME")

def test_reads_{i}(READS):
    record("NAME")
""" for i in range(3))


def test_work_for_the_run_is_made_once_and_each_module_stays_on_one_worker(pytester, monkeypatch, tmp_path):
    monkeypatch.setenv("CK_MADE", str(tmp_path / "made"))
    monkeypatch.setenv("CK_RAN", str(tmp_path / "ran"))
    _conftest_for_workers(pytester, _SESSION_CONFTEST)
    pytester.makeini("[pytest]\nmarkers =\n    browser: b\n    notebooks: n\n    sweeps: s\n    slow: l\n")
    modules = {f"test_ck_{name}": _MODULE.replace("NAME", name).replace("READS", reads)
               for name, reads in [("a", "tmp_path"), ("b", "executed_chapters"), ("c", "tmp_path"),
                                   ("d", "executed_chapters")]}
    pytester.makepyfile(**modules)
    result = pytester.runpytest(*_LEAN, "-n", "2", "--dist", "loadfile", "--no-loadscope-reorder")
    result.assert_outcomes(passed=24)
    assert len((tmp_path / "made").read_text().split()) == 1, "made by both workers"
    ran = [line.split() for line in (tmp_path / "ran").read_text().splitlines()]
    for name in "abcd":
        assert len({worker for module, worker in ran if module == name}) == 1, (name, ran)
    # the modules that read the run's work come first, each in its own order
    order = pytester.runpytest("-n", "0", "--collect-only", "-q").outlines
    assert [line.split("::")[0] for line in order if "::" in line][::6] == \
        ["test_ck_b.py", "test_ck_d.py", "test_ck_a.py", "test_ck_c.py"], order


def test_with_everything_there_no_skip_line_is_written(pytester, monkeypatch):
    monkeypatch.setattr(lab_harness, "missing_reason", lambda: None)
    pytester.makeini("[pytest]\nmarkers =\n    browser: b\n    notebooks: n\n")
    pytester.makepyfile(test_ck_lab=_BROWSER_TESTS.format(name="lab"))
    result = pytester.runpytest("-p", "suite_plugin")
    result.assert_outcomes(passed=2)
    assert not [line for line in result.outlines if "browser tests skipped" in line]


def _defined(pattern: str) -> set[str]:
    """Names of the functions of the files of tests/ whose `def` line matches `pattern` (one group: the name)."""
    return {name for path in Path(__file__).parent.glob("*.py")
            for name in re.findall(pattern, path.read_text(encoding="utf-8"), re.MULTILINE)}


def test_the_notebook_tests_named_in_the_plugin_exist():
    # a renamed test or fixture would otherwise drop out of the marker into the fast loop
    for entry in suite_plugin.NOTEBOOK_TESTS:
        module, name = entry.split("::")
        source = (Path(__file__).parent / module).read_text(encoding="utf-8")
        assert re.search(rf"^def {name}\(", source, re.MULTILINE), entry
    assert suite_plugin.NOTEBOOK_FIXTURES <= _defined(r"^@pytest\.fixture.*\n(?:@.*\n)*def (\w+)\(")


def test_notebook_tests_and_sweeps_carry_their_markers_and_slow(pytester, monkeypatch):
    # file names of their own: the suite's modules of the same names are imported already
    monkeypatch.setattr(suite_plugin, "NOTEBOOK_TESTS", {"test_ck_site.py::test_small_build"})
    monkeypatch.setattr(suite_plugin, "SWEEP_MODULES", {"test_ck_layout.py"})
    pytester.makeini("[pytest]\nmarkers =\n    browser: b\n    notebooks: n\n    sweeps: s\n    slow: l\n")
    pytester.makepyfile(
        test_ck_site="def test_small_build():\n    pass\n\ndef test_landing_page():\n    pass\n",
        test_ck_other="import pytest\n\n@pytest.fixture\ndef release():\n    return 1\n\n"
                      "def test_reads_the_release(release):\n    pass\n",
        test_ck_layout="import pytest\nfrom coursekit.tools.chapters import explorer_factories\n\n"
                       "FACTORIES = list(explorer_factories().values())\n\n"
                       "@pytest.mark.parametrize('factory', FACTORIES[:2])\ndef test_each(factory):\n    pass\n\n"
                       "@pytest.mark.parametrize('name', [f.__name__ for f in FACTORIES[:1]] + ['plain'])\n"
                       "def test_named(name):\n    pass\n")
    fast = pytester.runpytest("-p", "suite_plugin", "-m", "not slow", "-v")
    fast.assert_outcomes(passed=2, deselected=5)
    fast.stdout.fnmatch_lines(["*test_ck_site.py::test_landing_page PASSED*"])
    fast.stdout.fnmatch_lines(["*test_named?plain? PASSED*"])
    assert pytester.runpytest("-p", "suite_plugin", "-m", "notebooks").parseoutcomes()["passed"] == 2
    assert pytester.runpytest("-p", "suite_plugin", "-m", "sweeps").parseoutcomes()["passed"] == 3


def _ran(prelude: str, *sources: str):
    """A notebook as nbclient leaves it: `prelude` then code cells `sources`, each with an output."""
    cells = [nbformat.v4.new_code_cell(source, execution_count=i, outputs=[nbformat.v4.new_output(
        "display_data", data={"text/plain": f"out {i}", "application/x-report": "{}"})])
        for i, source in enumerate((prelude, *sources))]
    nb = nbformat.v4.new_notebook(cells=cells)
    nb.metadata["language_info"] = {"name": "python", "version": "3.11.7"}
    return nb


def test_replay_gives_the_shared_outputs_to_the_same_notebook_only():
    shared = _ran("describe()\nreport()", "x = 1", "plot(x)")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in ("describe()", "x = 1", "plot(x)")])
    replay_into(nb, shared, drop=("application/x-report",))
    assert [c.outputs[0]["data"] for c in nb.cells[1:]] == [{"text/plain": "out 1"}, {"text/plain": "out 2"}]
    assert [c.execution_count for c in nb.cells] == [0, 1, 2] and nb.metadata["language_info"]["name"] == "python"
    assert "application/x-report" in shared.cells[1].outputs[0]["data"], "the shared copy is left as it was"
    changed = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in ("describe()", "x = 2", "plot(x)")])
    with pytest.raises(AssertionError, match="cells differ"):
        replay_into(changed, shared)
    other_prelude = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in ("frames()", "x = 1", "plot(x)")])
    with pytest.raises(AssertionError, match="prelude differs"):
        replay_into(other_prelude, shared)


def test_replaying_executes_like_execute_all_but_replays_the_shared_chapters():
    """The slides' build takes it as its `execute`: each chapter gets the outputs of its shared
    copy, as execute_all leaves a notebook (no prelude cell kept), and nothing is executed here."""
    shared = _ran("describe()\nreport()", "x = 1", "plot(x)")

    class Shared:
        def instructor(self, name):
            assert name == "01_a.ipynb"
            return shared

    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in ("x = 1", "plot(x)")])
    replaying(Shared())([nb], [Path("01_a.ipynb")], prelude="describe()", timeout=1, what="the slides")
    assert [c.source for c in nb.cells] == ["x = 1", "plot(x)"]
    assert [c.outputs[0]["data"]["text/plain"] for c in nb.cells] == ["out 1", "out 2"]
