"""Every public function and method on bad input: a clear ValueError/TypeError, never a hang.

The cases are the table in `bad_input_cases.py` (one line per case; add a
line there for every new public function). They run in two worker processes
(each imports coursekit once) with a per-case deadline, so that a hang or a
crash fails the case that caused it instead of stopping the suite; each case
is one test here, so a failure report names it.
"""

from __future__ import annotations

import inspect
import json
import os
import queue
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import pytest

import bad_input_cases as table
import coursekit as ck
from coursekit import models
from coursekit.tools.chapters import chapter_modules, check_functions

#: the worker: the whole table imported (cases added at its end too), then its main loop
WORKER = f"import sys; sys.path.insert(0, {str(Path(table.__file__).parent)!r}); import bad_input_cases; bad_input_cases.main()"
#: a worker that prints nothing for this long is stuck outside any case's deadline
#: (the per-case alarm and fault handler act within DEADLINE + 5 s; the rest is for
#: importing the libraries on a loaded machine) and is killed
SILENCE_LIMIT = 60

#: public classes without bad-input cases of their own, and why
NOT_CALLED_BY_STUDENTS = {
    # exceptions and warnings are raised by coursekit, not called with data
    name for name in ck.__all__
    if inspect.isclass(getattr(ck, name)) and issubclass(getattr(ck, name), BaseException)
}


def _worker_lines(ids: list[str], env: dict):
    """Start a worker on `ids`; yield its report records, None if it falls silent, then its stderr."""
    with tempfile.TemporaryFile("w+") as todo_file, tempfile.TemporaryFile("w+") as err_file:
        todo_file.write("\n".join(ids) + "\n")
        todo_file.seek(0)
        proc = subprocess.Popen([sys.executable, "-c", WORKER], stdin=todo_file, stdout=subprocess.PIPE,
                                stderr=err_file, text=True, env=env)
        lines: queue.Queue = queue.Queue()
        threading.Thread(target=lambda: [*map(lines.put, proc.stdout), lines.put("")], daemon=True).start()
        while True:
            try:
                line = lines.get(timeout=SILENCE_LIMIT)
            except queue.Empty:
                proc.kill()
                yield None
                break
            if not line:
                break
            if line.startswith(table.MARK):  # anything else is output a case printed past the redirection
                yield json.loads(line[len(table.MARK):])
        proc.wait()
        err_file.seek(0)
        yield err_file.read()


def _run_batch(ids: list[str]) -> dict[str, dict]:
    """Run the cases `ids` in one worker; a worker killed inside a case marks it and restarts."""
    results: dict[str, dict] = {}
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.pathsep.join(
        [str(Path(ck.__file__).parent.parent), os.environ.get("PYTHONPATH", "")]))
    todo = list(ids)
    while todo:
        started, stderr = None, ""
        for record in _worker_lines(todo, env):
            if isinstance(record, str):
                stderr = record
            elif record is None:
                stderr = f"no output for {SILENCE_LIMIT} s"
            elif "start" in record:
                started = record["start"]
            else:
                results[record["id"]] = record
                started = None
        if started is not None:  # the worker died inside this case
            results[started] = dict(status="fail", detail="the worker was killed while running this "
                                    f"case (a hang in compiled code or a crash): {stderr[-2000:]}")
        elif not any(i in results for i in todo):
            raise RuntimeError(f"the bad-input worker made no progress:\n{stderr[-4000:]}")
        todo = [i for i in todo if i not in results]
    return results


@pytest.fixture(scope="module")
def results() -> dict[str, dict]:
    ids = [case.id for case in table.CASES]
    # two workers, one per core, each with every other case (neighbouring cases cost alike)
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(2) as pool:
        halves = pool.map(_run_batch, [ids[0::2], ids[1::2]])
    return {k: v for half in halves for k, v in half.items()}


@pytest.mark.parametrize("case_id", [case.id for case in table.CASES])
def test_bad_input(results, case_id):
    verdict = results[case_id]
    assert verdict["status"] == "pass", verdict["detail"]


def test_case_ids_are_unique():
    ids = [case.id for case in table.CASES]
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})


def _public(module, prefix: str = "") -> set[str]:
    return {prefix + name for name in module.__all__
            if inspect.isfunction(getattr(module, name)) or inspect.isclass(getattr(module, name))}


def test_every_public_function_and_class_has_bad_input_cases():
    """A new public name without a line in the table fails here."""
    covered = {case.target for case in table.CASES}
    covered |= {target.split(".")[0] for target in covered}  # a class is covered by its methods' cases
    wanted = _public(ck) - NOT_CALLED_BY_STUDENTS
    wanted |= _public(models, "models.")
    wanted |= {"exercises." + label.split(".")[1] for label in check_functions()}
    wanted |= {f"explorers.{name}" for module in chapter_modules("explorers") for name in module.__all__
               if inspect.isfunction(getattr(module, name)) and not name.endswith("_explorer")}
    # methods students call
    wanted |= {"StateSpace.f", "StateSpace.h", "StateSpace.poles", "NonlinearSystem.f",
               "NonlinearSystem.h", "SimulationResult.plot"}
    assert not wanted - covered, f"add bad-input cases for {sorted(wanted - covered)}"


def test_every_case_kind_can_fail():
    """The harness itself: a silent return, a wrong exception type, a wrong name and a hang fail."""
    probes = [table.Case("probe", "silent", lambda: None, "bad", "x"),
              table.Case("probe", "wrong type", lambda: {}["x"], "bad", "x"),
              table.Case("probe", "wrong name", lambda: int("y"), "bad", table._word("x")),
              table.Case("probe", "Correct", lambda: print("Correct: yes") or True, "feedback", ""),
              table.Case("probe", "warns", lambda: __import__("warnings").warn("w"), "ok", ""),
              table.Case("probe", "no warning", lambda: None, "warns", "x"),
              table.Case("probe", "foreign warning", lambda: __import__("warnings").warn("x"), "warns", "x")]
    for probe in probes:
        assert table._run_case(probe)["status"] == "fail", probe.label
    import signal
    old = signal.signal(signal.SIGALRM, table._alarm)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.2)
        hang = table._run_case(table.Case("probe", "hang", lambda: [0 for _ in iter(int, 1)], "bad", "x"))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert hang["status"] == "hang"
