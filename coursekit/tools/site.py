"""The course website: the chapter notebooks, executed, as a static site that works offline.

``python -m coursekit site --out DIR`` calls :func:`build_site`. The build runs in a temporary
directory and needs no network:

1. copy the chapter notebooks (for ``student=True`` the student edition: solutions removed);
2. execute each one with nbclient, without storing widget state, and drop the widget views
   from the outputs, so that no empty widget area is left; the kernel draws every figure
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

import concurrent.futures
import importlib.util
import json
import multiprocessing
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from . import static_explorers
from .cells import ENVIRONMENT, INSTALL, is_solution, role
from .builds import start_build

__all__ = [
    "build_site",
    "erratum_admonitions",
    "fold_solution_code",
    "strip_widget_views",
    "chapter_entry",
    "landing_page",
    "sphinx_conf",
    "missing_site_tools",
    "repository_of",
    "for_the_site",
    "run_online",
    "describe_images",
    "figure_text_sizes",
    "WIDGET_VIEW", "ALT", "SMALLEST_TEXT",
]

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"

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


def strip_widget_views(nb):
    """Remove the widget views from every output of `nb` (in place) and return `nb`.

    Without a kernel a widget view renders as an empty area; the explorers also carry a static
    ``image/png`` in the same output, which is what the site shows. An output left with no data
    at all is dropped.
    """
    for cell in nb.cells:
        if cell.get("cell_type") != "code":
            continue
        kept = []
        for output in cell.get("outputs", []):
            data = output.get("data")
            if data is not None and WIDGET_VIEW in data:
                del data[WIDGET_VIEW]
                if not data:
                    continue
            kept.append(output)
        cell["outputs"] = kept
    nb.metadata.pop("widgets", None)
    return nb


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
    blockquote the box holds that one paragraph. Everything else is returned unchanged.
    """
    if not isinstance(markdown, str):
        raise TypeError(f"markdown must be a str, got {type(markdown).__name__}")
    out: list[str] = []
    for block, quoted in _blocks(markdown.split("\n")):
        out.extend(_rewrite_block(block, quoted))
    return "\n".join(out)


def _blocks(lines):
    """Split lines into runs of blockquote lines and runs of other lines (code fences kept whole)."""
    block, quoted, fenced = [], None, False
    for line in lines:
        if line.lstrip().startswith("```"):
            fenced = not fenced
        is_quote = not fenced and line.startswith(">")
        if block and is_quote != quoted:
            yield block, quoted
            block = []
        block.append(line)
        quoted = is_quote
    if block:
        yield block, quoted


def _rewrite_block(lines, quoted):
    if quoted:
        body = [re.sub(r"^> ?", "", line) for line in lines]
        paragraphs = _paragraphs(body)
        if not any(_ERRATUM_LEAD.match(p[0]) for p in paragraphs):
            return lines
        return _quote_admonitions(paragraphs)
    out, groups, i = [], _paragraphs(lines, keep_blank=True), 0
    while i < len(groups):
        lead = _ERRATUM_LEAD.match(groups[i][0])
        if not lead:
            out.extend(groups[i])
            i += 1
            continue
        box = groups[i]
        i += 1
        # a paragraph ending in ":" announces what follows (say a displayed equation): keep it
        while box[-1].rstrip().endswith(":") and i + 1 < len(groups) and not groups[i][0].strip():
            box = box + groups[i] + groups[i + 1]
            i += 2
        out.extend(_admonition(lead, box))
    return out


def _paragraphs(lines, keep_blank=False):
    """Group lines into paragraphs (a fenced code block stays whole); with keep_blank the blank
    lines between paragraphs are groups of their own."""
    groups, current, fenced = [], [], False
    for line in lines:
        if line.lstrip().startswith("```"):
            fenced = not fenced
        if line.strip() or fenced:
            current.append(line)
            continue
        if current:
            groups.append(current)
            current = []
        if keep_blank:
            groups.append([line])
    if current:
        groups.append(current)
    return groups


def _quote_admonitions(paragraphs):
    """Blockquote paragraphs -> admonitions; an erratum's box keeps its following paragraphs."""
    out, box = [], None
    for paragraph in paragraphs:
        lead = _ERRATUM_LEAD.match(paragraph[0])
        if lead:
            if box:
                out.extend(_admonition(*box) + [""])
            box = (lead, paragraph)
        elif box:
            box = (box[0], box[1] + [""] + paragraph)
        else:
            out.extend(["> " + line if line else ">" for line in paragraph] + [""])
    out.extend(_admonition(*box))
    return out


def _admonition(lead, paragraph):
    title = lead.group(1).strip()
    first = paragraph[0][lead.end():]
    body = ([first] if first.strip() else []) + paragraph[1:]
    return ["::::{admonition} " + title, ":class: erratum", *body, "::::"]


def chapter_entry(nb, page: str) -> dict:
    """Number, title and numbered sections of chapter notebook `nb`, for the landing page."""
    text = "\n\n".join(_source(cell) for cell in nb.cells if cell.get("cell_type") == "markdown")
    title = _CHAPTER_TITLE.search(text)
    if title is None:
        raise ValueError(f"notebook {page!r} has no '# ' title line in its markdown cells")
    number = title.group(1) or page.split("_", 1)[0].lstrip("0")
    sections = [f"{num} {name}" for num, name in _SECTION.findall(text)]
    return {"number": number, "title": title.group(2), "page": page, "sections": sections}


def _source(cell) -> str:
    source = cell.get("source", "")
    return "".join(source) if isinstance(source, list) else source


def landing_page(chapters: list[dict], *, student: bool = False, run_online: str = "") -> str:
    """The MyST text of the landing page: the chapter table and how to run the notebooks."""
    edition = ("This is the **student edition**: the exercises are there, their solutions are not."
               if student else
               "Each exercise is followed by its worked solution, folded: click the line above it to open it.")
    rows = [f"| {c['number']} | [{c['title']}]({c['page']}.ipynb) | {' · '.join(c['sections'])} |"
            for c in chapters]
    online = f"\n### Run online\n\n{run_online.strip()}\n" if run_online.strip() else ""
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
{online}
```{{toctree}}
:hidden:
:maxdepth: 2

{toctree}
```
"""


def sphinx_conf(*, title: str) -> str:
    """The Sphinx ``conf.py`` of the site: MyST-NB without execution, the book theme, MathJax offline."""
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
    "use_repository_button": False,
    "use_source_button": False,
    "use_issues_button": False,
    "use_edit_page_button": False,
    "navigation_with_keys": False,
}}
html_show_sourcelink = False
html_context = {{"default_mode": "light"}}   # the theme logs an error when no mode is stored
html_copy_source = False
"""


def build_site(out_dir, *, student: bool = False, notebooks_dir=None, timeout: int = 600,
               verbose: bool = False) -> Path:
    """Build the course website into `out_dir` and return the path of its ``index.html``.

    `student=True` builds it from the student edition (no solutions). `notebooks_dir` defaults to
    the repository's ``notebooks/``; `timeout` is the limit in seconds for one notebook cell;
    the landing page links to Binder, Colab and the repository once the notebooks' install cell
    holds the repository's address (``python -m coursekit colab``); `verbose=True` prints each
    step to stderr. `out_dir` is replaced by the new site.
    """
    if not isinstance(student, bool):
        raise TypeError(f"student must be True or False, got {student!r}")
    out, sources = start_build(out_dir, notebooks_dir, timeout=timeout, verbose=verbose,
                               built_before=_built_before, kind="a site")
    missing = missing_site_tools()
    if missing:
        raise RuntimeError("the site tools are not installed (" + ", ".join(missing) + "): run "
                           "python -m pip install -e \".[site]\" from the repository root")
    with tempfile.TemporaryDirectory(prefix="coursekit-site-") as tmp:
        src = Path(tmp) / "src"
        src.mkdir()
        chapters = _prepare_all(sources, src, student=student, timeout=timeout, verbose=verbose)
        import nbformat
        _write_sources(src, chapters, student=student,
                       repository=repository_of(nbformat.read(sources[0], as_version=4)))
        html = Path(tmp) / "html"
        _say(verbose, "building the HTML pages with Sphinx")
        _run_sphinx(src, html)
        if out.exists():
            shutil.rmtree(out)
        shutil.copytree(html, out)
    return out / "index.html"


def _built_before(folder: Path) -> bool:
    """Whether `folder` holds a site built before (which a new build may replace)."""
    return (folder / "index.html").is_file() and (folder / "_static").is_dir()


def _say(verbose: bool, message: str) -> None:
    if verbose:
        print(f"coursekit site: {message}", file=sys.stderr, flush=True)


def _prepare_all(sources: list[Path], src: Path, *, student: bool, timeout: int,
                 verbose: bool) -> list[dict]:
    """Prepare every notebook, one worker process (and kernel) per core, in chapter order."""
    workers = max(1, min(len(sources), os.cpu_count() or 1))
    _say(verbose, f"executing {len(sources)} notebooks, {workers} at a time")
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        futures = [pool.submit(_prepare, path, src, student=student, timeout=timeout)
                   for path in sources]
        chapters = []
        for path, future in zip(sources, futures):
            chapters.append(future.result())
            _say(verbose, f"executed {path.name}")
    return chapters


def _prepare(path: Path, src: Path, *, student: bool, timeout: int) -> dict:
    """Read, edit, execute and write one chapter notebook into `src`; return its landing entry."""
    import nbformat
    nb = nbformat.read(path, as_version=4)
    if student:
        from .release import student_edition   # the one definition of the student edition
        nb = student_edition(nb)
    (src / "downloads").mkdir(exist_ok=True)
    nbformat.write(nb, src / "downloads" / path.name)       # the notebook as a reader downloads it
    nb = for_the_site(nb, path.name, repository=repository_of(nb))
    nb.cells.insert(0, nbformat.v4.new_code_cell(SITE_FIGURES))
    _execute(nb, cwd=path.parent, timeout=timeout, name=path.name)
    nb.cells.pop(0)
    describe_images(nb)
    sizes = figure_text_sizes(nb)
    strip_widget_views(nb)
    frames = static_explorers.publish(nb, src / "_static" / static_explorers.ASSETS,
                                      f"_static/{static_explorers.ASSETS}", stem=path.stem)
    fold_solution_code(nb)
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            cell.source = erratum_admonitions(_source(cell))
    nbformat.write(nb, src / path.name)
    sizes.update({f["sha256"]: f["smallest_text_pt"] for f in frames if f["smallest_text_pt"] is not None})
    return {**chapter_entry(nb, path.stem), "smallest_text_pt": sizes, "frames": frames}


def repository_of(nb) -> str | None:
    """The course repository's https address, as the install cell of `nb` holds it (None until
    ``python -m coursekit colab`` has written one)."""
    from .colab import cell_repository
    return next((cell_repository(_source(c)) for c in nb.cells if role(c) == INSTALL), None)


def for_the_site(nb, name: str, *, repository: str | None = None):
    """`nb` as its page shows it: without the setup cells (the install cell and the environment
    check, whose output is the build machine's), with a line to download the notebook under its
    title (and to the repository, when its address is known)."""
    import nbformat
    nb.cells = [c for c in nb.cells if role(c) not in (INSTALL, ENVIRONMENT)]
    where = f" · [the course repository]({repository})" if repository else ""
    nb.cells.insert(1, nbformat.v4.new_markdown_cell(
        f"Download this chapter as a notebook: {{download}}`{name} <downloads/{name}>`{where}"))
    return nb


#: the media type under which the kernel adds each figure's description to its display data
ALT = "text/x-coursekit-alt"
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


def describe_images(nb):
    """Give each code cell's images of `nb` their descriptions as ``alt`` (in place; returned):
    a figure's from `ALT`, an explorer's from its text (title, settings, readout and data)."""
    for cell in nb.cells:
        texts = []
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if ALT in data:
                texts.append(_source({"source": data.pop(ALT)}))
            elif "image/png" in data and WIDGET_VIEW in data:
                texts.append(_source({"source": data.get("text/plain", "")}))
        if texts:
            mystnb = cell.metadata.setdefault("mystnb", {})
            mystnb["image"] = {**mystnb.get("image", {}), "alt": " ".join(texts)}
    return nb


def figure_text_sizes(nb) -> dict[str, float]:
    """Remove the `SMALLEST_TEXT` data from the outputs of `nb` (in place) and return them as
    {SHA-256 of the output's PNG: size in points of the smallest text of that image}."""
    import base64
    import hashlib
    sizes = {}
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            size = _source({"source": data.pop(SMALLEST_TEXT, "None")})
            if size != "None" and "image/png" in data:
                png = base64.b64decode(_source({"source": data["image/png"]}))
                sizes[hashlib.sha256(png).hexdigest()] = float(size)
    return sizes


def _execute(nb, *, cwd: Path, timeout: int, name: str) -> None:
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError
    client = NotebookClient(nb, timeout=timeout, kernel_name="python3", store_widget_state=False,
                            resources={"metadata": {"path": str(cwd)}})
    try:
        client.execute()
    except CellExecutionError as error:
        raise RuntimeError(f"notebook {name} failed while building the site:\n{error}") from None


def _write_sources(src: Path, chapters: list[dict], *, student: bool, repository: str | None) -> None:
    title = "Course notebooks (student edition)" if student else "Course notebooks"
    (src / "index.md").write_text(landing_page(chapters, student=student, run_online=run_online(repository)),
                                  encoding="utf-8")
    (src / "conf.py").write_text(sphinx_conf(title=title), encoding="utf-8")
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


def run_online(repository: str | None) -> str:
    """The landing page's "Run online" text for the course repository at `repository` (an https
    address on GitHub), or '' when there is none: no link is published before it can work."""
    match = re.fullmatch(r"https://github\.com/([\w.-]+/[\w.-]+?)(?:\.git)?/?", repository or "")
    if match is None:
        return ""
    path = match.group(1)
    return (f"Open a chapter on [Binder](https://mybinder.org/v2/gh/{path}/HEAD?urlpath=lab/tree/notebooks) "
            f"(a temporary JupyterLab; nothing is saved) or on Google Colab "
            f"(https://colab.research.google.com/github/{path}/blob/main/notebooks/, then the chapter's file "
            f"name), or get everything from [the course repository]({repository}).")


def _run_sphinx(src: Path, html: Path) -> None:
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-q", "-j", "auto", str(src), str(html),
           "-d", str(src.parent / "doctrees")]
    result = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, PYTHONWARNINGS="ignore"))
    if result.returncode != 0:
        raise RuntimeError(f"Sphinx failed to build the site (exit {result.returncode}):\n"
                           f"{result.stderr[-4000:]}")
