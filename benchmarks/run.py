"""Benchmarks for coursekit: prints a markdown table of medians and ratios.

Run from the repository root (with the `dev` extra installed):

    python benchmarks/run.py            # everything
    python benchmarks/run.py --quick    # fewer repetitions, no notebooks
    python benchmarks/run.py --browser  # everything, plus the browser benchmark
    python benchmarks/run.py --browser-only   # only the browser benchmark (benchmarks/browser.py)
    python benchmarks/run.py --browser-only --busy   # and again beside two CPU-bound processes
    python benchmarks/run.py --grading        # everything, plus the grader (python -m coursekit grade)
    python benchmarks/run.py --grading-only   # only the grader benchmark
    python benchmarks/run.py --builds-only    # only the builds (site, student site, slides)

Each pair of competitors is timed in interleaved repetitions (a, b, a, b, ...)
so that drift in the machine's speed affects both alike; the table reports
medians. Nothing here is a test: targets are printed next to the measurements.
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def interleaved(funcs: dict, repeat: int) -> dict:
    """Median wall time of each function, calling them in turn `repeat` times."""
    times = {name: [] for name in funcs}
    for _ in range(repeat):
        for name, func in funcs.items():
            start = time.perf_counter()
            func()
            times[name].append(time.perf_counter() - start)
    return {name: statistics.median(values) for name, values in times.items()}


def ms(seconds: float) -> str:
    return f"{1e3 * seconds:.2f} ms"


def random_stable(n: int, seed: int):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A -= (np.abs(np.linalg.eigvals(A).real).max() + 0.5) * np.eye(n)
    return A, rng.normal(size=(n, 1)), rng.normal(size=(1, n))


def bench_simulate(repeat: int) -> list[str]:
    import control
    from scipy.signal import lsim
    import coursekit as ck
    rows = ["| states | coursekit `simulate` | python-control `forced_response` | scipy `lsim` "
            "| ratio to forced_response (target <= 0.1) | max difference |",
            "|---|---|---|---|---|---|"]
    t = np.linspace(0, 10, 10_001)
    for n in (4, 20):
        A, B, C = random_stable(n, seed=n)
        u = np.sin(t) + 0.1 * np.random.default_rng(0).normal(size=t.size)
        x0 = np.ones(n)
        ours, theirs = ck.StateSpace(A, B, C), control.ss(A, B, C, 0)
        med = interleaved({
            "ck": lambda: ck.simulate(ours, t, u, x0=x0),
            "control": lambda: control.forced_response(theirs, t, u, X0=x0, return_x=True),
            "lsim": lambda: lsim((A, B, C, 0), u, t, X0=x0),
        }, repeat)
        x_ck = ck.simulate(ours, t, u, x0=x0).x
        x_ct = control.forced_response(theirs, t, u, X0=x0, return_x=True).states.T
        x_ls = lsim((A, B, C, 0), u, t, X0=x0)[2]
        diff = max(np.abs(x_ck - x_ct).max(), np.abs(x_ck - x_ls).max())
        rows.append(f"| {n} | {ms(med['ck'])} | {ms(med['control'])} | {ms(med['lsim'])} "
                    f"| {med['ck'] / med['control']:.3f}{' (missed)' if med['ck'] > 0.1 * med['control'] else ''} "
                    f"| {diff:.1e} |")
    return rows


def bench_place(repeat: int) -> list[str]:
    import control
    from scipy.signal import place_poles
    import coursekit as ck
    rows = ["| n | coursekit `place` | python-control `place` | scipy `place_poles` | max rel. K difference |",
            "|---|---|---|---|---|"]
    for n in (3, 6, 10):
        rng = np.random.default_rng(n)
        A, B = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
        poles = -np.linspace(1, 3, n)
        med = interleaved({
            "ck": lambda: ck.place(A, B, poles),
            "control": lambda: control.place(A, B, poles),
            "scipy": lambda: place_poles(A, B, poles),
        }, repeat)
        K = ck.place(A, B, poles)
        K_ref = -np.atleast_2d(control.place(A, B, poles))
        rel = np.abs(K - K_ref).max() / np.abs(K_ref).max()
        rows.append(f"| {n} | {ms(med['ck'])} | {ms(med['control'])} | {ms(med['scipy'])} | {rel:.1e} |")
    return rows


def explorer_factories():
    """Every explorer of the course, found by `coursekit.tools.chapters` (a new chapter's too)."""
    from coursekit.tools.chapters import explorer_factories as found
    return found().items()


def slider_grid(explorer) -> list[dict]:
    """Every combination of each slider's minimum, middle, maximum and current value, and of
    every option of a dropdown."""
    choices = []
    for widget in explorer.controls.values():
        if hasattr(widget, "min"):
            middle = type(widget.value)((widget.min + widget.max) / 2)
            choices.append(sorted({widget.min, middle, widget.max, widget.value}))
        else:
            choices.append([o[1] if isinstance(o, tuple) else o for o in widget.options])
    return [dict(zip(explorer.controls, combo)) for combo in itertools.product(*choices)]


def redraw(explorer) -> None:
    """Compute and draw the explorer's figure for its current settings again, as for a setting
    not seen before (the results the explorer keeps are dropped first): a frame whose axes stay
    as they are (a blit)."""
    explorer._results.cache_clear()
    explorer.refresh()


def bench_explorers(repeat: int) -> list[str]:
    rows = ["| explorer | compute (target < 20 ms) | compute, slowest setting of the slider grid "
            "| settings over 20 ms | compute + redraw |", "|---|---|---|---|---|"]
    for label, factory in explorer_factories():
        explorer = factory()
        # compute is timed alone, as each setting of the grid is: timed in turn with a redraw it
        # ran after the drawing's garbage and cold caches, 1.5 to 5 times slower in CPU time, and
        # read above the slowest setting of the grid in 7 of 9 explorers
        med = {**interleaved({"compute": lambda: explorer._compute(**explorer.params)}, repeat),
               **interleaved({"refresh": lambda: redraw(explorer)}, repeat)}
        grid = slider_grid(explorer)
        slowest = [interleaved({"compute": lambda: explorer._compute(**params)}, 3)["compute"]
                   for params in grid]
        rows.append(f"| {label} | {ms(med['compute'])} | {ms(max(slowest))} "
                    f"| {sum(t > 0.020 for t in slowest)} of {len(grid)} | {ms(med['refresh'])} |")
    return rows


def imports_only(nb, modules=()):
    """A copy of the notebook holding only its top-level import lines (and %matplotlib),
    followed by an import of each of `modules`."""
    import copy
    import nbformat
    lines = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        for line in cell.source.splitlines():
            if line.startswith(("import ", "from ", "%matplotlib")):
                lines.append(line.strip())
    baseline = copy.deepcopy(nb)
    baseline.cells = [nbformat.v4.new_code_cell("\n".join(dict.fromkeys(lines)))]
    if modules:
        baseline.cells.append(nbformat.v4.new_code_cell(
            "import importlib\n"
            f"for name in {sorted(modules)!r}:\n"
            "    try:\n"
            "        importlib.import_module(name)\n"
            "    except Exception:\n"
            "        pass"))
    return baseline


# Prepended to the probe run: sums the time spent rendering figures, i.e. every Agg draw
# (inline figures and explorers alike) and every PNG encode, without changing what runs.
_TIME_RENDERING = """\
import time as _time
import matplotlib.image as _image
from matplotlib.backends.backend_agg import FigureCanvasAgg as _Agg
_rendering = [0.0]
def _timed(func):
    def wrapper(*args, **kwargs):
        start = _time.perf_counter()
        try:
            return func(*args, **kwargs)
        finally:
            _rendering[0] += _time.perf_counter() - start
    return wrapper
_Agg.draw, _image.imsave = _timed(_Agg.draw), _timed(_image.imsave)"""

_REPORT = ("import sys as _sys\n"
           "print(_rendering[0], *(m for m in _sys.modules if not any(p.startswith('_') for p in m.split('.'))))")


def probe(nb) -> tuple[set, float]:
    """Run the notebook once, instrumented, and return every public module it has imported by
    its end (lazily imported ones included: scipy.signal at the first pole placement, ...) and
    the seconds it spent rendering figures (Agg draws and PNG encoding)."""
    import copy
    import nbformat
    probe_nb = copy.deepcopy(nb)
    probe_nb.cells.insert(0, nbformat.v4.new_code_cell(_TIME_RENDERING))
    probe_nb.cells.append(nbformat.v4.new_code_cell(_REPORT))
    run_notebook(probe_nb, keep=True)
    rendering, *modules = "".join(out.get("text", "") for out in probe_nb.cells[-1].outputs).split()
    return set(modules), float(rendering)


def run_notebook(nb, keep: bool = False) -> None:
    """Execute a notebook in a fresh kernel, from the notebooks/ folder (in place if `keep`)."""
    import copy
    from nbclient import NotebookClient
    client = NotebookClient(nb if keep else copy.deepcopy(nb), timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(ROOT / "notebooks")}})
    client.execute()


def bench_notebooks(repeat: int) -> list[str]:
    """Each notebook against two floors: its own import lines, and the same import lines plus
    every module the full run ends up importing (the heavy SciPy submodules, sympy and
    ipywidgets load lazily, inside the coursekit functions that need them). The last two
    columns show how much of the budget matplotlib alone takes: the time one instrumented run
    spends drawing and encoding its figures, and the ratio a run would reach if that were all it
    did beyond the second floor (no computation, no cell overhead)."""
    import nbformat
    rows = ["| notebook | full run | import lines only | ratio | all modules it imports "
            "| ratio (target <= 2) | figure rendering (one run) | (all modules + rendering) / all modules |",
            "|---|---|---|---|---|---|---|---|"]
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        modules, rendering = probe(nb)
        lines_only, all_imports = imports_only(nb), imports_only(nb, modules)
        med = interleaved({"full": lambda: run_notebook(nb),
                           "lines": lambda: run_notebook(lines_only),
                           "modules": lambda: run_notebook(all_imports)}, repeat)
        rows.append(f"| {path.name} | {med['full']:.1f} s | {med['lines']:.1f} s "
                    f"| {med['full'] / med['lines']:.2f} | {med['modules']:.1f} s "
                    f"| {med['full'] / med['modules']:.2f} | {rendering:.1f} s "
                    f"| {(med['modules'] + rendering) / med['modules']:.2f} |")
    return rows


def bench_import(repeat: int) -> list[str]:
    code = ("import time; t = time.perf_counter(); import {mod}; "
            "print(time.perf_counter() - t)")

    def measure(mod):
        out = subprocess.run([sys.executable, "-c", code.format(mod=mod)], capture_output=True,
                             text=True, check=True, cwd=ROOT)
        return float(out.stdout)

    samples = {"numpy": [], "coursekit": []}
    for _ in range(repeat):
        for mod in samples:
            samples[mod].append(measure(mod))
    med = {mod: statistics.median(v) for mod, v in samples.items()}
    return ["| `import` in a fresh interpreter | median |", "|---|---|",
            f"| numpy | {ms(med['numpy'])} |",
            f"| coursekit (includes numpy; target < 500 ms) | {ms(med['coursekit'])} |"]


def bench_browser(steps: int, shots: Path | None = None, only: list[str] | None = None,
                  busy: bool = False) -> list[str]:
    """Each explorer and the trivial-interact floor in JupyterLab + headless Chromium (see
    benchmarks/browser.py), beside CPU-bound processes when `busy`; an explorer is light when
    its compute + redraw, timed here, is at most browser.LIGHT_MS."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import browser
    browser.require_browser()
    factories = {label: f for label, f in explorer_factories() if not only or label in only}
    kernel_ms = {}
    for label, factory in factories.items():
        explorer = factory()
        kernel_ms[label] = 1e3 * interleaved({"refresh": lambda: redraw(explorer)}, 11)["refresh"]
    return browser.run_browser(list(factories), kernel_ms, steps=steps, shots=shots, busy=busy,
                               log=lambda line: print(line, file=sys.stderr))


#: what each section measures, for docs/performance.md
ABOUT = {
    "simulate": "coursekit's exact LTI simulation against python-control and SciPy on the same input.",
    "place": "Pole placement against python-control and SciPy, and how far the gains differ.",
    "explorers": "Each explorer's compute function, and compute + redraw of its figure (a blit when "
                 "the axes stay), timed in the kernel without a browser.",
    "import time": "`import coursekit` in a fresh interpreter.",
    "notebooks": "Each chapter notebook run top to bottom against two floors: its import lines alone, "
                 "and every module it ends up importing.",
    "browser": "What a student feels in JupyterLab + headless Chromium (`benchmarks/browser.py`): a "
               "keyboard step of the first slider against the trivial `interact` floor measured in the "
               "same session, and the figures painted per second while dragging it, right after Run All "
               "(first drag) and again after the steps. An explorer is light when its kernel compute + "
               "redraw is at most 25 ms. The last column shows where a drag's CPU goes: headless "
               "Chromium without a GPU spends most of a core on the drag itself (the floor's row: a "
               "slider and a small image), which on 2 cores bounds every row. Targets relative to the "
               "floor of the same run: step at most 1.0 times, first drag at least 1.0 times its "
               "figures per second (1.3 times for a light explorer).",
    "browser, busy machine": "The browser benchmark again with two CPU-bound processes (a Python loop "
               "each) running beside the browser and the kernel, as when a class shares one server: each "
               "explorer's drags, the first and the one after the steps, must paint at least as often as "
               "the trivial `interact` floor in the same run (the other targets as above).",
    "grading": "`python -m coursekit grade` on copies of chapter 1's student edition: notebooks graded per "
               "minute with two at a time against one at a time, grading one notebook in the bubblewrap "
               "sandbox against the same without it (`--no-sandbox`), and against a plain "
               "`jupyter nbconvert --execute` of it (all start a fresh kernel).",
    "builds": "The instructor's builds of the whole course, each a fresh `python -m coursekit` process: the "
              "website's two editions from one execution of the notebooks (`site --out A --student-out B`) "
              "against each edition built alone, and the slides.",
}


def write_docs(path: Path, command: str, report: list[list[str]]) -> None:
    """docs/performance.md: each section of this run (`report`: its lines, heading first) in place
    of the file's section of the same title, saying the command and date that measured it; the
    sections this run did not measure stay as they were."""
    import datetime

    def title(heading: str) -> str:
        return heading.split(" (median of")[0]

    kept: dict = {}
    if path.exists():
        for chunk in path.read_text(encoding="utf-8").split("\n## ")[1:]:
            lines = ("## " + chunk).rstrip("\n").split("\n")
            kept[title(lines[0])] = lines + [""]
    stamp = (f"Measured by `{command}` on {datetime.date.today().isoformat()}, {os.cpu_count()} cores, "
             f"Python {sys.version.split()[0]}, numpy {np.__version__}.")
    for lines in report:
        kept[title(lines[0])] = [lines[0], "", stamp, *lines[1:]]
    head = ["# Performance", "",
            "Written by `benchmarks/run.py` (do not edit by hand): `--docs` writes again the sections its "
            "run measured, each saying the command and date that measured it, and keeps the others. "
            "Competitors are timed in interleaved repetitions and reported as medians; speed is judged "
            "by the ratios, which hold across machines better than the times.", ""]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(head + [line for lines in kept.values() for line in lines]).rstrip("\n") + "\n",
                    encoding="utf-8")


def _student_submissions(folder: Path, count: int) -> Path:
    """`count` copies of chapter 1's student edition in `folder` (student ids s01, s02, ...)."""
    from coursekit.tools.notebooks import read_notebook, write_notebook
    from coursekit.tools.release import student_edition
    nb = student_edition(read_notebook(ROOT / "notebooks" / "01_representations.ipynb"))
    folder.mkdir(parents=True, exist_ok=True)
    for i in range(1, count + 1):
        write_notebook(nb, folder / f"s{i:02d}.ipynb")
    return folder


def _nbconvert(path: Path, out: Path) -> None:
    subprocess.run([sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute",
                    str(path), "--output-dir", str(out)], check=True, capture_output=True, cwd=path.parent)


def bench_grading(repeat: int, count: int = 6) -> list[str]:
    """The grader on copies of chapter 1's student edition: notebooks graded per minute with two
    at a time against one at a time, and the time to grade one notebook in the sandbox against
    the same without it and against a plain ``jupyter nbconvert --to notebook --execute`` of it
    (all start a fresh kernel)."""
    import tempfile
    from coursekit.tools.grading import grade
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        many, one = _student_submissions(tmp / "many", count), _student_submissions(tmp / "one", 1)
        med = interleaved({"jobs 1": lambda: grade(many, tmp / "g1", chapter=1, jobs=1),
                           "jobs 2": lambda: grade(many, tmp / "g2", chapter=1, jobs=2),
                           "grade one": lambda: grade(one, tmp / "g", chapter=1, jobs=1),
                           "no sandbox": lambda: grade(one, tmp / "u", chapter=1, jobs=1, sandbox=False),
                           "nbconvert": lambda: _nbconvert(one / "s01.ipynb", tmp / "nbconvert")}, repeat)
    per_minute = {jobs: 60 * count / med[jobs] for jobs in ("jobs 1", "jobs 2")}
    load = os.getloadavg()[1] if hasattr(os, "getloadavg") else float("nan")
    return ["| measure | value | target |", "|---|---|---|",
            f"| machine load average (5 min) at the end, {os.cpu_count()} cores | {load:.1f} | |",
            f"| notebooks graded per minute, --jobs 1 ({count} notebooks) | {per_minute['jobs 1']:.1f} | |",
            f"| notebooks graded per minute, --jobs 2 | {per_minute['jobs 2']:.1f} | |",
            f"| speed-up --jobs 2 / --jobs 1 | {per_minute['jobs 2'] / per_minute['jobs 1']:.2f} | >= 1.6 |",
            f"| grading one notebook (sandboxed) | {med['grade one']:.1f} s | |",
            f"| the same with --no-sandbox | {med['no sandbox']:.1f} s | |",
            f"| sandboxed / not sandboxed | {med['grade one'] / med['no sandbox']:.2f} | <= 1.15 |",
            f"| jupyter nbconvert --execute of it | {med['nbconvert']:.1f} s | |",
            f"| grader / nbconvert | {med['grade one'] / med['nbconvert']:.2f} | <= 1.3 |"]


def _command(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "coursekit", *args], check=True, capture_output=True, cwd=ROOT)


def bench_builds(repeat: int) -> list[str]:
    """Seconds per build of the course: both site editions from one execution, each alone, the slides."""
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        med = interleaved({
            "both": lambda: _command("site", "--out", f"{tmp}/a", "--student-out", f"{tmp}/b"),
            "site": lambda: _command("site", "--out", f"{tmp}/a"),
            "student": lambda: _command("site", "--student", "--out", f"{tmp}/b"),
            "slides": lambda: _command("slides", "--out", f"{tmp}/s")}, repeat)
    load = os.getloadavg()[1] if hasattr(os, "getloadavg") else float("nan")
    alone = med["site"] + med["student"]
    return ["| build | seconds | target |", "|---|---|---|",
            f"| machine load average (5 min) at the end, {os.cpu_count()} cores | {load:.1f} | |",
            f"| `site --out A --student-out B` (both editions) | {med['both']:.0f} | |",
            f"| `site --out A` (full edition) | {med['site']:.0f} | |",
            f"| `site --student --out B` | {med['student']:.0f} | |",
            f"| both editions in one / each alone | {med['both'] / alone:.2f} | <= 0.8 |",
            f"| `slides --out S` | {med['slides']:.0f} | |"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions, skip notebooks")
    parser.add_argument("--browser", action="store_true",
                        help="add the browser benchmark (JupyterLab + headless Chromium)")
    parser.add_argument("--browser-only", action="store_true", help="run only the browser benchmark")
    parser.add_argument("--explorer", action="append", default=None, metavar="chN.name_explorer",
                        help="browser benchmark: only this explorer (repeatable)")
    parser.add_argument("--busy", action="store_true",
                        help="add the browser benchmark beside two CPU-bound processes")
    parser.add_argument("--grading", action="store_true",
                        help="add the grader benchmark (python -m coursekit grade on chapter 1 copies)")
    parser.add_argument("--grading-only", action="store_true", help="run only the grader benchmark")
    parser.add_argument("--builds", action="store_true",
                        help="add the builds of the website (both editions) and the slides")
    parser.add_argument("--builds-only", action="store_true", help="run only the builds benchmark")
    parser.add_argument("--screenshots", type=Path, default=None, metavar="DIR",
                        help="browser benchmark: save a screenshot of each notebook after its drag")
    parser.add_argument("--docs", action="store_true",
                        help="also write the tables to docs/performance.md")
    args = parser.parse_args()
    repeat = 5 if args.quick else 21
    steps = 7 if args.quick else 15
    browser_section = ("browser: JupyterLab + headless Chromium, 1600x1000, first slider of each explorer",
                       lambda reps: bench_browser(reps, args.screenshots, args.explorer), steps)
    sections = [
        ("simulate: 10 001 samples, one input", bench_simulate, repeat),
        ("place: single input, poles -1..-3", bench_place, repeat),
        ("explorers", bench_explorers, repeat),
        ("import time", bench_import, 5 if args.quick else 11),
    ]
    if not args.quick:
        sections.append(("notebooks (fresh kernel each run)", bench_notebooks, 3))
    if args.browser:
        sections.append(browser_section)
    if args.browser_only:
        sections = [browser_section]
    if args.busy:
        sections.append(("browser, busy machine: two CPU-bound processes beside JupyterLab + headless Chromium",
                         lambda reps: bench_browser(reps, args.screenshots, args.explorer, busy=True), steps))
    grading_section = ("grading: chapter 1 student edition, fresh kernel per notebook", bench_grading,
                       1 if args.quick else 3)
    if args.grading:
        sections.append(grading_section)
    if args.grading_only:
        sections = [grading_section]
    builds_section = ("builds: the whole course, fresh processes", bench_builds, 1 if args.quick else 3)
    if args.builds:
        sections.append(builds_section)
    if args.builds_only:
        sections = [builds_section]
    print(f"coursekit benchmarks, Python {sys.version.split()[0]}, numpy {np.__version__}\n")
    report = []
    for title, func, reps in sections:
        lines = [f"## {title} (median of {reps})", "", ABOUT[title.split(":")[0].split(" (")[0]], "",
                 *func(reps), ""]
        print("\n".join(lines))
        report.append(lines)
    if args.docs:
        shown = [a for a in sys.argv[1:] if a not in (args.screenshots and str(args.screenshots), "--screenshots")]
        write_docs(ROOT / "docs" / "performance.md", "python benchmarks/run.py " + " ".join(shown), report)


if __name__ == "__main__":
    main()
