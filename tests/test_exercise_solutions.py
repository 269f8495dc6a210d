"""The exercises of the notebooks: Run All answers nothing, every worked solution is right.

A solution is a markdown cell tagged ``solution``: a folded ``<details>`` block
around a fenced ``python`` block, so running a notebook never executes it. These
tests execute it anyway. For each notebook they run, in one namespace, the
notebook's import statements, then every exercise cell in order, each followed
by the code of its solution, as a student who pastes the solution below the
exercise would. Each unanswered exercise must print "Not yet", each solution must
print "Correct" and its check must return a true `CheckResult`.

One more test runs the exercise cells in a real IPython kernel: a check on the
last line of a cell must leave no ``Out[n]`` (no execute_result message).
"""

from __future__ import annotations

import ast
import contextlib
import io
import json
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

from coursekit.tools.notebooks import chapter_notebooks
from coursekit.exercises._feedback import CheckResult
from kernels import this_python_kernel

NOTEBOOKS = chapter_notebooks(Path(__file__).resolve().parents[1] / "notebooks")
SUMMARY = "Solution (try the exercise first)"
SOLUTION = re.compile(r"<details><summary>(?P<summary>[^<]*)</summary>\n\n```python\n(?P<code>.*?)\n```\n\n"
                      r"</details>", re.S)
CHECK = re.compile(r"\bex\.(check_\w+)\(")


@dataclass
class Cell:
    index: int
    kind: str          # "code" or "markdown"
    tags: tuple
    exercise: bool     # metadata coursekit: exercise
    source: str


def _cells(path: Path) -> list[Cell]:
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    return [Cell(i, c["cell_type"], tuple(c["metadata"].get("tags", ())),
                 c["metadata"].get("coursekit") == "exercise", "".join(c["source"]))
            for i, c in enumerate(cells)]


def _is_exercise_cell(cell: Cell) -> bool:
    """A code cell where the student answers: it calls an ex.check_* function."""
    return cell.kind == "code" and cell.exercise and CHECK.search(cell.source) is not None


def _is_solution(cell: Cell) -> bool:
    return "solution" in cell.tags


def _solution_code(cell: Cell) -> str:
    match = SOLUTION.fullmatch(cell.source.strip())
    assert match, f"cell {cell.index}: a solution cell must be exactly a <details> block around a ```python block"
    return match["code"]


def _imports(cells: list[Cell]) -> str:
    """The import statements of the code cells before the exercises (IPython magics left out)."""
    from IPython.core.inputtransformer2 import TransformerManager
    statements = []
    for cell in cells:
        if cell.exercise:
            break
        if cell.kind == "code":
            tree = ast.parse(TransformerManager().transform_cell(cell.source))
            statements += [ast.unparse(node) for node in tree.body
                           if isinstance(node, (ast.Import, ast.ImportFrom))]
    return "\n".join(statements)


def _run_keeping_last(code: str, namespace: dict, where: str) -> tuple[object, str]:
    """Run `code`; return the value of its last statement (an expression or an assert's
    test, which is then checked here instead) and what it printed."""
    tree = ast.parse(code)
    last = tree.body[-1]
    assert isinstance(last, (ast.Expr, ast.Assert)), f"{where}: must end with a check call"
    target = ast.Assign(targets=[ast.Name("_check_result_", ast.Store())], value=last.value
                        if isinstance(last, ast.Expr) else last.test)
    tree.body[-1] = ast.fix_missing_locations(ast.copy_location(target, last))
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(tree, where, "exec"), namespace)
    return namespace.pop("_check_result_"), out.getvalue()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_exercise_has_one_folded_solution_cell_right_after_it(path):
    cells = _cells(path)
    code_solutions = [c.index for c in cells if c.kind == "code" and (_is_solution(c) or "assert ex.check_" in c.source)]
    assert not code_solutions, f"{path.name}: cells {code_solutions} are solutions in code cells (Run All runs them)"
    exercises = [c for c in cells if _is_exercise_cell(c)]
    headings = [c for c in cells if c.kind == "markdown" and c.source.startswith("### Exercise")]
    assert exercises and len(exercises) == len(headings), (
        f"{path.name}: {len(headings)} exercise headings but {len(exercises)} cells calling ex.check_*")
    solutions = [c for c in cells if _is_solution(c)]
    assert [c.index for c in solutions] == [c.index + 1 for c in exercises], (
        f"{path.name}: every exercise cell must be followed by exactly one solution cell, and nothing else "
        "may be tagged solution")
    for exercise, solution in zip(exercises, solutions):
        assert solution.kind == "markdown" and solution.exercise, solution.index
        match = SOLUTION.fullmatch(solution.source.strip())
        assert match, f"{path.name} cell {solution.index}: not a <details> block around a ```python block"
        assert match["summary"] == SUMMARY, f"the summary must give nothing away: {match['summary']!r}"
        last = ast.parse(match["code"]).body[-1]
        assert isinstance(last, ast.Assert), f"{path.name} cell {solution.index}: must end with assert ex.check_..."
        assert CHECK.findall(ast.unparse(last)) == CHECK.findall(exercise.source)[-1:], (
            f"{path.name} cell {solution.index}: the solution must assert the exercise's own check")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_unanswered_exercises_say_not_yet_and_every_solution_is_correct(path):
    from IPython.display import display
    cells = _cells(path)
    namespace = {"display": display}   # what the kernel provides without an import
    exec(compile(_imports(cells), f"{path.name}: imports", "exec"), namespace)
    checked = 0
    for cell in cells:
        if cell.kind == "code" and cell.exercise and not _is_exercise_cell(cell):
            exec(compile(cell.source, f"{path.name} cell {cell.index}", "exec"), namespace)
        elif _is_exercise_cell(cell):
            result, out = _run_keeping_last(cell.source, namespace, f"{path.name} cell {cell.index}")
            assert isinstance(result, CheckResult) and bool(result) is False, (cell.index, result)
            assert "Not yet" in out and "Correct" not in out, f"{path.name} cell {cell.index}: {out}"
        elif _is_solution(cell):
            where = f"{path.name} solution cell {cell.index}"
            result, out = _run_keeping_last(_solution_code(cell), namespace, where)
            assert isinstance(result, CheckResult) and bool(result) is True, f"{where}: {result!r}\n{out}"
            assert "Correct:" in out and "Not yet" not in out, f"{where}: {out}"
            checked += 1
    assert checked == sum(map(_is_exercise_cell, cells)) >= 1      # a chapter may have one exercise (extending.md)


def test_run_all_in_a_kernel_leaves_no_out_line_and_answers_nothing():
    """The exercise cells of all notebooks in one kernel, then one right answer: no execute_result
    (but for the progress table each notebook ends with)."""
    import nbformat
    from nbclient import NotebookClient
    sources = []
    for path in NOTEBOOKS:
        cells = _cells(path)
        sources += [_imports(cells)] + [c.source for c in cells if c.kind == "code" and c.exercise]
    sources.append("ex.check_stability([True, False, False, True])")   # a right answer, on the last line
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in sources])
    NotebookClient(nb, km=this_python_kernel(), timeout=120).execute(cleanup_kc=True)   # and shut it down
    outputs = [(cell.source, out) for cell in nb.cells for out in cell.outputs]
    shows_progress = [s for s in sources if s.startswith("ex.progress(")]   # the last cell of each notebook
    assert len(shows_progress) == len(NOTEBOOKS)
    assert not [s for s, out in outputs if out.output_type == "error"
                or (out.output_type == "execute_result" and s not in shows_progress)], outputs
    printed = {cell.source: "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
               for cell in nb.cells}
    answered = [s for s, text in printed.items() if "Correct" in text]
    assert answered == [sources[-1]], f"only the right answer may print Correct: {answered}"
    exercise_cells = [s for s in sources[:-1] if CHECK.search(s)]
    assert all(printed[s].startswith("Not yet") for s in exercise_cells), printed
    # the exercise data are typeset (markdown with LaTeX) and keep a plain-text form
    shown = [out.data for _, out in outputs if out.output_type == "display_data"]
    assert len(shown) == len(exercise_cells)
    assert all("text/markdown" in data and "text/plain" in data for data in shown)
    assert any(r"\begin{bmatrix}" in data["text/markdown"] for data in shown)
