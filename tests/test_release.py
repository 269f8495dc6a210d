"""The student edition: built from the real notebooks, executed, and checked cell by cell.

The release of the four notebooks is built once into a temporary folder and executed once per
test session (the session fixture ``executed_chapters``, tests/executed_chapters.py: a chapter
whose code cells are the instructor edition's, as the test below on solution cells asserts, takes
the outputs of the instructor edition's execution, which runs the same code); the tests below then
read the built files and the executed notebooks. The unit tests at the end use small
notebooks made here, with both kinds of solution cell (markdown ``<details>`` and code).
"""

import base64
import re
from pathlib import Path

import nbformat
import pytest

import coursekit.exercises as ex
from coursekit.__main__ import main
from coursekit.tools.cells import SOLUTION_TAG
from coursekit.tools.chapters import chapter_modules
from coursekit.tools.notebooks import default_notebook_dir, read_notebook
from coursekit.tools.release import STUDENT_NOTE, build_release, student_edition

NOTEBOOKS = sorted(default_notebook_dir().glob("*.ipynb"))


def _chapter(path: Path) -> int:
    """The chapter number of a notebook ``NN_name.ipynb``."""
    return int(path.name.split("_", 1)[0])


@pytest.fixture(scope="module")
def release(executed_chapters):
    student = executed_chapters.student()
    return {"paths": student.paths, "stored": [read_notebook(p) for p in student.paths],
            "executed": student.notebooks}


def _has_tag(cell, tag):
    return tag in cell.get("metadata", {}).get("tags", [])


def test_release_writes_one_student_notebook_per_chapter(release):
    assert [p.name for p in release["paths"]] == [p.name for p in NOTEBOOKS]
    # one notebook for each chapter of the course's one registry (coursekit/_chapters.py)
    registry = sorted({int(m.__name__.rsplit("ch", 1)[1]) for package in ("explorers", "exercises")
                       for m in chapter_modules(package)})
    assert [_chapter(p) for p in NOTEBOOKS] == registry and registry[:4] == [1, 2, 3, 4]


def test_no_solution_cell_remains_and_the_exercises_do(release):
    for path, nb in zip(NOTEBOOKS, release["stored"]):
        original = read_notebook(path)
        solutions = [c for c in original.cells if _has_tag(c, SOLUTION_TAG)]
        assert solutions, f"{path.name} has no solution cell: the test would check nothing"
        assert not [c for c in nb.cells if _has_tag(c, SOLUTION_TAG)]
        kept = [c for c in original.cells if not _has_tag(c, SOLUTION_TAG)]
        assert [c.source for c in nb.cells if c.cell_type == "code"] == \
            [c.source for c in kept if c.cell_type == "code"]
        for solution in solutions:   # no solution's text survives anywhere
            assert all(solution.source not in c.source for c in nb.cells)


def test_release_is_stored_without_outputs(release):
    for nb in release["stored"]:
        code = [c for c in nb.cells if c.cell_type == "code"]
        assert code and all(c.outputs == [] and c.execution_count is None for c in code)
        assert "widgets" not in nb.metadata


def test_first_cell_says_where_the_solutions_are(release):
    for nb in release["stored"]:
        assert nb.cells[0].cell_type == "markdown" and nb.cells[0].source.startswith("# Chapter")
        assert nb.cells[0].source.rstrip().endswith(STUDENT_NOTE)
        assert sum(STUDENT_NOTE in c.source for c in nb.cells) == 1


def _exercise_sentences_about_solutions(nb):
    """Sentences of the exercise text that mention a solution and do not say 'never'/'not'/'no'."""
    found = []
    for cell in nb.cells:
        if cell.cell_type == "markdown" and cell.metadata.get("coursekit") == "exercise" \
                and not _has_tag(cell, SOLUTION_TAG):
            for sentence in re.split(r"(?<=[.!?])\s+", cell.source):
                if re.search(r"\bsolutions?\b", sentence, re.IGNORECASE) \
                        and not re.search(r"\b(never|not|no)\b", sentence, re.IGNORECASE):
                    found.append(sentence)
    return found


def test_exercise_text_no_longer_points_to_a_solution(release):
    for path, nb in zip(NOTEBOOKS, release["stored"]):
        assert _exercise_sentences_about_solutions(read_notebook(path)), (
            f"{path.name}: the instructor text no longer mentions its solutions; the test checks nothing")
        assert _exercise_sentences_about_solutions(nb) == []


def test_release_runs_top_to_bottom_without_errors(release):
    for path, nb in zip(release["paths"], release["executed"]):
        errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs
                  if o.output_type == "error"]
        assert not errors, f"{path.name}: {errors[0].ename}: {errors[0].evalue}"
        assert all(c.execution_count is not None for c in nb.cells if c.cell_type == "code")


def test_every_unanswered_exercise_prints_not_yet(release):
    for path, nb in zip(release["paths"], release["executed"]):
        checks = [c for c in nb.cells if c.cell_type == "code" and "ex.check_" in c.source]
        called = [re.search(r"\bex\.(check_\w+)\(", c.source).group(1) for c in checks]
        # one answer cell for each exercise the chapter declares, in order
        assert called == [e.check for e in ex.chapter_exercises(_chapter(path))], path.name
        for cell in checks:
            printed = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
            assert "Not yet" in printed, f"{path.name}: {cell.source!r} printed {printed!r}"


def test_explorers_keep_their_static_figure_for_slides_and_html(release):
    # what nbconvert (--to slides or html) shows of an explorer executed without widget state
    from nbconvert import SlidesExporter
    nb = release["executed"][0]
    explorers = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs
                 if "application/vnd.jupyter.widget-view+json" in o.get("data", {})]
    assert len(explorers) >= 2
    html, _ = SlidesExporter().from_notebook_node(nb)
    for output in explorers:
        png = output["data"]["image/png"]
        assert base64.b64decode(png)[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.replace("\n", "") in html.replace("\n", "")


# -- the command line -------------------------------------------------------------------------

def test_cli_release_refuses_a_non_empty_folder_without_force(tmp_path, capsys):
    source = tmp_path / "nbs"
    source.mkdir()
    nbformat.write(_notebook(), str(source / "one.ipynb"))
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(SystemExit) as stop:
        main(["release", "--out", str(out), "--notebooks", str(source)])
    assert stop.value.code == 2
    assert "is not empty" in capsys.readouterr().err
    assert main(["release", "--out", str(out), "--notebooks", str(source), "--force"]) == 0
    assert (out / "keep.txt").read_text() == "mine" and (out / "one.ipynb").is_file()
    assert "1 notebooks written" in capsys.readouterr().out


def test_cli_release_never_writes_over_the_instructor_notebooks(tmp_path, capsys):
    source = tmp_path / "nbs"
    source.mkdir()
    nbformat.write(_notebook(), str(source / "one.ipynb"))
    before = (source / "one.ipynb").read_bytes()
    with pytest.raises(SystemExit):
        main(["release", "--out", str(source), "--notebooks", str(source), "--force"])
    assert "would replace the instructor edition" in capsys.readouterr().err
    assert (source / "one.ipynb").read_bytes() == before


def test_cli_release_without_notebooks_says_where_it_looked(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["release", "--out", str(tmp_path / "out"), "--notebooks", str(tmp_path)])
    assert f"no notebooks (*.ipynb) found in {tmp_path}" in capsys.readouterr().err


def test_cli_needs_a_command_and_out(capsys):
    with pytest.raises(SystemExit):
        main([])
    with pytest.raises(SystemExit):
        main(["release"])
    assert "--out" in capsys.readouterr().err


def test_python_dash_m_coursekit_help_lists_the_commands():
    import subprocess
    import sys
    result = subprocess.run([sys.executable, "-m", "coursekit", "--help"], capture_output=True, text=True,
                            check=True)
    assert all(command in result.stdout for command in ("release", "slides", "colab", "site", "grade"))


# -- student_edition on small notebooks -------------------------------------------------------

def _notebook():
    v4 = nbformat.v4
    return v4.new_notebook(cells=[
        v4.new_markdown_cell("# Title\n\nIntro."),
        v4.new_code_cell("x = 1", outputs=[v4.new_output("stream", name="stdout", text="1\n")],
                         execution_count=3),
        v4.new_markdown_cell("## Exercises\n\nType your answer and run the cell. It never shows the "
                             "solution. The worked solution sits in a collapsed box below each exercise "
                             "— try first!\n\nClick **Solution** to unfold a worked solution. Try it "
                             "first!\n\nTry the first exercise now.", metadata={"coursekit": "exercise"}),
        v4.new_code_cell("answer = None\nprint('Not yet')", metadata={"coursekit": "exercise"}),
        v4.new_markdown_cell("<details><summary>Solution</summary>\n\n```python\nanswer = 1\n```\n"
                             "</details>", metadata={"tags": ["solution"], "coursekit": "exercise"}),
        v4.new_code_cell("answer = 1", metadata={"tags": ["solution"], "jupyter": {"source_hidden": True}}),
    ], metadata={"widgets": {"state": {}}})


def test_student_edition_removes_both_kinds_of_solution_cell():
    nb = _notebook()
    student = student_edition(nb)
    assert [c.source for c in student.cells if "answer = 1" in c.source] == []
    assert len(nb.cells) == 6, "the input notebook must not change"
    assert [c.cell_type for c in student.cells] == ["markdown", "code", "markdown", "code"]


def test_student_edition_clears_outputs_and_widget_state():
    student = student_edition(_notebook())
    assert student.cells[1].outputs == [] and student.cells[1].execution_count is None
    assert "widgets" not in student.metadata
    assert _notebook().cells[1].outputs, "the input keeps its outputs"


def test_student_edition_drops_only_the_sentences_that_point_to_a_solution():
    text = student_edition(_notebook()).cells[2].source
    assert text == ("## Exercises\n\nType your answer and run the cell. It never shows the solution."
                    "\n\nTry the first exercise now.")


def test_student_edition_is_idempotent_and_notes_once():
    once = student_edition(_notebook())
    twice = student_edition(once)
    assert nbformat.writes(once) == nbformat.writes(twice)
    assert once.cells[0].source == "# Title\n\nIntro.\n\n" + STUDENT_NOTE


def test_student_edition_adds_a_note_cell_when_the_first_cell_is_code():
    nb = _notebook()
    nb.cells.pop(0)
    student = student_edition(nb)
    assert student.cells[0].cell_type == "markdown" and student.cells[0].source == STUDENT_NOTE


def test_student_edition_refuses_what_is_not_a_notebook():
    with pytest.raises(TypeError, match="nb must be a notebook"):
        student_edition({"cells": []})


def test_build_release_checks_its_arguments(tmp_path):
    with pytest.raises(TypeError, match="out must be a folder path"):
        build_release(3)
    with pytest.raises(TypeError, match="force must be True or False"):
        build_release(tmp_path / "x", force="yes")
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="out must be a folder"):
        build_release(tmp_path / "file")


def test_written_notebooks_validate_and_keep_the_json_style(tmp_path):
    source = tmp_path / "nbs"
    source.mkdir()
    nbformat.write(_notebook(), str(source / "one.ipynb"))
    (path,) = build_release(tmp_path / "out", notebooks=source)
    nbformat.validate(nbformat.read(str(path), as_version=4))
    text = Path(path).read_text(encoding="utf-8")
    assert text.startswith('{\n "cells": [\n  {\n') and text.endswith("}\n")


def test_default_notebook_folder_without_an_editable_install(tmp_path, monkeypatch):
    # installed with `pip install .` (Binder): the package is not beside notebooks/, the clone is the cwd
    import coursekit.tools.notebooks as release
    monkeypatch.setattr(release, "__file__", str(tmp_path / "site-packages" / "coursekit" / "tools" / "notebooks.py"))
    monkeypatch.chdir(tmp_path)
    assert release.default_notebook_dir() == tmp_path / "notebooks"
    monkeypatch.undo()
    assert release.default_notebook_dir() == Path(__file__).resolve().parents[1] / "notebooks"
