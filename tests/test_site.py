"""The course website's pieces (coursekit.tools.site) and one small build without a browser.

The full build of the four chapters, checked page by page in Chromium, is in
tests/test_site_browser.py (marker ``browser``). Here: the markdown and notebook rewrites, the
landing page, argument checks, the command line, and a build of one small notebook that holds one
of each thing the site treats specially (skipped, with the reason, without the ``site`` extra).
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from coursekit.tools import site
from coursekit.tools.notebooks import ALT, WIDGET_VIEW, chapter_notebooks
from coursekit.tools.kernel_metadata import kernelspec_metadata
from coursekit.__main__ import main

NOTEBOOKS = Path(__file__).parents[1] / "notebooks"


def _code(source, tags=(), outputs=(), metadata=None):
    cell = nbformat.v4.new_code_cell(source, metadata=dict(metadata or {}))
    if tags:
        cell.metadata["tags"] = list(tags)
    cell.outputs = list(outputs)
    return cell


def _markdown(source, tags=(), metadata=None):
    cell = nbformat.v4.new_markdown_cell(source, metadata=dict(metadata or {}))
    if tags:
        cell.metadata["tags"] = list(tags)
    return cell


# --- errata ------------------------------------------------------------------------------

def test_blockquote_with_two_errata_becomes_two_boxes():
    text = ("Intro $x$.\n\n> **Erratum (1.1).** First slip,\n> second line.\n>\n"
            "> **Erratum (1.2).** Second slip.\n\nAfter.")
    out = site.erratum_admonitions(text)
    assert out.count("::::{admonition} ") == 2
    assert "::::{admonition} Erratum (1.1)\n:class: erratum\nFirst slip,\nsecond line.\n::::" in out
    assert "::::{admonition} Erratum (1.2)\n:class: erratum\nSecond slip.\n::::" in out
    assert out.startswith("Intro $x$.\n") and out.endswith("After.")
    assert "**Erratum" not in out and "> " not in out


def test_remark_erratum_and_following_quote_paragraph_stay_in_one_box():
    text = "> **Remark / erratum (1.9).** The printed version.\n>\n> $$\\dot x = f(x)$$\n\nNext."
    out = site.erratum_admonitions(text)
    assert out.count("::::{admonition} Remark / erratum (1.9)") == 1
    box = out[out.index("::::{admonition}"):out.rindex("::::")]
    assert "$$\\dot x = f(x)$$" in box
    assert out.endswith("Next.")


def test_plain_paragraph_erratum_keeps_the_equation_it_announces():
    text = ("Before.\n\n**Erratum (2.15).** False; solving gives:\n\n$$A^2B = -2AB + B.$$\n\n"
            "(The conclusion stands.)")
    out = site.erratum_admonitions(text)
    box = out[out.index("::::{admonition} Erratum (2.15)"):]
    box = box[:box.index("\n::::") + 5]
    assert "$$A^2B = -2AB + B.$$" in box
    assert "(The conclusion stands.)" not in box
    assert out.endswith("(The conclusion stands.)")


def test_text_without_errata_and_code_fences_are_left_alone():
    text = ("# Title\n\n> A quote, not an erratum.\n\nSome **bold** text.\n\n```python\n"
            "**Erratum (9.9).** inside code\n\n**Erratum (9.8).** still code\n```\n")
    assert site.erratum_admonitions(text) == text


def test_erratum_admonitions_refuses_non_text():
    with pytest.raises(TypeError, match="markdown must be a str"):
        site.erratum_admonitions(["> **Erratum"])


# --- notebook rewrites ---------------------------------------------------------------------

def test_the_pages_show_no_widget_view_but_the_figure_or_text_beside_it():
    from myst_nb.core.render import get_mime_priority
    conf = {}
    exec(site.sphinx_conf(title="t"), conf)     # the configuration Sphinx runs
    shown = get_mime_priority("html", conf["nb_mime_priority_overrides"])
    assert WIDGET_VIEW not in shown and shown.index("image/png") < shown.index("text/plain")


def test_fold_solution_code_folds_only_solution_code_cells():
    nb = nbformat.v4.new_notebook()
    nb.cells = [_code("x = None"), _code("x = 42", tags=["solution"]),
                _markdown("<details>...</details>", tags=["solution"])]
    site.fold_solution_code(nb)
    assert "tags" not in nb.cells[0].metadata
    assert nb.cells[1].metadata["tags"] == ["solution", "hide-cell"]
    assert nb.cells[1].metadata["mystnb"]["code_prompt_show"] == "Show solution"
    assert nb.cells[2].metadata["tags"] == ["solution"]


# --- landing page and notebooks ------------------------------------------------------------

def test_chapter_entry_reads_title_and_numbered_sections_of_chapter_1():
    nb = nbformat.read(NOTEBOOKS / "01_representations.ipynb", as_version=4)
    entry = site.chapter_entry(nb, "01_representations")
    assert entry["number"] == "1"
    assert entry["title"] == "Signals, systems and their representations"
    assert entry["sections"][:2] == ["1.1 Introduction", "1.2 A few systems"]
    assert all(s.startswith("1.") for s in entry["sections"])


def test_chapter_entry_needs_a_title():
    nb = nbformat.v4.new_notebook()
    nb.cells = [_markdown("no title here")]
    with pytest.raises(ValueError, match="no '# ' title"):
        site.chapter_entry(nb, "05_x")


def test_landing_page_has_a_row_and_a_toctree_entry_per_chapter():
    chapters = [{"number": "1", "title": "One", "page": "01_one", "sections": ["1.1 A", "1.2 B"]},
                {"number": "2", "title": "Two", "page": "02_two", "sections": []}]
    text = site.landing_page(chapters)
    assert "| 1 | [One](01_one.ipynb) | 1.1 A · 1.2 B |" in text
    assert "| 2 | [Two](02_two.ipynb) |  |" in text
    assert re.search(r"```\{toctree\}\n:hidden:\n:maxdepth: 2\n\n01_one\n02_two\n```", text)
    assert 'python -m pip install -e ".[lab]"' in text and "python -m jupyterlab notebooks/" in text
    assert "worked solution, folded" in text
    student = site.landing_page(chapters, student=True)
    assert "student edition" in student


def test_chapter_notebooks_are_found_in_order_and_bad_folders_refused(tmp_path):
    assert [p.name for p in chapter_notebooks(NOTEBOOKS)][:2] == [
        "01_representations.ipynb", "02_controllability.ipynb"]
    with pytest.raises(ValueError, match="not a directory"):
        chapter_notebooks(tmp_path / "missing")
    with pytest.raises(ValueError, match="no chapter notebook"):
        chapter_notebooks(tmp_path)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"student": "yes"}, TypeError, "student must be True or False"),
    ({"verbose": 1}, TypeError, "verbose must be True or False"),
    ({"timeout": 0}, ValueError, "timeout must be a positive"),
    ({"timeout": 2.5}, ValueError, "timeout must be a positive"),
    ({"student": True, "student_out": "s"}, ValueError, "pass student=False"),
])
def test_build_site_checks_its_arguments(tmp_path, kwargs, error, match):
    with pytest.raises(error, match=match):
        site.build_site(tmp_path / "out", **kwargs)


def test_build_site_refuses_one_folder_for_both_editions(tmp_path):
    with pytest.raises(ValueError, match="student_out .* is out_dir"):
        site.build_site(tmp_path / "out", student_out=tmp_path / "out", notebooks_dir=NOTEBOOKS)


def test_build_site_refuses_to_write_over_the_notebooks(tmp_path):
    nbformat.write(nbformat.v4.new_notebook(), tmp_path / "01_a.ipynb")
    with pytest.raises(ValueError, match="is the notebooks folder"):
        site.build_site(tmp_path, notebooks_dir=tmp_path)


def test_build_site_never_deletes_a_folder_that_is_not_a_site(tmp_path):
    (tmp_path / "notes.txt").write_text("keep me")
    with pytest.raises(ValueError, match="not a site built before"):
        site.build_site(tmp_path, notebooks_dir=NOTEBOOKS)
    with pytest.raises(ValueError, match="is a file"):
        site.build_site(tmp_path / "notes.txt", notebooks_dir=NOTEBOOKS)
    assert (tmp_path / "notes.txt").read_text() == "keep me"


def test_command_line_needs_out_and_reports_errors(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["site"])
    assert stop.value.code == 2
    assert "--out" in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:       # every command reports its errors alike
        main(["site", "--out", str(tmp_path / "o"), "--notebooks", str(tmp_path / "none")])
    assert stop.value.code == 2
    assert "site: error:" in capsys.readouterr().err


# --- one small build --------------------------------------------------------------------------

PNG = base64.b64encode(bytes.fromhex(
    "89504e470d0a1a0a0000000d4948445200000001000000010806000000"
    "1f15c4890000000d49444154789c6360f8cfc0f01f0005000201a5b7e1"
    "d60000000049454e44ae426082")).decode()

SMALL_NOTEBOOK = [
    _markdown("# Chapter 7 — A small chapter\n\nIntro with $\\dot x = A x$."),
    _code("# install cell: pip install git+https://github.com/OWNER/NAME", metadata={"coursekit": "install"}),
    _markdown("Run the environment check first.", metadata={"coursekit": "environment"}),
    _code("print('BUILD-MACHINE-VERSIONS')", metadata={"coursekit": "environment"}),
    _markdown("## 7.1 First section\n\n> **Erratum (7.1).** The notes print $A^T$; it is $A$."),
    _code("from IPython.display import display\n"
          f"display({{'image/png': '{PNG}', 'text/plain': 'explorer (static figure)',\n"
          "         'application/vnd.jupyter.' + 'widget-view+json':\n"
          "             {'model_id': 'm1', 'version_major': 2, 'version_minor': 0}}, raw=True)"),
    _code("%matplotlib inline\nimport matplotlib.pyplot as plt\n"
          "plt.plot([0, 1, 2], [0, 3, 1], label='bump'); plt.xlabel('time t [s]'); plt.legend(); plt.show()"),
    _markdown("### Exercise 7.1: one number"),
    _code("display({'text/markdown': '`n` $= 42$'}, raw=True)   # exercise data are typeset this way"),
    _code("answer = None"),
    _code("answer = 6 * 7  # worked solution: SOLUTION-IN-CODE", tags=["solution"]),
    _markdown("<details><summary>Solution</summary>\n\n```python\nanswer = 42  # SOLUTION-IN-MARKDOWN\n```\n\n"
              "</details>", tags=["solution"]),
]


def _counted(name: str) -> list:
    """A chapter's title and a cell that notes each execution in runs-NAME.log of its folder."""
    return [_markdown(f"# Chapter {int(name)} — chapter {name}"),
            _code(f"_ = open('runs-{name}.log', 'a').write('run\\n')")]


#: run in the tiny chapter's kernel: a connection to a host of the documentation range (RFC 5737)
_PROBE = ("import socket\ntry:\n    socket.create_connection(('192.0.2.1', 80), 1)\n"
          "except OSError as e:\n    print('refused:', e)")


@pytest.fixture(scope="module")
def small_site(tmp_path_factory):
    """The small chapter (and a tiny one with no solution in code, whose last cell tries to reach
    the network) built in both editions by one ``python -m coursekit site`` with every outside
    connection refused and logged (`_NO_NETWORK`): ``({False: (index, page), True: (index, page)},
    {chapter: times executed}, [the connections refused])``."""
    missing = site.missing_site_tools()
    if missing:
        pytest.skip("the site extra is not installed (missing: " + ", ".join(missing) + ")")
    root = tmp_path_factory.mktemp("small")
    folder, guard = root / "nb", root / "guard"
    folder.mkdir()
    guard.mkdir()
    (guard / "sitecustomize.py").write_text(_NO_NETWORK, encoding="utf-8")
    tiny = _counted("08") + [_code(_PROBE)]
    for name, cells in [("07_small", SMALL_NOTEBOOK + _counted("07")[1:]), ("08_tiny", tiny)]:
        nb = nbformat.v4.new_notebook(cells=cells)
        nb.metadata["kernelspec"] = kernelspec_metadata()
        nbformat.write(nb, folder / f"{name}.ipynb")
    log = root / "network.log"
    log.touch()
    package = str(Path(site.__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(guard), package]), CK_NETWORK_LOG=str(log))
    result = subprocess.run([sys.executable, "-m", "coursekit", "site", "--out", str(root / "site"), "--student-out",
                             str(root / "student"), "--notebooks", str(folder)],
                            env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    editions = {False: root / "site" / "index.html", True: root / "student" / "index.html"}
    runs = {name: (folder / f"runs-{name}.log").read_text().count("run") for name in ("07", "08")}
    pages = {student: (i, (i.parent / "07_small.html").read_text(encoding="utf-8")) for student, i in editions.items()}
    return pages, runs, log.read_text().splitlines()


def test_small_build_both_editions_from_one_execution_unless_a_solution_is_code(small_site):
    assert small_site[1] == {"07": 2, "08": 1}


def _text(page: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", page))


def test_small_build_instructor_site(small_site):
    index, page = small_site[0][False]
    out = index.parent
    assert "07_small.html" in index.read_text(encoding="utf-8")
    # math: typeset by the MathJax copied into the site, loaded from there
    assert (out / "_static" / "mathjax" / "tex-chtml.js").is_file()
    assert re.search(r'<script[^>]*src="_static/mathjax/tex-chtml\.js"', page)
    assert not re.search(r'<(script|link)[^>]*(src|href)="(https?:)?//', page)
    assert '<span class="math' in page
    assert '<span class="math notranslate nohighlight">\\(= 42\\)</span>' in page   # math in markdown output
    # the explorer: its static figure, no widget view
    assert re.search(r'<img[^>]*src="_images/', page) and WIDGET_VIEW not in page
    # the erratum box
    assert '<div class="erratum admonition">' in page and "**Erratum" not in page
    # both kinds of solution, folded
    assert "SOLUTION-IN-CODE" in _text(page) and "SOLUTION-IN-MARKDOWN" in _text(page)
    assert "Show solution" in page and page.count("<details") >= 2
    assert not re.search(r"<details[^>]*\sopen", page)
    # section numbers are the notebook's own: no second numbering added
    assert re.search(r"<h2>7\.1 First section", page)
    # every image described: the figure from its data, the explorer by its text
    alts = re.findall(r'<img[^>]*alt="([^"]*)"', page)
    assert any("bump: starts at 0, highest 3 at time t [s] = 1" in html.unescape(a) for a in alts), alts
    assert "explorer (static figure)" in [html.unescape(a) for a in alts] and not any("_images/" in a for a in alts)
    # the smallest text of every figure recorded by its image (the browser test measures it); the
    # stand-in for an explorer is no figure: nothing to record
    record = json.loads((out / "_static" / site.FIGURE_RECORD).read_text(encoding="utf-8"))["smallest_text_pt"]
    images = {src: hashlib.sha256((out / src).read_bytes()).hexdigest()
              for src in re.findall(r'<img[^>]*src="(_images/[^"]*)"', page)}
    sizes = [record.get(digest) for digest in images.values()]
    assert len(sizes) == 2 and 10.0 in sizes and None in sizes, (images, record)
    assert site.SMALLEST_TEXT not in page and ALT not in page
    # no setup cell, placeholder or build-machine output; the notebook to download, stored clean
    assert "OWNER/NAME" not in page and "BUILD-MACHINE-VERSIONS" not in page
    assert "mybinder" not in page and "colab" not in page and "github.com" not in page  # no address yet
    link = re.search(r'<a[^>]*href="(_downloads/[^"]*07_small\.ipynb)"', page)
    assert link, "no download link to the chapter's notebook"
    downloaded = nbformat.read(out / link.group(1), as_version=4)
    assert not any(c.get("outputs") for c in downloaded.cells if c.cell_type == "code")
    # the notebook to download is no page of the site: no orphan copy, none in the search index
    assert not (out / "downloads").exists(), sorted(p.name for p in (out / "downloads").iterdir())
    assert "downloads/" not in (out / "searchindex.js").read_text(encoding="utf-8")


def test_small_build_student_site_has_no_solutions(small_site):
    index, page = small_site[0][True]
    link = re.search(r'<a[^>]*href="(_downloads/[^"]*07_small\.ipynb)"', page)
    downloaded = (index.parent / link.group(1)).read_text(encoding="utf-8")
    assert "SOLUTION" not in downloaded and "answer = None" in downloaded   # the student edition
    assert "student edition" in index.read_text(encoding="utf-8")
    assert "answer = None" in _text(page)
    assert "SOLUTION" not in _text(page) and "Show solution" not in page


@pytest.mark.parametrize("repository, github", [
    (None, None), ("https://github.com/OWNER", None), ("https://gitlab.com/a/b", None),
    ("https://github.com/uni-x/control-course.git", "https://github.com/uni-x/control-course"),
])
def test_repository_and_launch_buttons_appear_only_with_a_repository_address(repository, github):
    conf = {}
    exec(site.sphinx_conf(title="t", repository=repository), conf)     # the configuration Sphinx runs
    options = conf["html_theme_options"]
    assert options["use_repository_button"] == bool(github) and ("launch_buttons" in options) == bool(github)
    if github:
        assert options["repository_url"] == github and options["path_to_docs"] == "notebooks"
        assert set(options["launch_buttons"]) >= {"binderhub_url", "colab_url"}


#: put before the build's own Python processes (the build, the kernels, Sphinx): every connection
#: to a host other than this machine is refused, and noted in the file named by $CK_NETWORK_LOG
_NO_NETWORK = """
import os, socket
_connect = socket.socket.connect

def _refuse_outside(self, address, *args):
    host = address[0] if isinstance(address, tuple) else ""
    if self.family in (socket.AF_INET, socket.AF_INET6) and not (
            host.startswith("127.") or host in ("localhost", "::1")):
        with open(os.environ["CK_NETWORK_LOG"], "a") as log:
            log.write(f"{address}\\n")
        raise OSError(f"the network is refused in this test: {address}")
    return _connect(self, address, *args)

socket.socket.connect = _refuse_outside
"""


def test_the_site_builds_with_every_outside_connection_refused(small_site):
    # the probe cell's own attempt is the only one: the guard works, and the build asked for nothing
    assert small_site[2] == ["('192.0.2.1', 80)"]
