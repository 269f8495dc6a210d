"""Notebooks are stored without outputs, execution counts or widget state."""

import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))


def test_there_are_notebooks():
    assert NOTEBOOKS, "no notebooks found in notebooks/"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_is_stored_clean(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    dirty = [i for i, cell in enumerate(nb["cells"]) if cell["cell_type"] == "code"
             and (cell.get("outputs") or cell.get("execution_count") is not None)]
    assert not dirty, (f"{path.name}: code cells {dirty} have stored outputs or execution counts; "
                       "clear them (Edit > Clear Outputs of All Cells) before committing")
    assert "widgets" not in nb.get("metadata", {}), (
        f"{path.name}: widget state is stored in the notebook metadata; "
        "clear it (in JupyterLab: Settings > Save Widget State Automatically off, then save)")


#: what Markdown reads as the start of a list, heading or quote when a line begins with it
_BLOCK_START = re.compile(r"^(\+ |- |\* |#|> |\d+[.)] )")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_no_wrapped_line_of_a_formula_starts_a_list_or_heading(path):
    # a formula wrapped so that its second line begins with "+ v$" was read as a list item on the
    # website and in the slides: the math and the prose swapped places (JupyterLab showed it right)
    bad = []
    for index, cell in enumerate(json.loads(path.read_text(encoding="utf-8"))["cells"]):
        if cell["cell_type"] != "markdown":
            continue
        dollars = 0
        for line in "".join(cell["source"]).split("\n"):
            if not line.strip():
                dollars = 0                  # a blank line ends the paragraph (and any math)
                continue
            if dollars % 2 and _BLOCK_START.match(line):
                bad.append(f"cell {index}: {line[:60]!r}")
            dollars += len(re.findall(r"(?<!\\)\$", line.replace("$$", "")))
    assert not bad, f"{path.name}: a line inside $...$ starts like a list or heading: {bad}"
