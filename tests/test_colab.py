"""The install cell (Colab): first code cell of every notebook, a no-op where coursekit is installed."""

import subprocess
import sys

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools.colab import (INSTALL_MARK, apply_install_cell, cell_repository, install_cell_source,
                             repository_from_git, with_install_cell)
from coursekit.tools.notebooks import default_notebook_dir, read_notebook

NOTEBOOKS = sorted(default_notebook_dir().glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_install_cell_is_the_first_code_cell(path):
    nb = read_notebook(path)
    first_code = next(c for c in nb.cells if c.cell_type == "code")
    assert first_code.metadata.get("coursekit") == INSTALL_MARK
    assert first_code.source == install_cell_source(cell_repository(first_code.source))


def test_all_notebooks_install_from_the_same_place():
    sources = {next(c for c in read_notebook(p).cells if c.cell_type == "code").source for p in NOTEBOOKS}
    assert len(sources) == 1


def _run(source, *, hide_coursekit):
    """Run an install cell's source in a fresh Python; with hide_coursekit, as if it were not installed."""
    prelude = ("import importlib.util, subprocess\n"
               "real = importlib.util.find_spec\n"
               "importlib.util.find_spec = lambda name, *a: None if name == 'coursekit' else real(name, *a)\n"
               "def fake_run(args, check):\n"
               "    print('RUN', args)\n"
               "subprocess.run = fake_run\n") if hide_coursekit else ""
    return subprocess.run([sys.executable, "-c", prelude + source], capture_output=True, text=True)


@pytest.mark.parametrize("repository", [None, "https://github.com/someone/course"])
def test_install_cell_does_nothing_where_coursekit_is_installed(repository):
    result = _run(install_cell_source(repository), hide_coursekit=False)
    assert result.returncode == 0 and result.stdout == "" and result.stderr == ""


def test_install_cell_installs_from_the_repository_where_coursekit_is_missing():
    result = _run(install_cell_source("https://github.com/someone/course"), hide_coursekit=True)
    assert result.returncode == 0, result.stderr
    assert "'coursekit @ git+https://github.com/someone/course'" in result.stdout
    assert "'-m', 'pip', 'install'" in result.stdout


def test_install_cell_without_repository_says_what_to_do():
    result = _run(install_cell_source(None), hide_coursekit=True)
    assert result.returncode != 0
    assert "ModuleNotFoundError: coursekit is missing: install it from the course repository" in result.stderr


def test_an_install_cell_without_repository_shows_no_install_line():
    """No stand-in address (OWNER/NAME) a reader would copy: an install line only with a real address."""
    source = install_cell_source(None)
    assert "OWNER" not in source and "git+" not in source and "pip install" not in source
    for path in NOTEBOOKS:
        first_code = next(c for c in read_notebook(path).cells if c.cell_type == "code")
        assert "OWNER/NAME" not in first_code.source, path.name


@pytest.mark.parametrize("repository", [None, "https://github.com/course/coursekit"])
def test_the_install_cell_s_comment_says_what_it_does(repository):
    """Without an address the cell stops with a message: its comment must not promise an install."""
    comment = "".join(line for line in install_cell_source(repository).splitlines(True) if line.startswith("#"))
    assert ("this cell installs it" in comment) == (repository is not None), comment


@pytest.mark.parametrize("bad", ["github.com/a/b", "http://github.com/a/b", "https://github.com/a b", 3])
def test_install_cell_refuses_what_is_not_an_https_address(bad):
    with pytest.raises(ValueError, match="repository must be the https address"):
        install_cell_source(bad)


def test_repository_round_trips_through_the_cell():
    url = "https://gitlab.example.org/group/course"
    assert cell_repository(install_cell_source(url)) == url
    assert cell_repository(install_cell_source(None)) is None


def _git_repo(tmp_path, remote):
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    if remote:
        subprocess.run(["git", "-C", str(tmp_path), "remote", "add", "origin", remote], check=True)


@pytest.mark.parametrize("remote, expected", [
    ("https://github.com/someone/course.git", "https://github.com/someone/course"),
    ("git@github.com:someone/course.git", "https://github.com/someone/course"),
    ("ssh://git@github.com/someone/course", "https://github.com/someone/course"),
    (None, None),
])
def test_repository_from_git(tmp_path, remote, expected):
    _git_repo(tmp_path, remote)
    assert repository_from_git(tmp_path) == expected


def _small():
    v4 = nbformat.v4
    return v4.new_notebook(cells=[
        v4.new_markdown_cell("# Title"),
        v4.new_markdown_cell("Run this first.", metadata={"coursekit": "environment"}),
        v4.new_code_cell("import coursekit as ck", metadata={"coursekit": "environment"}),
    ])


def test_with_install_cell_goes_before_the_environment_check_and_is_rewritten_in_place():
    nb = with_install_cell(_small())
    assert [c.metadata.get("coursekit") for c in nb.cells] == [None, INSTALL_MARK, "environment",
                                                              "environment"]
    nb = with_install_cell(nb, repository="https://github.com/a/b")
    assert len(nb.cells) == 4 and cell_repository(nb.cells[1].source) == "https://github.com/a/b"


def test_cli_colab_writes_the_address_given_or_from_git(tmp_path, capsys):
    nbformat.write(_small(), str(tmp_path / "a.ipynb"))
    assert main(["colab", "--notebooks", str(tmp_path), "--repository", "https://github.com/a/b"]) == 0
    assert "installs from https://github.com/a/b: 1 notebook(s) changed" in capsys.readouterr().out
    _git_repo(tmp_path, "git@github.com:c/d.git")
    assert main(["colab", "--notebooks", str(tmp_path)]) == 0
    cell = read_notebook(tmp_path / "a.ipynb").cells[1]
    assert cell_repository(cell.source) == "https://github.com/c/d"
    assert apply_install_cell(tmp_path, repository="https://github.com/c/d", write=False) == []


def test_cli_colab_without_any_address_stops_with_the_fix(tmp_path, capsys):
    nbformat.write(_small(), str(tmp_path / "a.ipynb"))
    _git_repo(tmp_path, None)
    with pytest.raises(SystemExit):
        main(["colab", "--notebooks", str(tmp_path)])
    assert "pass --repository https://github.com/OWNER/NAME" in capsys.readouterr().err
