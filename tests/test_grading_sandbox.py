"""The grader against hostile submissions: each notebook sealed off, its answers read as data.

One grading run (bubblewrap sandbox, two notebooks at a time) of a class folder where one
honest student (``victim``, every exercise right) sits among notebooks that attack the
grader, the instructor's machine and the other students, and honest answers that the
recorder once lost. Every attack must leave the victim's row, the grade book, the
submissions and the grader's working folder as they should be, and get its own row right.
Skipped where bubblewrap cannot run (the grader then refuses to grade without
``--no-sandbox``, which `test_without_bwrap_the_grader_refuses_in_one_line` checks
everywhere).
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import socket
import sys
import threading
import uuid
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_notebook, new_output

from coursekit.__main__ import main
from coursekit.exercises._catalog import chapter_exercises
from coursekit.tools.grading import sandbox as sandbox_module
from coursekit.tools.grading import SandboxUnavailable, grade
from coursekit.tools.notebooks import default_notebook_dir, read_notebook
from grading_cases import SANDBOX, answer, solved

CHECKS = [entry.check for entry in chapter_exercises(1)]
TIMEOUT = 20


needs_bwrap = pytest.mark.skipif(not SANDBOX, reason="bubblewrap (bwrap) is missing or cannot make "
                                 "namespaces here: apt-get install bubblewrap")


class Listener:
    """A TCP server on loopback that counts the connections it is offered."""

    def __init__(self):
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.connections = 0
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                connection, _ = self.server.accept()
            except OSError:
                return
            self.connections += 1
            connection.close()


def _attacks(places: dict) -> dict[str, list[str]]:
    """The hostile notebooks' code cells (after the heading and the imports)."""
    victim, out, cwd = (repr(str(places[k])) for k in ("victim", "out", "cwd"))
    marker, token, port = repr(str(places["marker"])), places["token"], places["port"]
    write_all = (f"import pathlib\nfor target in ({victim}, {out} + '/grades.csv', {out} + '/feedback/victim.md', "
                 f"{cwd} + '/pwned.txt'):\n    try:\n        pathlib.Path(target).write_text('hacked')\n"
                 "    except OSError:\n        pass")
    daemon = ("import subprocess, sys\ncode = '''import pathlib, sys, time\nfor _ in range(300):\n"
              + "\n".join("    " + line for line in write_all.splitlines()) +
              "\n    time.sleep(0.2)'''\n"
              f"subprocess.Popen([sys.executable, '-c', code, {token!r}], start_new_session=True,\n"
              "                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)")
    code = f"__import__('pathlib').Path({marker}).touch() or 1"
    forged_line = json.dumps({"check": "check_msd_state_space",
                              "args": {"A": {"sympy_matrix": [[code]]}, "B": [[0], [0.5]], "C": [[1, 0]]}})
    bomb = "json.dumps({'check': 'check_compartment_state_space', 'args': {'A': [{}] * 250_000, 'B': 0, 'C': 0}})"
    return {
        "daemon": [daemon],
        "writer": [write_all],
        "reader": [f"import os\nseen = os.path.exists({victim})\nA = [[0, 1], [-4, -0.2]] if seen else None\n"
                   "ex.check_msd_state_space(A, [[0], [0.5]], [[1, 0]])"],
        "killer": ["import os, signal\nos.kill(os.getppid(), signal.SIGKILL)"],
        "forger": ["import os\nline = '\\n{\"status\": \"ok\", \"detail\": \"forged\", \"errors\": []}\\n'\n"
                   "try:\n    open(f'/proc/{os.getppid()}/fd/1', 'w').write(line)\nexcept OSError:\n    pass\n"
                   "os.kill(os.getppid(), 9)", "raise ValueError('after the forgery')"],
        "network": [f"import socket\ntry:\n    socket.create_connection(('127.0.0.1', {port}), timeout=3)\n"
                    "except OSError as error:\n    print('no network:', error)"],
        "forged": ["import json, os\nwith open(os.environ['COURSEKIT_ANSWERS_FILE'], 'a') as file:\n"
                   f"    file.write({forged_line!r} + '\\n')\n"
                   f"    file.write({bomb} + '\\n')"],
        "flood": ["import os, json\nwrong = json.dumps({'check': 'check_msd_state_space', 'args': {'A': [[1]], "
                  "'B': [[1]], 'C': [[1]]}})\nwith open(os.environ['COURSEKIT_ANSWERS_FILE'], 'a') as file:\n"
                  "    file.write((wrong + '\\n') * 10_001)\n    file.write(('x' * 2**20 + '\\n') * 65)"],
    }


def _honest(right) -> dict[str, list]:
    """Right answers in the forms the recorder once lost or changed."""
    msd = answer(right, CHECKS[0])[0].source
    return {
        "killer": [answer(right, CHECKS[1])[0].source],        # answered after the kill
        "matrix": [msd.replace("ex.check_msd_state_space(A, B, C)",
                               "ex.check_msd_state_space(np.matrix(A), np.matrix(B), np.matrix(C))")],
        "flood": [msd],                      # after the flood of wrong records and junk
    }


def _write(folder: Path, name, cells, metadata) -> None:
    nbformat.write(new_notebook(cells=cells, metadata=metadata), folder / name)


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    base = tmp_path_factory.mktemp("class")
    folder, out, cwd = base / "submissions", base / "grades", base / "instructor"
    folder.mkdir(), cwd.mkdir()
    listener = Listener()
    places = {"victim": folder / "victim.ipynb", "out": out, "cwd": cwd, "marker": base / "ran-in-grader",
              "token": f"coursekit-daemon-{uuid.uuid4().hex}", "port": listener.port}
    instructor = read_notebook(default_notebook_dir() / "01_representations.ipynb")
    right = solved(instructor)
    heading, setup = right[0], new_code_cell("import numpy as np\nimport coursekit.exercises as ex")
    honest = _honest(right)
    _write(folder, "victim.ipynb", right, instructor.metadata)
    attacks = _attacks(places)
    for name in {**attacks, **honest}:
        sources = attacks.get(name, []) + honest.get(name, [])
        _write(folder, f"{name}.ipynb", [heading, setup, *map(new_code_cell, sources)], instructor.metadata)
    stale = new_code_cell("")                                          # empty, with an error saved from before
    stale.outputs = [new_output("error", ename="NameError", evalue="old", traceback=[])]
    _write(folder, "stale.ipynb", [heading, setup, stale, *answer(right, CHECKS[4])], instructor.metadata)
    _write(folder, os.fsdecode(b"caf\xe9.ipynb"), [heading, setup, *answer(right, CHECKS[2])], instructor.metadata)
    (folder / "=HYPERLINK(1).ipynb").write_text("{", encoding="utf-8")
    (folder / "link.ipynb").symlink_to(folder / "victim.ipynb")
    os.mkfifo(folder / "fifo.ipynb")
    before = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir()
              if p.is_file() and not p.is_symlink()}
    start = Path.cwd()
    os.chdir(cwd)
    try:
        grade(folder, out, chapter=1, timeout=TIMEOUT, memory="2G", jobs=2)
    finally:
        os.chdir(start)
    return {"folder": folder, "out": out, "cwd": cwd, "places": places, "before": before, "listener": listener}


def _rows(out: Path) -> dict[str, dict]:
    with open(out / "grades.csv", newline="", encoding="utf-8") as file:
        return {row["student"]: row for row in csv.DictReader(file)}


def _scores(row) -> list[int]:
    return [int(row[check]) for check in CHECKS]


@needs_bwrap
def test_the_honest_student_keeps_every_point_among_the_attacks(graded):
    row = _rows(graded["out"])["victim"]
    assert (row["status"], _scores(row)) == ("ok", [1] * 5)
    feedback = (graded["out"] / "feedback" / "victim.md").read_text(encoding="utf-8")
    assert feedback.count("Correct:") == 5 and "hacked" not in feedback


@needs_bwrap
def test_nothing_outside_its_box_is_written_read_or_left_running(graded):
    folder, cwd = graded["folder"], graded["cwd"]
    after = {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir()
             if p.is_file() and not p.is_symlink()}
    assert after == graded["before"]                                  # no submission changed
    assert list(cwd.iterdir()) == []                                  # nothing in the grader's working folder
    assert "hacked" not in (graded["out"] / "grades.csv").read_text(encoding="utf-8")
    token = graded["places"]["token"].encode()
    alive = [pid for pid in os.listdir("/proc") if pid.isdigit() and _cmdline_has(pid, token)]
    assert alive == []                                                # the daemon ended with its sandbox
    assert graded["listener"].connections == 0                        # no network
    rows = _rows(graded["out"])
    assert _scores(rows["reader"])[0] == 0                            # the victim's notebook was not there


def _cmdline_has(pid: str, token: bytes) -> bool:
    try:
        return token in Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False


@needs_bwrap
@pytest.mark.parametrize("student, status, scores", [
    ("daemon", "ok", [0] * 5),
    ("writer", "ok", [0] * 5),
    ("killer", "ok", [0, 1, 0, 0, 0]),        # its parent is the sandbox's own init: the kernel lives on
    ("forger", "cell error", [0] * 5),        # the runner's output is out of its reach
    ("network", "ok", [0] * 5),
    ("forged", "ok", [0] * 5),                # code in the answers file is not run, the bomb costs nothing
    ("flood", "ok", [1, 0, 0, 0, 0]),         # the last answer counts behind 10,001 records and 65 MiB
    ("matrix", "ok", [1, 0, 0, 0, 0]),        # np.matrix is an answer like any array
    ("stale", "ok", [0, 0, 0, 0, 1]),         # an error saved with the file is not this run's
    ("caf\\xe9", "ok", [0, 0, 1, 0, 0]),       # a file name that is not UTF-8
    ("'=HYPERLINK(1)", "invalid notebook", [0] * 5),
])
def test_each_submission_gets_its_own_row(graded, student, status, scores):
    row = _rows(graded["out"])[student]
    assert (row["status"], _scores(row)) == (status, scores)


@needs_bwrap
def test_links_and_special_files_are_not_graded_and_code_never_ran_in_the_grader(graded):
    rows = _rows(graded["out"])
    assert "link" not in rows and "fifo" not in rows
    assert not graded["places"]["marker"].exists()
    forged = (graded["out"] / "feedback" / "forged.md").read_text(encoding="utf-8")
    assert forged.count("Not yet") == 2 and "received MutableDenseMatrix" in forged   # checked as data


@needs_bwrap
def test_a_cell_error_names_the_cell_the_message_and_the_exercises_after_it(graded):
    feedback = (graded["out"] / "feedback" / "forger.md").read_text(encoding="utf-8")
    assert "cell 4 (the 4th cell from the top) raised ValueError: after the forgery" in feedback
    assert "forged" not in feedback.split("Score:")[0].replace("after the forgery", "")


def test_without_bwrap_the_grader_refuses_in_one_line(tmp_path, monkeypatch, capsys):
    (tmp_path / "subs").mkdir()
    monkeypatch.setattr(sandbox_module, "find_bwrap", lambda: None)
    with pytest.raises(SandboxUnavailable, match="bubblewrap.*--no-sandbox"):
        grade(tmp_path / "subs", tmp_path / "out", chapter=1)
    with pytest.raises(SystemExit) as stopped:
        main(["grade", "--chapter", "1", str(tmp_path / "subs"), "--out", str(tmp_path / "out")])
    assert stopped.value.code == 2
    said = capsys.readouterr().err.strip().splitlines()
    assert len(said) == 1 and "--no-sandbox" in said[0]
    assert not (tmp_path / "out").exists()
    table = grade(tmp_path / "subs", tmp_path / "out", chapter=1, sandbox=False)
    assert table.exists()


def test_the_sandbox_never_shows_the_home_or_working_folder(tmp_path, monkeypatch):
    """Folders on sys.path are shown read-only, but never the home or the working folder
    (``python -m`` puts the latter on sys.path), and a hidden folder inside a shown one is covered."""
    from coursekit.tools.grading.sandbox import Sandbox
    monkeypatch.chdir(tmp_path)
    for entry in (str(Path.home()), str(tmp_path), "/"):
        monkeypatch.syspath_prepend(entry)
    inside = Path(sys.prefix).resolve() / "hidden-inside-python"
    args = Sandbox(box=tmp_path / "box", package_root=Path("/nowhere"), hidden=(inside,)).command(["true"])
    shown = {args[i + 1] for i, flag in enumerate(args) if flag in ("--ro-bind", "--bind", "--ro-bind-try")}
    assert str(Path.home().resolve()) not in shown and str(tmp_path.resolve()) not in shown and "/" not in shown
    assert str(Path(sys.prefix).resolve()) in shown and str((tmp_path / "box").resolve()) in shown
    assert args[args.index(str(inside)) - 1] == "--tmpfs"
    assert "--unshare-all" in args and "--die-with-parent" in args and "--clearenv" in args


def _processes_naming(text: str) -> list[str]:
    """The command lines of the processes whose command line holds `text`."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            line = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if text in line:
            found.append(line)
    return found


@needs_bwrap
def test_a_long_temp_folder_leaves_room_for_the_kernel_s_sockets(tmp_path):
    """A sandboxed kernel talks over Unix sockets in the grader's temp folder: under a temp folder
    whose path leaves them no room (108 bytes at most), the grader puts its own in /tmp."""
    import subprocess
    folder, scratch = tmp_path / "subs", tmp_path / ("t" * 70)
    folder.mkdir(), scratch.mkdir()
    _write(folder, "quick.ipynb", [new_code_cell("x = 1")], {})
    subprocess.run([sys.executable, "-m", "coursekit", "grade", "--chapter", "1", str(folder), "--out",
                    str(tmp_path / "out"), "--timeout", "60", "--jobs", "1"], env={**os.environ, "TMPDIR": str(scratch)},
                   check=True, capture_output=True)
    rows = list(csv.DictReader((tmp_path / "out" / "grades.csv").open(encoding="utf-8")))
    assert [row["status"] for row in rows] == ["ok"], rows


@needs_bwrap
def test_a_grader_stopped_midway_leaves_nothing_running(tmp_path):
    """Ctrl-C (here SIGKILL) on the grader ends its runners and their sandboxed kernels too."""
    import shutil
    import subprocess
    import tempfile
    import time
    # a short temp folder: the grader's own goes into it (not into /tmp), so its processes name it
    folder, scratch = tmp_path / "subs", Path(tempfile.mkdtemp(prefix="ck-stop-"))
    folder.mkdir()
    _write(folder, "sleeper.ipynb", [new_code_cell("import time\nwhile True:\n    time.sleep(0.1)")], {})
    grader = subprocess.Popen([sys.executable, "-m", "coursekit", "grade", "--chapter", "1", str(folder), "--out",
                               str(tmp_path / "out"), "--timeout", "120", "--jobs", "1"],
                              env={**os.environ, "TMPDIR": str(scratch)},
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 90
    while not any("ipykernel_launcher" in p for p in _processes_naming(str(scratch))):
        grades = tmp_path / "out" / "grades.csv"
        assert grader.poll() is None, f"the grader ended (exit {grader.returncode}) before its kernel was seen: " \
            + (grades.read_text(encoding="utf-8") if grades.exists() else "no grades written")
        assert time.monotonic() < deadline, "the kernel never started"
        time.sleep(0.2)
    grader.kill()
    grader.wait()
    deadline = time.monotonic() + 15
    while _processes_naming(str(scratch)) and time.monotonic() < deadline:
        time.sleep(0.2)
    left = _processes_naming(str(scratch))
    shutil.rmtree(scratch, ignore_errors=True)
    assert left == []
