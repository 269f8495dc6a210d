"""The grader: ``python -m coursekit grade --chapter N SUBMISSIONS --out DIR``.

`grade` executes every ``*.ipynb`` of SUBMISSIONS (regular files only: links
and special files are skipped; the file name's stem is the student's id),
each in a fresh kernel of its own, sealed off by the sandbox of
`coursekit.tools.grading.sandbox` (bubblewrap: read-only system, no network, no other
process, nothing of the instructor's files, the other submissions or the
grader's folders), with a time limit for the whole notebook and memory,
CPU-time and file-size limits for its kernel, `jobs` at a time
(`coursekit.tools.grading.runner`, which runs outside the sandbox). While a
notebook runs, each call of a course ``check_*`` appends the answer to a
file in the submission's one writable folder; the grader reads it back
afterwards as data only, bounded (`coursekit.exercises._answers`). It then
checks the last answer given to each exercise of the chapter again, in its
own process, with the course's own checks: nothing the notebook prints or
returns is trusted, and a check the notebook replaced or patched recorded
nothing, so its exercise scores 0 as "not answered".

It writes

* ``DIR/grades.csv``: one row per submission, sorted by student: ``student``,
  one column per exercise (its check's name, 1 or 0), ``total``, ``status``
  (see `STATUSES`); the same submissions give the same file;
* ``DIR/feedback/<student>.md``: the status and, for each exercise, the
  feedback its check gives on the student's answer (never the solution).

Where the sandbox cannot run (no bwrap, not Linux, user namespaces refused),
`grade` raises `SandboxUnavailable` unless called with ``sandbox=False``
(``--no-sandbox``), which runs the notebooks with the grader's own rights.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import signal
import stat
import subprocess
import sys
import tempfile
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from ..._chapters import exercises
from ...exercises._answers import ANSWERS_ENV, decode, read_last_records
from ...exercises._catalog import chapter_exercises
from ...exercises._feedback import feedback_to
from ..notebooks import write_notebook
from .kernel import kernel_argv
from .runner import RUNNER_STATUSES
from .sandbox import Sandbox, SandboxUnavailable, check_sandbox

__all__ = ["STATUSES", "Outcome", "grade", "parse_memory", "grade_answers", "student_id", "SandboxUnavailable"]

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

#: first characters that make a spreadsheet read a cell as a formula (CSV injection)
_FORMULA = ("=", "+", "-", "@", "\t", "\r")


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
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            match = re.search(r"^#\s+Chapter\s+(\d+)", cell.source, re.M)
            if match:
                return int(match[1])
    code = "\n".join(cell.source for cell in nb.cells if cell.cell_type == "code")
    called = {number for number, entries in exercises().items() for entry in entries
              if re.search(rf"\b{entry.check}\s*\(", code)}
    return called.pop() if len(called) == 1 else None


def student_id(path: Path) -> str:
    """The student id of a submission: its file name without ``.ipynb``, as text whatever its
    bytes (a name that is not UTF-8, as unzip leaves Windows names, keeps its odd bytes as
    ``\\xNN``)."""
    return os.fsencode(path.stem).decode("utf-8", "backslashreplace")


def _submission_paths(submissions: Path) -> list[Path]:
    """The regular ``*.ipynb`` files of `submissions` (no links, folders, pipes or devices), by name."""
    paths = []
    for path in submissions.glob("*.ipynb"):
        try:
            if stat.S_ISREG(path.lstat().st_mode):
                paths.append(path)
        except OSError:
            continue
    return sorted(paths, key=lambda p: os.fsencode(p.name))


def _read_text(path: Path) -> str:
    """A submission's text, opened without following a link or waiting on a pipe swapped in."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    fd = os.open(path, flags)
    with open(fd, "rb") as file:
        if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
            raise ValueError("not a regular file")
        return file.read().decode("utf-8")


def _read_submission(path: Path, chapter: int):
    """The notebook, or a (status, detail) pair saying why it is not run."""
    import nbformat
    try:
        nb = nbformat.reads(_read_text(path), as_version=4)
        nbformat.validate(nb)
    except Exception as error:  # any unreadable file becomes a row, never stops the grading
        return ("invalid notebook", f"{type(error).__name__}: {str(error).splitlines()[0][:200]}")
    said = _chapter_of(nb)
    if said is not None and said != chapter:
        return ("wrong chapter", f"the notebook is chapter {said}, the grading is for chapter {chapter}")
    return nb


def _kernel_env(answers: Path) -> dict:
    """What a kernel is told beyond its environment: where its answers go."""
    return {ANSWERS_ENV: str(answers)}


def _package_root() -> Path:
    """The folder that holds the ``coursekit`` package the grader runs (the kernels import it too)."""
    import coursekit
    return Path(coursekit.__file__).resolve().parents[1]


def _stop(process: subprocess.Popen) -> None:
    """Stop a runner and whatever it started in its process group."""
    try:
        if hasattr(os, "killpg"):
            os.killpg(process.pid, signal.SIGKILL)
        else:
            process.kill()
    except OSError:
        pass                                      # ended already
    process.wait()


@dataclass(frozen=True)
class _Run:
    """The settings of one grading run that every notebook shares."""

    chapter: int
    exercises: tuple            # the chapter's exercises, fetched once for the whole run
    timeout: float
    memory: int
    folder: Path                    # the run's temporary folder: one sub-folder per submission
    hidden: tuple[Path, ...]        # folders no kernel may see
    sandboxed: bool

    def sandbox(self, box: Path, answers: Path) -> Sandbox:
        return Sandbox(box=box, package_root=_package_root(), hidden=self.hidden, env=_kernel_env(answers))

    def kernel_argv(self, box: Path, answers: Path) -> list[str]:
        argv = kernel_argv(self.memory, int(self.timeout) + 30)
        return self.sandbox(box, answers).command(argv) if self.sandboxed else argv


def _run_notebook(nb, number: int, run: _Run, checks: list[str]) -> tuple[str, str, list[dict], dict[str, dict]]:
    """Execute `nb` in a sandbox of its own; (status, detail, cell errors, last answer to each of `checks`)."""
    own = run.folder / str(number)
    box, private = own / "box", own / "runner"       # the kernel's only writable folder; the runner's
    box.mkdir(parents=True)
    private.mkdir()
    notebook = private / "submission.ipynb"
    write_notebook(nb, notebook)
    answers, work = box / "answers.jsonl", box / "submission"
    answers.touch()
    work.mkdir()
    if run.sandboxed:
        run.sandbox(box, answers).prepare()
    job = {"notebook": str(notebook), "cwd": str(work), "timeout": run.timeout, "memory": run.memory,
           "kernel_argv": run.kernel_argv(box, answers),
           "connection_file": str(box / "kernel.json") if run.sandboxed else None}
    env = {**os.environ, **({} if run.sandboxed else _kernel_env(answers))}
    with open(answers, encoding="utf-8", errors="replace") as held:  # still readable if the notebook deletes it
        outcome = _execute(private / "job.json", job, env)
        last = read_last_records(held, checks)
    return outcome["status"], outcome["detail"], outcome["errors"], last


def _temp_root() -> str | None:
    """Where the grader's temp folder goes: the user's temp folder (None), unless a sandboxed kernel's
    IPC sockets in it ("/coursekit-grade-XXXXXXXX/N/box/ipc-NNNNN", about 50 bytes more) would pass a
    Unix socket's 107 bytes ("File name too long": the kernel dies); then /tmp."""
    return None if len(tempfile.gettempdir()) + 50 <= 107 else "/tmp"


def _execute(job_file: Path, job: dict, env: dict) -> dict:
    """Run the notebook's runner; its outcome, accepted only in the runner's own form."""
    job_file.write_text(json.dumps(job), encoding="utf-8")
    command = [sys.executable, "-m", "coursekit.tools.grading.runner", str(job_file)]
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(_package_root()), env.get("PYTHONPATH")) if p)
    process = subprocess.Popen(command, cwd=job_file.parent, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True,
                               errors="replace", start_new_session=True)
    try:
        out, _ = process.communicate(timeout=job["timeout"] + _GRACE)
    except subprocess.TimeoutExpired:
        _stop(process)
        return {"status": "timeout", "detail": f"stopped at the time limit of {job['timeout']:g} s", "errors": []}
    return _runner_outcome(out, process.returncode)


def _runner_outcome(out: str, returncode) -> dict:
    """The outcome the runner printed last, checked field by field; a crash otherwise."""
    crashed = {"status": "crashed", "detail": f"the notebook's runner ended without an outcome "
                                              f"(exit status {returncode})", "errors": []}
    try:
        outcome = json.loads(out.strip().splitlines()[-1])
    except (IndexError, ValueError, RecursionError):
        return crashed
    if not (isinstance(outcome, dict) and outcome.get("status") in RUNNER_STATUSES
            and isinstance(outcome.get("detail"), str) and isinstance(outcome.get("errors"), list)):
        return crashed
    errors = [e for e in outcome["errors"] if isinstance(e, dict) and isinstance(e.get("cell"), int)
              and isinstance(e.get("ename"), str) and isinstance(e.get("evalue"), str)]
    return {"status": outcome["status"], "detail": outcome["detail"][:500], "errors": errors}


def _check_again(check, arguments: dict) -> tuple[bool, str]:
    """Run the course's own check on a recorded answer: (correct, the feedback it gave).

    The feedback is caught with `feedback_to`, in this thread only, so checks
    of other students running at the same time keep theirs apart.
    """
    printed = io.StringIO()
    try:
        with feedback_to(printed):
            result = check(**{name: decode(value) for name, value in arguments.items()})
        return bool(result), printed.getvalue().strip()
    except Exception as error:  # an answer the check cannot take is a wrong answer, with the reason
        return False, f"this answer could not be checked: {type(error).__name__}: {str(error)[:500]}"


#: the feedback of an exercise no answer was recorded for
NOT_ANSWERED = ("Not answered: no answer to this exercise reached the course's check while the notebook "
                "ran (its check was not run, was run only with the untouched placeholder, or was replaced "
                "in the notebook).")


def grade_answers(last: dict[str, dict], exercises) -> tuple[dict[str, int], dict[str, str]]:
    """Scores and feedback per exercise of `exercises` from the last answer recorded for each
    check (``{check: arguments}``, as `read_last_records` gives)."""
    from ... import exercises as course
    scores, feedback = {}, {}
    for entry in exercises:
        if entry.check not in last:
            scores[entry.check], feedback[entry.check] = 0, NOT_ANSWERED
            continue
        check = getattr(course, entry.check).__wrapped__
        correct, text = _check_again(check, last[entry.check])
        scores[entry.check], feedback[entry.check] = int(correct), text
    return scores, feedback


def _later_exercises(nb, cell: int, exercises) -> list[str]:
    """The labels of the exercises whose checks are called in the cells after `cell` (from 1)."""
    code = "\n".join(c.source for c in nb.cells[cell:] if c.cell_type == "code")
    return [entry.label for entry in exercises if re.search(rf"\b{entry.check}\s*\(", code)]


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def _error_lines(nb, errors: list[dict], exercises) -> list[str]:
    """One line per cell that raised: which cell, the error, and the exercises after it."""
    lines = []
    for error in errors:
        later = _later_exercises(nb, error["cell"], exercises)
        after = (f"; exercises after it: {', '.join(later)} (their answers count when their cells ran)"
                 if later else "")
        message = f": {error['evalue']}" if error["evalue"] else ""
        lines.append(f"- cell {error['cell']} (the {_ordinal(error['cell'])} cell from the top) raised "
                     f"{error['ename']}{message}{after}")
    return lines


def _grade_one(path: Path, number: int, run: _Run) -> Outcome:
    student, exercises = student_id(path), run.exercises
    try:
        read = _read_submission(path, run.chapter)
        if isinstance(read, tuple):
            (status, detail), last = read, {}
        else:
            status, detail, errors, last = _run_notebook(read, number, run, [e.check for e in exercises])
            detail = "\n".join([detail, *_error_lines(read, errors, exercises)])
        scores, feedback = grade_answers(last, exercises)
    except Exception as error:  # the grade book is written whatever happens to one notebook
        status, detail = "grader error", f"{type(error).__name__}: {str(error)[:500]}"
        scores, feedback = grade_answers({}, exercises)
    return Outcome(student, status, detail, scores, feedback)


def _feedback_text(outcome: Outcome, exercises) -> str:
    total = sum(outcome.scores.values())
    detail, *more = outcome.detail.split("\n")
    meaning = STATUSES[outcome.status]
    status = f"{detail}." if detail == meaning else f"{detail} ({meaning})."
    lines = [f"# Feedback for {outcome.student}: chapter {exercises[0].chapter}", "",
             f"Status: **{outcome.status}**: {status}", *more, "", f"Score: {total} of {len(outcome.scores)}", ""]
    for entry in exercises:
        text = outcome.feedback[entry.check].replace("```", "` ` `")      # cannot close the fence
        lines += [f"## Exercise {entry.label}: {entry.title} (`{entry.check}`): {outcome.scores[entry.check]}",
                  "", "```text", text, "```", ""]
    return "\n".join(lines)


def _spreadsheet_safe(text: str) -> str:
    """`text` as a CSV cell that no spreadsheet runs as a formula (a leading quote where needed)."""
    return f"'{text}" if text.startswith(_FORMULA) else text


def _feedback_names(outcomes: list[Outcome]) -> list[str]:
    """A file name per outcome: its student id, made distinct where two ids would clash."""
    names, seen = [], set()
    for outcome in outcomes:
        base = outcome.student or "_"
        name, n = base, 1
        while name.casefold() in seen:
            n += 1
            name = f"{base}~{n}"
        seen.add(name.casefold())
        names.append(name)
    return names


def _write(outcomes: list[Outcome], exercises, out: Path) -> Path:
    checks = [entry.check for entry in exercises]
    feedback_dir = out / "feedback"
    feedback_dir.mkdir(parents=True, exist_ok=True)
    for old in feedback_dir.glob("*.md"):
        old.unlink()
    for outcome, name in zip(outcomes, _feedback_names(outcomes)):
        (feedback_dir / f"{name}.md").write_text(_feedback_text(outcome, exercises), encoding="utf-8")
    table = out / "grades.csv"
    with open(table, "w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file, lineterminator="\n")
        writer.writerow(["student", *checks, "total", "status"])
        for o in outcomes:
            writer.writerow([_spreadsheet_safe(o.student), *(o.scores[c] for c in checks),
                             sum(o.scores.values()), o.status])
    return table


def _require_tools() -> None:
    """RuntimeError naming the extra to install when nbformat, nbclient or ipykernel is missing."""
    import importlib.util
    missing = [name for name in ("nbformat", "nbclient", "ipykernel") if importlib.util.find_spec(name) is None]
    if missing:
        raise RuntimeError(f"grading needs {', '.join(missing)}: install the grade extra, "
                           "python -m pip install \"coursekit[grade]\" (or -e \".[grade]\" in the repository)")


def _check_arguments(submissions: Path, out: Path, chapter, timeout, jobs) -> tuple:
    """The exercises of `chapter`, once every argument is checked."""
    exercises = tuple(chapter_exercises(chapter))
    if not submissions.is_dir():
        raise ValueError(f"submissions: {submissions} is not a folder; pass the folder of submitted notebooks")
    if out.resolve() == submissions.resolve():
        raise ValueError("out must be another folder than submissions (the feedback would mix with them)")
    if not (isinstance(timeout, (int, float)) and timeout > 0):
        raise ValueError(f"timeout must be a positive number of seconds, received {timeout!r}")
    if not (isinstance(jobs, int) and jobs >= 1):
        raise ValueError(f"jobs must be a whole number of at least 1, received {jobs!r}")
    return exercises


def _sealed(run: _Run) -> None:
    """Try the sandbox once before grading (SandboxUnavailable, saying what to do, if it fails)."""
    probe = run.folder / "probe"
    probe.mkdir()
    try:
        check_sandbox(run.sandbox(probe, probe / "answers.jsonl"))
    except SandboxUnavailable as error:
        raise SandboxUnavailable(f"{error}. Without the sandbox each notebook runs with your rights: pass "
                                 "--no-sandbox (sandbox=False) to accept that, or grade inside a container "
                                 "(docs/grading.md)") from None


def grade(submissions, out, *, chapter: int, timeout: float = 300, memory: int | str = "4G",
          jobs: int | None = None, sandbox: bool = True) -> Path:
    """Grade every ``*.ipynb`` of `submissions` for `chapter`; returns the path of ``grades.csv``.

    `timeout` is in seconds per notebook, `memory` the kernel's address-space
    limit (bytes or "4G"), `jobs` how many notebooks run at once (default: the
    number of cores). Each notebook runs in the bubblewrap sandbox; where it
    cannot, `SandboxUnavailable` is raised, unless `sandbox` is False, which
    runs the notebooks with your own rights. See the module docstring for
    what is written to `out`.
    """
    submissions, out = Path(submissions), Path(out)
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    exercises = _check_arguments(submissions, out, chapter, timeout, jobs)
    _require_tools()
    memory = parse_memory(memory) if isinstance(memory, str) else int(memory)
    paths = _submission_paths(submissions)
    # a notebook may leave files it made unremovable: that must not cost it its grades
    with tempfile.TemporaryDirectory(prefix="coursekit-grade-", dir=_temp_root(), ignore_cleanup_errors=True) as folder:
        hidden = tuple(Path(p).resolve() for p in (submissions, out, folder, Path.cwd()))
        run = _Run(chapter, exercises, float(timeout), memory, Path(folder), hidden, bool(sandbox))
        if run.sandboxed:
            _sealed(run)
        with warnings.catch_warnings(), ThreadPoolExecutor(max_workers=jobs) as pool:
            warnings.simplefilter("ignore")      # the checks' warnings say nothing their feedback does not
            outcomes = list(pool.map(lambda item: _grade_one(item[1], item[0], run), enumerate(paths)))
    out.mkdir(parents=True, exist_ok=True)
    return _write(outcomes, exercises, out)
