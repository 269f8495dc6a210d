"""The course's slides: ``python -m coursekit slides --out DIR`` calls :func:`build_slides`.

Every chapter notebook (found by `coursekit.tools.notebooks`) becomes one reveal.js slide show,
executed, in one folder with an index page that links them. The build needs no network and
neither do the slides:

1. each notebook gets the slide types of `coursekit.tools.slides` (in memory: the notebooks
   are not rewritten) and is executed (`coursekit.tools.notebooks.execute_all`); each figure gets
   its text alternative from its data (`coursekit.tools.notebooks.harvest_alt_texts`), as on the website
   (`DESCRIBE_FIGURES`, with the website's `coursekit.tools.site_figures.add_output`), and each
   explorer its frames for the settings its sliders stop at: on the slides its sliders are native
   range inputs that swap the frames, with no kernel (`coursekit.tools.static_explorers`);
2. nbconvert's ``SlidesExporter`` writes the slides with the template ``coursekit_reveal``
   (shipped in this package), which extends nbconvert's reveal template and loads reveal.js and
   MathJax 3 from the folder: no jQuery, require.js or mermaid from a CDN, no MathJax 2 (whose
   preview spans left the first slide's equations on screen twice), and the reveal.js theme
   ``white``, whose fonts ship with reveal.js (``simple``, nbconvert's default, loads Google
   Fonts). MathJax typesets the slides, and only them, before reveal.js starts: reveal.js copies
   the text of the slide shown into a live region for screen readers, and that copy must be the
   typeset equations, not TeX for MathJax to typeset a second time. The slides are 1280 x 800
   without the ``In [n]:`` prompts, so that a line of the notebooks' code fits; a sub-slide
   taller than that is cut into sub-slides that fit, in the page before reveal.js starts (the
   template's script measures the typeset slides);
3. reveal.js (from the PyPI package ``sphinx-revealjs``) and MathJax 3 (from
   ``sphinx-mathjax-offline``, which the website uses too) are copied into the folder.

The tools are the optional ``slides`` extra (``pip install -e ".[slides]"``).
"""

from __future__ import annotations

import html
import importlib.util
import shutil
import tempfile
from pathlib import Path
from typing import Callable

from . import static_explorers
from .builds import start_build
from .notebooks import ALT, execute_all, harvest_alt_texts, read_notebook, say
from .site import chapter_entry
from .slides import with_slide_metadata

__all__ = ["SLIDE_TOOLS", "DESCRIBE_FIGURES", "TEMPLATE", "MATHJAX", "SUFFIX", "build_slides", "missing_slide_tools",
           "asset_folders", "slides_exporter", "index_page"]

#: import name -> pip name of what the build needs (the ``slides`` extra)
SLIDE_TOOLS = {"nbconvert": "nbconvert", "nbclient": "nbclient", "nbformat": "nbformat",
               "ipykernel": "ipykernel", "sphinx_revealjs": "sphinx-revealjs",
               "sphinx-mathjax-offline": "sphinx-mathjax-offline"}

#: run first in each notebook the slides execute: every figure gets its description under `ALT`
#: (the figures themselves are drawn as in JupyterLab: a slide is as wide as the screen), every
#: explorer its frames (`coursekit.tools.static_explorers`)
DESCRIBE_FIGURES = f"""\
import coursekit.tools.site_figures as _site_figures
from coursekit import describe_figure as _describe
_site_figures.add_output(get_ipython(), {ALT!r}, _describe, explorers=False)
import coursekit.tools.static_explorers as _static_explorers
_static_explorers.install(get_ipython(), column=False)
"""

#: the nbconvert template of the slides, a folder of this package
TEMPLATE = Path(__file__).resolve().parent / "templates" / "coursekit_reveal"

#: where each asset is found: (pip name, folder inside the package, a file it must hold)
_ASSETS = {"reveal.js": ("sphinx-revealjs", "sphinx_revealjs", "_static/revealjs", "dist/reveal.js"),
           "mathjax": ("sphinx-mathjax-offline", "sphinx-mathjax-offline", "static/mathjax",
                       "tex-chtml-full.js")}

#: the MathJax 3 component the slides load (TeX in, HTML out, every TeX extension in one file)
MATHJAX = "mathjax/tex-chtml-full.js"
#: a chapter's slides are NOTEBOOK_STEM + SUFFIX in the folder (nbconvert's name for them)
SUFFIX = ".slides.html"
_INSTALL = "python -m pip install -e \".[slides]\" from the repository root"


def missing_slide_tools() -> list[str]:
    """The pip names of the slide tools that are not installed (empty when all are)."""
    return [pip_name for module, pip_name in SLIDE_TOOLS.items()
            if importlib.util.find_spec(module) is None]


def asset_folders() -> dict[str, Path]:
    """``{"reveal.js": folder, "mathjax": folder}``: the installed copies the slides load."""
    folders = {}
    for name, (pip_name, module, inside, probe) in _ASSETS.items():
        spec = importlib.util.find_spec(module)
        folder = Path(spec.submodule_search_locations[0]) / inside if spec else None
        if folder is None or not (folder / probe).is_file():
            raise RuntimeError(f"{name} not found: the package {pip_name} is missing or does not ship "
                               f"{inside}/{probe}; run {_INSTALL}")
        folders[name] = folder
    return folders


def slides_exporter():
    """nbconvert's ``SlidesExporter`` with the course's template and the assets in the folder."""
    from nbconvert import SlidesExporter
    return SlidesExporter(template_name=TEMPLATE.name, extra_template_basedirs=[str(TEMPLATE.parent)],
                          reveal_url_prefix="reveal.js", reveal_theme="white", reveal_scroll=True,
                          exclude_input_prompt=True, exclude_output_prompt=True, mathjax_url=MATHJAX)


def index_page(chapters: list[dict]) -> str:
    """The index page: one link per chapter (entries of `coursekit.tools.site.chapter_entry`)."""
    items = "\n".join(
        f'<li><a href="{html.escape(c["page"])}{SUFFIX}">Chapter {html.escape(c["number"])}: '
        f'{html.escape(c["title"])}</a><br>{html.escape(" · ".join(c["sections"]))}</li>'
        for c in chapters)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>State-space control: the course slides</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 50em; margin: 2em auto; padding: 0 1em;
        line-height: 1.5; color: #1a1a1a; }}
li {{ margin-bottom: 1em; }}
a {{ color: #0645ad; font-weight: 600; }}
kbd {{ border: 1px solid #767676; border-radius: 3px; padding: 0 0.3em; }}
</style>
</head>
<body>
<main>
<h1>State-space control: the course slides</h1>
<p>One slide show per chapter of the lecture notes, executed: every figure is there, and the
explorers' sliders work, each figure computed when the slides were built for the values the
sliders stop at (a line under each explorer says which settings are live; a running notebook
computes every setting). The slides work without a network.</p>
<p>Keys: <kbd>→</kbd> next section, <kbd>↓</kbd> next part of a section (or <kbd>Space</kbd>
for the next slide in order), <kbd>Esc</kbd> overview, <kbd>S</kbd> speaker view.</p>
<ol>
{items}
</ol>
</main>
</body>
</html>
"""


def build_slides(out_dir, *, notebooks_dir=None, timeout: int = 600, verbose: bool = False,
                 execute: Callable = execute_all) -> Path:
    """Build the slides of every chapter into `out_dir`; return the path of its ``index.html``.

    `notebooks_dir` defaults to the repository's ``notebooks/``; `timeout` is the limit in
    seconds for one notebook cell; `verbose=True` prints each step to stderr. `out_dir` is
    replaced by the new slides (a folder holding anything else is refused). `execute` executes
    the chapters, called as `coursekit.tools.notebooks.execute_all` (the default) is: another
    function there may hand some notebooks outputs executed already (the tests replay theirs).
    """
    out, sources = start_build(out_dir, notebooks_dir, timeout=timeout, verbose=verbose,
                               built_before=_built_before, kind="slides")
    missing = missing_slide_tools()
    if missing:
        raise RuntimeError(f"the slide tools are not installed ({', '.join(missing)}): run {_INSTALL}")
    assets = asset_folders()
    notebooks = [with_slide_metadata(read_notebook(path)) for path in sources]
    execute(notebooks, sources, prelude=DESCRIBE_FIGURES, timeout=timeout, what="the slides", verbose=verbose)
    for nb in notebooks:
        harvest_alt_texts(nb)
    with tempfile.TemporaryDirectory(prefix="coursekit-slides-") as tmp:
        folder = Path(tmp) / "slides"
        folder.mkdir()
        say(verbose, "the slides", "writing the slides")
        frames = []
        chapters = [_write_chapter(nb, path, folder, frames) for nb, path in zip(notebooks, sources)]
        static_explorers.check_site_budget(frames, what="the slides")
        static_explorers.copy_assets(folder / static_explorers.ASSETS)
        for name, source in assets.items():
            shutil.copytree(source, folder / name)
        (folder / "index.html").write_text(index_page(chapters), encoding="utf-8")
        if out.exists():
            shutil.rmtree(out)
        shutil.copytree(folder, out)
    return out / "index.html"


def _built_before(folder: Path) -> bool:
    """Whether `folder` holds slides built before (which a new build may replace)."""
    return (folder / "index.html").is_file() and all((folder / name).is_dir() for name in _ASSETS)


def _write_chapter(nb, path: Path, folder: Path, frames: list) -> dict:
    """Write the slides of the executed notebook `nb` (read from `path`) and its explorers' frames
    (their entries added to `frames`); return its index entry."""
    frames += static_explorers.publish(nb, folder / static_explorers.ASSETS, static_explorers.ASSETS,
                                       stem=path.stem)
    entry = chapter_entry(nb, path.stem)
    nb.metadata["title"] = f"Chapter {entry['number']}: {entry['title']}"
    body, _ = slides_exporter().from_notebook_node(nb, resources={"metadata": {"name": path.stem}})
    (folder / f"{path.stem}{SUFFIX}").write_text(body, encoding="utf-8")
    return entry
