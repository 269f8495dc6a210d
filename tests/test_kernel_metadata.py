"""The notebooks store the kernel metadata JupyterLab writes, so an untouched notebook opens unmodified.

JupyterLab writes ``kernelspec`` and ``language_info`` from the kernel when it connects a notebook
(coursekit/tools/kernel_metadata.py); a stored value that differs marks the notebook modified.
The browser test (tests/test_browser.py) opens and closes each chapter; these tests check the
stored files against what this environment's kernel reports, and that every tool that rewrites
a notebook keeps the two entries.
"""

import platform
import re

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools.colab import with_install_cell
from coursekit.tools.kernel_metadata import (KERNEL_KEYS, apply_kernel_metadata, kernel_metadata,
                                             kernelspec_metadata, with_kernel_metadata)
from coursekit.tools.notebooks import default_notebook_dir, read_notebook
from coursekit.tools.release import student_edition
from coursekit.tools.slides import with_slide_metadata

NOTEBOOKS = sorted(default_notebook_dir().glob("*.ipynb"))
RESTORE = "python -m coursekit slides --kernel-metadata"


@pytest.fixture(scope="module")
def here():
    """The kernel metadata JupyterLab would write with this environment's python3 kernel."""
    return kernel_metadata()


def _without_version(language_info: dict) -> dict:
    return {key: value for key, value in language_info.items() if key != "version"}


def test_kernel_metadata_is_what_the_kernel_of_this_python_reports(here):
    assert set(here["kernelspec"]) == {"display_name", "language", "name"}
    assert (here["kernelspec"]["name"], here["kernelspec"]["language"]) == ("python3", "python")
    assert here["language_info"]["name"] == "python"
    assert here["language_info"]["version"] == platform.python_version()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_stores_the_kernel_metadata_jupyterlab_writes(path, here):
    stored = read_notebook(path).metadata
    assert stored.get("kernelspec") == here["kernelspec"], f"{path.name}: run {RESTORE}"
    info = stored.get("language_info", {})
    assert _without_version(info) == _without_version(here["language_info"]), f"{path.name}: run {RESTORE}"
    assert re.fullmatch(r"\d+\.\d+\.\d+", info.get("version", "")), (
        f"{path.name}: language_info.version {info.get('version')!r} is not the full Python version "
        f"a kernel reports; run {RESTORE}")


def test_all_notebooks_are_stored_for_one_python():
    versions = {read_notebook(p).metadata["language_info"]["version"] for p in NOTEBOOKS}
    assert len(versions) == 1, f"the notebooks are stored for several Pythons {sorted(versions)}; run {RESTORE}"


def test_stored_for_this_python_or_skipped_saying_which(here):
    stored = read_notebook(NOTEBOOKS[0]).metadata["language_info"]["version"]
    python = here["language_info"]["version"]
    if stored != python:
        pytest.skip(f"the notebooks are stored for Python {stored}, this is Python {python}: JupyterLab "
                    "marks them modified on opening here (jupyter/notebook#2123); the reference Python "
                    "is the one they are stored for")
    stale = apply_kernel_metadata(write=False, metadata=here)
    assert not stale, f"run {RESTORE} (out of date: {[p.name for p in stale]})"


def _small():
    v4 = nbformat.v4
    nb = v4.new_notebook(cells=[v4.new_markdown_cell("# Title"), v4.new_code_cell("x = 1"),
                                v4.new_markdown_cell("## 1 Exercises"),
                                v4.new_code_cell("answer = 2", metadata={"tags": ["solution"]})])
    return with_kernel_metadata(nb, {"kernelspec": kernelspec_metadata(),
                                     "language_info": {"name": "python", "version": "3.11.7"}})


@pytest.mark.parametrize("rewrite", [student_edition, with_slide_metadata, with_install_cell],
                         ids=lambda f: f.__name__)
def test_tools_that_rewrite_a_notebook_keep_its_kernel_metadata(rewrite):
    nb = _small()
    again = nbformat.reads(nbformat.writes(rewrite(nbformat.from_dict(nb))), as_version=4)
    assert {key: again.metadata[key] for key in KERNEL_KEYS} == {key: nb.metadata[key] for key in KERNEL_KEYS}


def test_with_kernel_metadata_refuses_an_incomplete_dictionary():
    with pytest.raises(ValueError, match=r"metadata lacks \['language_info'\]"):
        with_kernel_metadata(_small(), {"kernelspec": kernelspec_metadata()})
    with pytest.raises(TypeError, match="metadata must be a dict: received str"):
        with_kernel_metadata(_small(), "python3")


@pytest.mark.parametrize("kwargs, match", [({"notebooks": 3}, "notebooks must be a folder path"),
                                           ({"write": "no"}, "write must be True or False")])
def test_apply_kernel_metadata_checks_its_arguments(kwargs, match):
    with pytest.raises(TypeError, match=match):
        apply_kernel_metadata(metadata={}, **kwargs)


def test_kernelspec_of_a_kernel_that_is_not_installed():
    with pytest.raises(ValueError, match="kernel_name 'no-such-kernel' is not an installed kernel"):
        kernelspec_metadata("no-such-kernel")


def test_cli_slides_kernel_metadata_check_and_write(tmp_path, capsys, here):
    nb = with_slide_metadata(_small())
    nb.metadata["language_info"] = {"name": "python"}           # what the notebooks stored before
    nbformat.write(nb, str(tmp_path / "a.ipynb"))
    assert main(["slides", "--notebooks", str(tmp_path), "--check"]) == 0
    assert main(["slides", "--notebooks", str(tmp_path), "--check", "--kernel-metadata"]) == 1
    assert "kernel metadata out of date for Python" in capsys.readouterr().out
    assert main(["slides", "--notebooks", str(tmp_path), "--kernel-metadata"]) == 0
    assert "stored in 1 notebook(s)" in capsys.readouterr().out
    assert main(["slides", "--notebooks", str(tmp_path), "--check", "--kernel-metadata"]) == 0
    stored = read_notebook(tmp_path / "a.ipynb").metadata
    assert {key: stored[key] for key in KERNEL_KEYS} == here
