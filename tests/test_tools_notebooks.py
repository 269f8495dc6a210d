"""coursekit.tools.notebooks: executing notebooks side by side leaves no kernel behind."""

from __future__ import annotations

import nbformat
import psutil
import pytest

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
