"""coursekit.tools.notebooks: executing notebooks side by side leaves no kernel behind."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import nbformat
import psutil
import pytest

from coursekit.tools import site
from coursekit.tools.notebooks import execute_all
from kernels import this_python_kernel


def _kernels() -> set[int]:
    return {p.pid for p in psutil.Process().children(recursive=True)
            if "ipykernel_launcher" in " ".join(p.cmdline())}


@pytest.mark.parametrize("kernel", [None, lambda: this_python_kernel(asynchronous=True)],
                         ids=["named kernel", "kernel manager given"])
def test_execute_all_shuts_down_every_kernel_it_started(tmp_path, kernel):
    before = _kernels()
    notebooks = [nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(f"print({i} * 2)")]) for i in range(2)]
    execute_all(notebooks, [tmp_path / f"{i}.ipynb" for i in range(2)], timeout=60, what="the test", kernel=kernel)
    assert [nb.cells[0].outputs[0]["text"] for nb in notebooks] == ["0\n", "2\n"]
    assert _kernels() - before == set(), "a kernel outlived its notebook's execution"


def _imported(command: list[str], cwd) -> set[str]:
    """The modules the process of `command` (a Python command line) imported: ``-X importtime``."""
    result = subprocess.run([command[0], "-X", "importtime", *command[1:]], cwd=cwd, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-3000:]
    return {line.rsplit("|", 1)[-1].strip() for line in result.stderr.splitlines() if line.startswith("import time:")}


@pytest.mark.skipif(importlib.util.find_spec("rfc3987_syntax") is None,
                    reason="rfc3987-syntax is not installed here: there is no grammar to leave out")
def test_the_tools_processes_that_import_nbformat_leave_out_the_iri_grammar(tmp_path):
    """``python -m coursekit`` and the site's Sphinx build import nbformat without building the IRI
    grammar (`leave_out_the_iri_grammar`); a plain import of nbformat builds it, with the parser
    library lark (the refused import of rfc3987_syntax itself is listed too: lark tells them apart)."""
    assert "lark" in _imported([sys.executable, "-c", "import nbformat"], tmp_path)
    release = _imported([sys.executable, "-m", "coursekit", "release", "--out", str(tmp_path / "release")], tmp_path)
    assert "nbformat" in release and "lark" not in release
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "conf.py").write_text('extensions = ["myst_nb"]\n', encoding="utf-8")
    (tmp_path / "src" / "index.md").write_text("# Title\n", encoding="utf-8")
    sphinx = _imported([*site._SPHINX_BUILD, "-b", "html", "-q", "src", "html"], tmp_path)
    assert "nbformat" in sphinx and "lark" not in sphinx
    assert (tmp_path / "html" / "index.html").is_file()

