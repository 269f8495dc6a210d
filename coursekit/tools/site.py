"""The course website: the chapter notebooks, executed, as a static site that works offline.

``python -m coursekit site --out DIR`` calls :func:`build_site`. The build runs in a temporary
directory and needs no network:

1. read the chapter notebooks (`coursekit.tools.notebooks`);
2. execute each one once for both editions (`coursekit.tools.notebooks.execute_all`; the
   student edition, `coursekit.tools.release.student_text`, is the executed notebook without its
   solutions, unless a solution is code); MyST-NB shows no widget view
   (``nb_mime_priority_overrides``), which would be an empty area; the kernel draws every figure
   for the page's column, so that its smallest text is 11 CSS px or more at a 1,280-px window,
   describes it for its ``alt`` and notes the size of its smallest text, which the site
   records in ``_static/coursekit-figures.json`` (`coursekit.tools.site_figures`); it also
   renders each explorer's figure for the settings its sliders stop at, which the page swaps as
   native range inputs move, with no kernel (`coursekit.tools.static_explorers`);
3. rewrite the erratum paragraphs of the markdown cells into admonitions styled as boxes, and
   fold the old-style solution code cells behind a "Show solution" click (solutions written as
   markdown ``<details>`` blocks fold by themselves);
4. write a landing page (chapter table, how to run the notebooks) and a Sphinx configuration,
   and build the HTML with Sphinx, MyST-NB and the sphinx-book-theme (the Jupyter Book 1
   stack) without executing again. MathJax comes from the ``sphinx-mathjax-offline`` package
   and is copied into the site, so the pages typeset their equations with no network.

The Sphinx tools are the optional ``site`` extra (``pip install -e ".[site]"``); students do not
need them.
"""

from __future__ import annotations

import copy
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from . import static_explorers
from .builds import start_build
from .cells import ENVIRONMENT, INSTALL, is_solution, role
from .notebooks import (WIDGET_VIEW, execute_all, harvest_alt_texts, read_notebook, say, text_of,
                        write_notebook)
from .release import student_edition, student_text

__all__ = ["build_site", "erratum_admonitions", "fold_solution_code", "chapter_entry", "landing_page", "sphinx_conf",
           "missing_site_tools", "repository_of", "for_the_site", "github_repository", "SMALLEST_TEXT",
           "FIGURE_RECORD", "SITE_FIGURES", "figure_text_sizes"]

#: the theme's search button says "Search" to a screen reader but shows "Search ... Ctrl+K": its
#: accessible name becomes the text it shows (WCAG 2.5.3, label in name)
JS = """document.addEventListener("DOMContentLoaded", () => {
  for (const button of document.querySelectorAll("button.search-button__button")) {
    const shown = button.textContent.replace(/\\s+/g, " ").trim();
    if (shown) button.setAttribute("aria-label", shown);
  }
});
"""
SITE_TOOLS = {"sphinx": "sphinx", "myst_nb": "myst-nb", "sphinx_book_theme": "sphinx-book-theme",
              "sphinx-mathjax-offline": "sphinx-mathjax-offline", "nbclient": "nbclient",
              "nbformat": "nbformat", "ipykernel": "ipykernel"}

# An erratum paragraph starts with a bold lead such as "**Erratum (1.1).**" or
# "**Remark / erratum (1.9).**"; group 1 is the lead without its final period.
_ERRATUM_LEAD = re.compile(r"^\*\*((?:Erratum|Remark\s*/\s*erratum)\b[^*]*?)\.?\*\*\s*", re.IGNORECASE)
_CHAPTER_TITLE = re.compile(r"^#\s+(?:Chapter\s+(\d+)\s*[—:-]+\s*)?(.+?)\s*$", re.MULTILINE)
_SECTION = re.compile(r"^##\s+(\d+(?:\.\d+)+)\s+(.+?)\s*$", re.MULTILINE)

CSS = """\
/* coursekit site: erratum boxes and folded solutions */
div.admonition.erratum {
  border-color: #c2410c;
  background: #fff7ed;
}
div.admonition.erratum > .admonition-title {
  background: #ffedd5;
  color: #7c2d12;
}
div.admonition.erratum > .admonition-title::after { color: #c2410c; }
html[data-theme="dark"] div.admonition.erratum { background: #3b2314; }
html[data-theme="dark"] div.admonition.erratum > .admonition-title { background: #5a2e12; color: #ffedd5; }
section details {
  margin: 0.5em 0 1em 0;
}
/* the book theme keeps the sidebar toggle and the search in its own bars; newer releases of the
   pydata-sphinx-theme below it add a second, empty top bar that repeats the search field */
#pst-header { display: none; }
section details > summary {
  cursor: pointer;
  font-weight: 600;
  color: var(--pst-color-primary);
}
"""


def missing_site_tools() -> list[str]:
    """The pip names of the site tools that are not installed (empty when all are)."""
    return [pip_name for module, pip_name in SITE_TOOLS.items()
            if importlib.util.find_spec(module) is None]


def fold_solution_code(nb):
    """Fold every code cell tagged ``solution`` behind a "Show solution" click (in place).

    Solutions written as markdown cells (an HTML ``<details>`` block) fold by themselves and are
    left alone.
    """
    for cell in nb.cells:
        metadata = cell.setdefault("metadata", {})
        tags = metadata.get("tags", [])
        if cell.get("cell_type") == "code" and is_solution(cell):
            metadata["tags"] = [*tags, "hide-cell"] if "hide-cell" not in tags else tags
            metadata["mystnb"] = {**metadata.get("mystnb", {}),
                                  "code_prompt_show": "Show solution",
                                  "code_prompt_hide": "Hide solution"}
    return nb


def erratum_admonitions(markdown: str) -> str:
    """Rewrite each erratum of `markdown` as a MyST admonition with the class ``erratum``.

    An erratum is a paragraph, or a paragraph of a blockquote, that starts with a bold lead
    ``**Erratum ...**`` or ``**Remark / erratum ...**``. The lead becomes the box's title. In a
    blockquote, the paragraphs after an erratum up to the next erratum belong to it; outside a
    blockquote the box holds that one paragraph (and the block it announces when it ends in ":").
    Everything else is returned unchanged. The blocks are markdown-it-py's.
    """
    if not isinstance(markdown, str):
        raise TypeError(f"markdown must be a str, got {type(markdown).__name__}")
    from markdown_it import MarkdownIt
    lines, out, done = markdown.split("\n"), [], 0
    tokens = MarkdownIt("commonmark").parse(markdown)
    blocks = [t for t in tokens if t.level == 0 and t.map]
    i = 0
    while i < len(blocks):
        (start, end), lead = blocks[i].map, _ERRATUM_LEAD.match(lines[blocks[i].map[0]])
        out.extend(lines[done:start])
        if blocks[i].type == "paragraph_open" and lead:
            # a paragraph ending in ":" announces what follows (say a displayed equation): keep it
            while lines[end - 1].rstrip().endswith(":") and i + 1 < len(blocks):
                i, end = i + 1, blocks[i + 1].map[1]
            out.extend(_admonition(lead, lines[start:end]))
        elif blocks[i].type == "blockquote_open":
            out.extend(_quote(lines, start, end, [t.map for t in tokens if t.level == 1 and t.map
                                                  and start <= t.map[0] < end]))
        else:
            out.extend(lines[start:end])
        done, i = end, i + 1
    return "\n".join(out + lines[done:])


def _quote(lines: list[str], start: int, end: int, maps: list) -> list[str]:
    """The blockquote `lines[start:end]` (its blocks at `maps`) with its errata as admonitions; an
    erratum's box keeps the quote's following blocks up to the next erratum."""
    unquoted = [re.sub(r"^> ?", "", line) for line in lines]
    if not any(_ERRATUM_LEAD.match(unquoted[a]) for a, _ in maps):
        return lines[start:end]
    out, box = [], None
    for a, b in maps:
        paragraph, lead = unquoted[a:b], _ERRATUM_LEAD.match(unquoted[a])
        if lead:
            if box:
                out.extend(_admonition(*box) + [""])
            box = (lead, paragraph)
        elif box:
            box = (box[0], box[1] + [""] + paragraph)
        else:
            out.extend(["> " + line if line else ">" for line in paragraph] + [""])
    return out + _admonition(*box)


def _admonition(lead, paragraph):
    title = lead.group(1).strip()
    first = paragraph[0][lead.end():]
    body = ([first] if first.strip() else []) + paragraph[1:]
    return ["::::{admonition} " + title, ":class: erratum", *body, "::::"]


def chapter_entry(nb, page: str) -> dict:
    """Number, title and numbered sections of chapter notebook `nb`, for the landing page."""
    text = "\n\n".join(text_of(cell.source) for cell in nb.cells if cell.get("cell_type") == "markdown")
    title = _CHAPTER_TITLE.search(text)
    if title is None:
        raise ValueError(f"notebook {page!r} has no '# ' title line in its markdown cells")
    number = title.group(1) or page.split("_", 1)[0].lstrip("0")
    sections = [f"{num} {name}" for num, name in _SECTION.findall(text)]
    return {"number": number, "title": title.group(2), "page": page, "sections": sections}


def landing_page(chapters: list[dict], *, student: bool = False) -> str:
    """The MyST text of the landing page: the chapter table and how to run the notebooks."""
    edition = ("This is the **student edition**: the exercises are there, their solutions are not."
               if student else
               "Each exercise is followed by its worked solution, folded: click the line above it to open it.")
    rows = [f"| {c['number']} | [{c['title']}]({c['page']}.ipynb) | {' · '.join(c['sections'])} |"
            for c in chapters]
    toctree = "\n".join(c["page"] for c in chapters)
    return f"""# State-space control: the course notebooks

One notebook per chapter of the lecture notes, executed, with every figure. Section numbers and
equation numbers are those of the notes. Boxes marked *Erratum* point out slips in the notes and
show the corrected computation. {edition}

The explorers' sliders work on these pages too: each figure was computed when the site was built,
for the values the sliders stop at (a line under each explorer says which settings are live); a
running notebook computes every setting.

## Chapters

| chapter | notebook | sections |
|---|---|---|
{chr(10).join(rows)}

## Run the notebooks

Download or clone the course repository, then, from its root folder, in a fresh virtual
environment with Python 3.10 or newer:

```bash
python -m pip install -e ".[lab]"
python -m jupyterlab notebooks/
```

JupyterLab opens in the browser; open a chapter and use *Run > Run All Cells*. As root (a
container, a cloud machine) add `--allow-root` to the second command. The repository's
`environment.md` shows how to make the environment with venv, conda or uv.

```{{toctree}}
:hidden:
:maxdepth: 2

{toctree}
```
"""


def sphinx_conf(*, title: str, repository: str | None = None) -> str:
    """The Sphinx ``conf.py`` of the site: MyST-NB without execution, the book theme, MathJax
    offline; with the course repository's address on GitHub (`github_repository`), the theme's
    button to the repository and on each chapter its launch buttons (Binder, Colab), none before."""
    github = github_repository(repository)
    online = "" if github is None else f"""
    "repository_url": {github!r},
    "repository_branch": "main",
    "path_to_docs": "notebooks",
    "launch_buttons": {{"binderhub_url": "https://mybinder.org", "colab_url": "https://colab.research.google.com",
                       "notebook_interface": "jupyterlab"}},"""
    return f"""# generated by coursekit.tools.site; the site is rebuilt from the notebooks each time
project = {title!r}
author = "coursekit"
extensions = ["myst_nb", "sphinx-mathjax-offline"]
# downloads/ holds the notebooks to download (the {{download}} role copies them), not pages to build
exclude_patterns = ["_build", "**.ipynb_checkpoints", "downloads"]
master_doc = "index"
nb_execution_mode = "off"           # the notebooks arrive executed
nb_merge_streams = True
nb_render_markdown_format = "myst"  # markdown outputs (the exercise data) with $...$ math
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_dmath_double_inline = True
myst_heading_anchors = 3
suppress_warnings = ["myst.header", "mystnb.unknown_mime_type"]
# a widget's view is an empty area without a kernel: an explorer shows its figure, other widgets their text
nb_mime_priority_overrides = [("*", {WIDGET_VIEW!r}, None)]
html_theme = "sphinx_book_theme"
html_title = {title!r}
html_static_path = ["_static"]
html_css_files = ["coursekit.css", "ck-explorers/explorers.css"]
html_js_files = ["coursekit.js", "ck-explorers/explorers.js"]
html_theme_options = {{
    "home_page_in_toc": True,
    "show_toc_level": 2,
    "use_download_button": False,
    "use_fullscreen_button": False,
    "use_repository_button": {github is not None},{online}
    "use_source_button": False,
    "use_issues_button": False,
    "use_edit_page_button": False,
    "navigation_with_keys": False,
}}
html_show_sourcelink = False
html_context = {{"default_mode": "light"}}   # the theme logs an error when no mode is stored
html_copy_source = False
"""


def build_site(out_dir, *, student: bool = False, student_out=None, notebooks_dir=None,
               timeout: int = 600, verbose: bool = False) -> Path:
    """Build the course website into `out_dir` and return the path of its ``index.html``.

    `student=True` builds it from the student edition (no solutions); `student_out`, a second
    folder, also builds the student edition there from the same execution of the notebooks.
    `notebooks_dir` defaults to the repository's ``notebooks/``; `timeout` is the limit in
    seconds for one notebook cell; the pages get buttons to the repository, Binder and Colab
    once the notebooks' install cell holds its address on GitHub (``python -m coursekit
    colab``); `verbose=True` prints each step to stderr. Each output folder is replaced by its
    new site.
    """
    if not isinstance(student, bool):
        raise TypeError(f"student must be True or False, got {student!r}")
    if student and student_out is not None:
        raise ValueError("student_out builds the student edition beside the full one in out_dir: "
                         "pass student=False (no --student) with it")
    editions = {}
    for folder, is_student in [(out_dir, student)] + ([(student_out, True)] if student_out is not None else []):
        out, sources = start_build(folder, notebooks_dir, timeout=timeout, verbose=verbose,
                                   built_before=_built_before, kind="a site")
        if out in editions:
            raise ValueError(f"student_out {str(student_out)!r} is out_dir: pick another folder for the student edition")
        editions[out] = is_student
    missing = missing_site_tools()
    if missing:
        raise RuntimeError("the site tools are not installed (" + ", ".join(missing) + "): run "
                           "python -m pip install -e \".[site]\" from the repository root")
    with tempfile.TemporaryDirectory(prefix="coursekit-site-") as tmp:
        read = [read_notebook(path) for path in sources]
        executed = _executed(read, sources, editions=set(editions.values()), timeout=timeout, verbose=verbose)
        for n, (out, is_student) in enumerate(editions.items()):
            src = Path(tmp) / f"src{n}"
            chapters = [_page(nb, ran, path, src, student=is_student)
                        for nb, ran, path in zip(read, executed, sources)]
            _write_sources(src, chapters, student=is_student, repository=repository_of(read[0]))
            say(verbose, "the site", "building the HTML pages with Sphinx")
            _run_sphinx(src, Path(tmp) / f"html{n}")
            if out.exists():
                shutil.rmtree(out)
            shutil.copytree(Path(tmp) / f"html{n}", out)
    return next(iter(editions)) / "index.html"


def _shares_execution(nb) -> bool:
    """Whether the student edition of `nb` runs the same code as `nb`: no solution is code."""
    return not any(c.cell_type == "code" and is_solution(c) for c in nb.cells)


def _executed(notebooks: list, sources: list[Path], *, editions: set, timeout: int, verbose: bool) -> list:
    """Per notebook ``{student: (page, sizes)}``: its page executed for the editions of `editions`
    (True: the student edition), once for both unless a solution is code; each figure with its
    description as ``alt``, and the size of the smallest text of each image (`figure_text_sizes`)."""
    jobs = []
    for k, (nb, path) in enumerate(zip(notebooks, sources)):
        for student in sorted({False} if _shares_execution(nb) else editions):  # False serves both
            jobs.append((k, student, for_the_site(student_text(nb) if student else copy.deepcopy(nb), path.name)))
    execute_all([page for *_, page in jobs], [sources[k] for k, *_ in jobs], prelude=SITE_FIGURES,
                timeout=timeout, what="the site", verbose=verbose)
    executed = [{} for _ in notebooks]
    for k, student, page in jobs:
        harvest_alt_texts(page)
        page.metadata.pop("widgets", None)    # the state MyST-NB would load ipywidgets' script for
        for cell in page.cells:               # MyST-NB takes an image's alt from its cell
            alts = [o.metadata["image/png"]["alt"] for o in cell.get("outputs", [])
                    if "alt" in o.get("metadata", {}).get("image/png", {})]
            if alts:
                cell.metadata.setdefault("mystnb", {}).setdefault("image", {})["alt"] = " ".join(alts)
        executed[k][student] = (page, figure_text_sizes(page))
    return executed


def _page(nb, executed: dict, path: Path, src: Path, *, student: bool) -> dict:
    """Write chapter `nb` (read from `path`) into `src` as its page shows it in the edition asked
    for, from `executed` (see `_executed`), with the notebook to download; its landing entry."""
    (src / "downloads").mkdir(parents=True, exist_ok=True)
    write_notebook(student_edition(nb) if student else nb, src / "downloads" / path.name)
    page, sizes = copy.deepcopy(executed.get(student, executed.get(False)))
    if student:
        page = student_text(page)       # no change where the student edition was executed
    frames = static_explorers.publish(page, src / "_static" / static_explorers.ASSETS,
                                      f"_static/{static_explorers.ASSETS}", stem=path.stem)
    fold_solution_code(page)
    for cell in page.cells:
        if cell.cell_type == "markdown":
            cell.source = erratum_admonitions(text_of(cell.source))
    write_notebook(page, src / path.name)
    sizes.update({f["sha256"]: f["smallest_text_pt"] for f in frames if f["smallest_text_pt"] is not None})
    return {**chapter_entry(page, path.stem), "smallest_text_pt": sizes, "frames": frames}


def _built_before(folder: Path) -> bool:
    """Whether `folder` holds a site built before (which a new build may replace)."""
    return (folder / "index.html").is_file() and (folder / "_static").is_dir()


def repository_of(nb) -> str | None:
    """The course repository's https address, as the install cell of `nb` holds it (None until
    ``python -m coursekit colab`` has written one)."""
    from .colab import cell_repository
    return next((cell_repository(text_of(c.source)) for c in nb.cells if role(c) == INSTALL), None)


def for_the_site(nb, name: str):
    """`nb` as its page shows it: without the setup cells (the install cell and the environment
    check, whose output is the build machine's), with a line under its title to download the
    notebook as it is handed out (the theme's download button would give the page's source: the
    notebook executed and rewritten for the site)."""
    import nbformat
    nb.cells = [c for c in nb.cells if role(c) not in (INSTALL, ENVIRONMENT)]
    nb.cells.insert(1, nbformat.v4.new_markdown_cell(
        f"Download this chapter as a notebook: {{download}}`{name} <downloads/{name}>`"))
    return nb


#: the media type under which it adds the size of each figure's smallest text, in points
SMALLEST_TEXT = "text/x-coursekit-smallest-text-pt"
#: the file of the site, under ``_static``, that gives the size in points of the smallest text of
#: each image and the resolution of the explorers' frames, which WebP does not carry
#: (``{"smallest_text_pt": {sha256 of the image: size}, "dpi": {sha256 of a frame: dots per inch}}``)
FIGURE_RECORD = "coursekit-figures.json"

#: run first in each notebook the site executes: figures and explorers drawn for the page's
#: column, each with its description and the size of its smallest text (see `site_figures`)
SITE_FIGURES = """\
import coursekit.tools.site_figures as _site_figures
_site_figures.install(get_ipython())
"""


def figure_text_sizes(nb) -> dict[str, float]:
    """Remove the `SMALLEST_TEXT` data from the outputs of `nb` (in place) and return them as
    {SHA-256 of the output's PNG: size in points of the smallest text of that image}."""
    import base64
    import hashlib
    sizes = {}
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            size = text_of(data.pop(SMALLEST_TEXT, "None"))
            if size != "None" and "image/png" in data:
                png = base64.b64decode(text_of(data["image/png"]))
                sizes[hashlib.sha256(png).hexdigest()] = float(size)
    return sizes


def _write_sources(src: Path, chapters: list[dict], *, student: bool, repository: str | None) -> None:
    title = "Course notebooks (student edition)" if student else "Course notebooks"
    (src / "index.md").write_text(landing_page(chapters, student=student), encoding="utf-8")
    (src / "conf.py").write_text(sphinx_conf(title=title, repository=repository), encoding="utf-8")
    (src / "_static").mkdir(exist_ok=True)      # the explorers' frames may be there already
    static_explorers.copy_assets(src / "_static" / static_explorers.ASSETS)
    frames = [f for chapter in chapters for f in chapter.get("frames", [])]
    static_explorers.check_site_budget(frames, what="the site")
    (src / "_static" / "coursekit.css").write_text(CSS, encoding="utf-8")
    (src / "_static" / "coursekit.js").write_text(JS, encoding="utf-8")
    record = {digest: size for chapter in chapters for digest, size in chapter.get("smallest_text_pt", {}).items()}
    dpi = {f["sha256"]: f["dpi"] for f in frames}        # a WebP frame does not carry its resolution
    (src / "_static" / FIGURE_RECORD).write_text(json.dumps({"smallest_text_pt": record, "dpi": dpi}, indent=1),
                                                 encoding="utf-8")


def github_repository(repository: str | None) -> str | None:
    """`repository` as the book theme's buttons take it when it is an https address on GitHub
    (``https://github.com/OWNER/NAME``, no ``.git``), else None: no link is published before it
    can work (Binder and Colab open GitHub repositories)."""
    match = re.fullmatch(r"https://github\.com/([\w.-]+/[\w.-]+?)(?:\.git)?/?", repository or "")
    return f"https://github.com/{match.group(1)}" if match else None


#: sphinx-build (its own entry, ``sphinx.cmd.build.main``, as ``python -m sphinx`` runs it) in a
#: process spared the IRI grammar that MyST-NB's import of nbformat would build
#: (`coursekit.tools.notebooks.leave_out_the_iri_grammar`)
_SPHINX_BUILD = [sys.executable, "-c", "import sys; from coursekit.tools.notebooks import leave_out_the_iri_grammar; "
                 "leave_out_the_iri_grammar(); from sphinx.cmd.build import main; sys.exit(main(sys.argv[1:]))"]


def _run_sphinx(src: Path, html: Path) -> None:
    cmd = [*_SPHINX_BUILD, "-b", "html", "-q", "-j", "auto", str(src), str(html), "-d", str(src.parent / "doctrees")]
    result = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, PYTHONWARNINGS="ignore"))
    if result.returncode != 0:
        raise RuntimeError(f"Sphinx failed to build the site (exit {result.returncode}):\n"
                           f"{result.stderr[-4000:]}")
