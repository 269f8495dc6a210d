"""Notebooks are stored without outputs, execution counts or widget state."""

import json
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
