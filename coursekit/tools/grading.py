"""Grade a folder of submitted notebooks: ``python -m coursekit grade --chapter N SUBMISSIONS --out DIR``.

`grade` executes every ``*.ipynb`` of SUBMISSIONS (the file name's stem is the
student's id), each in a fresh kernel of its own, in a temporary working folder
holding a copy of that notebook only, with a time limit for the whole notebook
and a memory limit for its kernel, `jobs` at a time (`coursekit.tools._notebook_run`).
While a notebook runs, each call of a course ``check_*`` appends the answer
to a file the grader reads afterwards (`coursekit.exercises._answers`). The
grader then checks the last answer given to each exercise of the chapter again,
in its own process, with the course's own checks: nothing the notebook prints
or returns is trusted, and a check the notebook replaced or patched recorded
nothing, so its exercise scores 0 as "not answered".

It writes

* ``DIR/grades.csv``: one row per submission, sorted by student: ``student``,
  one column per exercise (its check's name, 1 or 0), ``total``, ``status``
  (see `STATUSES`); the same submissions give the same file;
* ``DIR/feedback/<student>.md``: the status and, for each exercise, the
  feedback its check gives on the student's answer (never the solution).

This is not a sandbox: a notebook runs with the rights of the user who grades,
so it can read (and write) every file that user can. For untrusted notebooks
run the grader in a container (docs/grading.md shows a command line).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["STATUSES", "Outcome", "grade", "parse_memory", "grade_answers"]

#: what the status column can say, and what it means (also written into the feedback)
STATUSES = {
    "ok": "the notebook ran to the end",
    "cell error": "some cells raised an exception; the others ran and their answers count",
    "memory": "a cell went over the memory limit; the answers given before and after count",
    "timeout": "the notebook was stopped at the time limit; the answers given before count",
    "crashed": "the kernel died (os._exit, a crash, the memory limit); the answers given before count",
    "invalid notebook": "the file is not a readable notebook (not nbformat JSON); not run",
    "wrong chapter": "the notebook is another chapter's (its title or the checks it calls); not run",
    "grader error": "the grader could not run this notebook; not graded",
}

#: seconds the grader waits beyond --timeout before it stops a notebook's runner itself
_GRACE = 60


@dataclass
class Outcome:
    """What became of one submission: its status and the feedback per exercise."""

    student: str
    status: str
    detail: str
    scores: dict[str, int] = field(default_factory=dict)
    feedback: dict[str, str] = field(default_factory=dict)


def parse_memory(text: str) -> int:
    """Bytes from "4G", "512M", "2048K" or a plain number of bytes; ValueError otherwise."""
    units = {"K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}
    value = str(text).strip().upper().removesuffix("B").removesuffix("I")
    factor = units.get(value[-1:], 1)
    number = value[:-1] if value[-1:] in units else value
    try:
        size = int(float(number) * factor)
    except ValueError:
        raise ValueError(f"memory must be a size such as 4G or 512M, received {text!r}") from None
    if size < 64 * 2**20:
        raise ValueError(f"memory must be at least 64M (a kernel needs that much to start), received {text!r}")
    return size


def _chapter_of(nb) -> int | None:
    """The chapter a notebook is: its title ("# Chapter 2 ..."), else the one chapter whose
    checks its code calls; None when neither tells."""
    from ..exercises._catalog import CATALOG
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            match = re.search(r"^#\s+Chapter\s+(\d+)", cell.source, re.M)
            if match:
                return int(match[1])
    code = "\n".join(cell.source for cell in nb.cells if cell.cell_type == "code")
    called = {number for number, entries in CATALOG.items() for entry in entries
              if re.search(rf"\b{entry.check}\s*\(", code)}
    return called.pop() if len(called) == 1 else None


def _read_submission(path: Path, chapter: int):
    """The notebook, or a (status, detail) pair saying why it is not run."""
    import nbformat
    try:
        nb = nbformat.reads(path.read_text(encoding="utf-8"), as_version=4)
        nbformat.validate(nb)
    except Exception as error:  # any unreadable file becomes a row, never stops the grading
        return ("invalid notebook", f"{type(error).__name__}: {str(error).splitlines()[0][:200]}")
    said = _chapter_of(nb)
    if said is not None and said != chapter:
        return ("wrong chapter", f"the notebook is chapter {said}, the grading is for chapter {chapter}")
    return nb


def _runner_env(answers: Path) -> dict:
    from ..exercises._answers import ANSWERS_ENV
    env = dict(os.environ)
    env[ANSWERS_ENV] = str(answers)
    package_root = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH")) if p)
    return env


def _stop(process: subprocess.Popen) -> None:
    """Stop a runner and whatever it started in its process group."""
    with contextlib.suppress(OSError):
        if hasattr(os, "killpg"):
            os.killpg(process.pid, signal.SIGKILL)
        else:
            process.kill()
    process.wait()


def _run_notebook(nb, student: str, timeout: float, memory: int) -> tuple[str, str, list[dict]]:
    """Execute a copy of `nb` in a folder of its own; (status, detail, answers recorded)."""
    from ..exercises._answers import read_records
    # a notebook may leave files it made unremovable: that must not cost it its grades
    with tempfile.TemporaryDirectory(prefix="coursekit-grade-", ignore_cleanup_errors=True) as box:
        work, private = Path(box) / "work" / "submission", Path(box) / "private"
        work.mkdir(parents=True)
        private.mkdir()
        notebook = work / f"{student}.ipynb"
        notebook.write_text(json.dumps(nb), encoding="utf-8")
        answers = private / "answers.jsonl"
        answers.touch()
        with open(answers, encoding="utf-8", errors="replace") as held:  # still readable if the notebook deletes it
            status, detail = _execute(notebook, private, timeout, memory, _runner_env(answers))
            records = read_records(held)
    return status, detail, records


def _execute(notebook: Path, private: Path, timeout: float, memory: int, env: dict) -> tuple[str, str]:
    command = [sys.executable, "-m", "coursekit.tools._notebook_run", str(notebook), str(private / "kernels"),
               str(timeout), str(memory)]
    process = subprocess.Popen(command, cwd=notebook.parent, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True,
                               start_new_session=True)
    try:
        out, _ = process.communicate(timeout=timeout + _GRACE)
    except subprocess.TimeoutExpired:
        _stop(process)
        return "timeout", f"stopped at the time limit of {timeout:g} s"
    lines = out.strip().splitlines()
    try:
        outcome = json.loads(lines[-1])
        return outcome["status"], outcome["detail"]
    except (IndexError, ValueError, KeyError, TypeError):
        return "crashed", f"the notebook's runner ended without an outcome (exit status {process.returncode})"


def _check_again(check, arguments: dict) -> tuple[bool, str]:
    """Run the course's own check on a recorded answer: (correct, the feedback it printed)."""
    from ..exercises._answers import decode
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = check(**{name: decode(value) for name, value in arguments.items()})
        return bool(result), printed.getvalue().strip()
    except Exception as error:  # an answer the check cannot take is a wrong answer, with the reason
        return False, f"this answer could not be checked: {type(error).__name__}: {error}"


def grade_answers(records: list[dict], chapter: int) -> tuple[dict[str, int], dict[str, str]]:
    """Scores and feedback per check of `chapter` from the recorded answers (the last one counts)."""
    from .. import exercises
    from ..exercises._catalog import chapter_exercises
    last = {record["check"]: record["args"] for record in records}
    scores, feedback = {}, {}
    for entry in chapter_exercises(chapter):
        if entry.check not in last:
            scores[entry.check] = 0
            feedback[entry.check] = ("Not answered: no answer reached the course's check while the notebook "
                                     "ran (a check that is replaced or redefined in the notebook records nothing).")
            continue
        check = getattr(exercises, entry.check).__wrapped__
        correct, text = _check_again(check, last[entry.check])
        scores[entry.check], feedback[entry.check] = int(correct), text
    return scores, feedback


def _grade_one(path: Path, chapter: int, timeout: float, memory: int) -> Outcome:
    student = path.stem
    try:
        read = _read_submission(path, chapter)
        if isinstance(read, tuple):
            status, detail, records = *read, []
        else:
            status, detail, records = _run_notebook(read, student, timeout, memory)
        scores, feedback = grade_answers(records, chapter)
    except Exception as error:  # the grade book is written whatever happens to one notebook
        status, detail = "grader error", f"{type(error).__name__}: {error}"
        scores, feedback = grade_answers([], chapter)
    return Outcome(student, status, detail, scores, feedback)


def _feedback_text(outcome: Outcome, chapter: int) -> str:
    from ..exercises._catalog import chapter_exercises
    total = sum(outcome.scores.values())
    lines = [f"# Feedback for {outcome.student}: chapter {chapter}", "",
             f"Status: **{outcome.status}**: {outcome.detail}. ({STATUSES[outcome.status]})", "",
             f"Score: {total} of {len(outcome.scores)}", ""]
    for entry in chapter_exercises(chapter):
        lines += [f"## Exercise {entry.label}: {entry.title} (`{entry.check}`): {outcome.scores[entry.check]}",
                  "", "```text", outcome.feedback[entry.check], "```", ""]
    return "\n".join(lines)


def _write(outcomes: list[Outcome], chapter: int, out: Path) -> Path:
    from ..exercises._catalog import chapter_exercises
    checks = [entry.check for entry in chapter_exercises(chapter)]
    feedback_dir = out / "feedback"
    feedback_dir.mkdir(parents=True, exist_ok=True)
    for old in feedback_dir.glob("*.md"):
        old.unlink()
    for outcome in outcomes:
        (feedback_dir / f"{outcome.student}.md").write_text(_feedback_text(outcome, chapter), encoding="utf-8")
    table = out / "grades.csv"
    with open(table, "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file, lineterminator="\n")
        writer.writerow(["student", *checks, "total", "status"])
        for o in outcomes:
            writer.writerow([o.student, *(o.scores[c] for c in checks), sum(o.scores.values()), o.status])
    return table


def _require_tools() -> None:
    """RuntimeError naming the extra to install when nbformat, nbclient or ipykernel is missing."""
    import importlib.util
    missing = [name for name in ("nbformat", "nbclient", "ipykernel") if importlib.util.find_spec(name) is None]
    if missing:
        raise RuntimeError(f"grading needs {', '.join(missing)}: install the grade extra, "
                           "python -m pip install \"coursekit[grade]\" (or -e \".[grade]\" in the repository)")


def _check_arguments(submissions: Path, out: Path, chapter, timeout, jobs) -> None:
    from ..exercises._catalog import chapter_exercises
    chapter_exercises(chapter)
    if not submissions.is_dir():
        raise ValueError(f"submissions: {submissions} is not a folder; pass the folder of submitted notebooks")
    if out.resolve() == submissions.resolve():
        raise ValueError("out must be another folder than submissions (the feedback would mix with them)")
    if not (isinstance(timeout, (int, float)) and timeout > 0):
        raise ValueError(f"timeout must be a positive number of seconds, received {timeout!r}")
    if not (isinstance(jobs, int) and jobs >= 1):
        raise ValueError(f"jobs must be a whole number of at least 1, received {jobs!r}")


def grade(submissions, out, *, chapter: int, timeout: float = 300, memory: int | str = "4G",
          jobs: int | None = None) -> Path:
    """Grade every ``*.ipynb`` of `submissions` for `chapter`; returns the path of ``grades.csv``.

    `timeout` is in seconds per notebook, `memory` the kernel's address-space
    limit (bytes or "4G"), `jobs` how many notebooks run at once (default: the
    number of cores). See the module docstring for what is written to `out`.
    """
    submissions, out = Path(submissions), Path(out)
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    _check_arguments(submissions, out, chapter, timeout, jobs)
    _require_tools()
    memory = parse_memory(memory) if isinstance(memory, str) else int(memory)
    paths = sorted(submissions.glob("*.ipynb"), key=lambda p: p.stem)
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        outcomes = list(pool.map(lambda p: _grade_one(p, chapter, timeout, memory), paths))
    out.mkdir(parents=True, exist_ok=True)
    return _write(outcomes, chapter, out)
