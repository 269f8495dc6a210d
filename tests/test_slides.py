"""The slides: the notebooks' slide metadata, and the slides of the course built and shown.

* Slide metadata: every section is a slide, and the stored metadata is what the tool writes.
* The build (``python -m coursekit slides --out DIR``): its pieces, and one small chapter built
  from the command line with every outside connection refused (skipped without the slides extra).
* In a browser (marker ``browser``): the whole course built once, every chapter opened from the
  disk in headless Chromium with every request that leaves the folder refused and recorded. A
  chapter fails on an outside request, a local file that does not load, a console error, an
  equation not typeset or typeset more than once (the rendered equations must be exactly the TeX
  sources of the page as written), TeX left in the text, reveal.js not started or not following
  the keys, an explorer without its figure, an image without a text alternative, or a WCAG 2.1
  AA violation found by axe-core (on every slide, laid out with reveal.js's print view).
"""

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from coursekit.__main__ import main
from coursekit.tools import notebooks as notebook_module, slideshow
from coursekit.tools.notebooks import ALT, WIDGET_VIEW, chapter_notebooks, default_notebook_dir, read_notebook
from coursekit.tools.slides import apply_slide_metadata, slide_types, with_slide_metadata

import lab_harness  # the browser tests' Chromium location, settings and axe-core
import static_explorer_checks  # the explorers' sliders on a static page

NOTEBOOKS = sorted(default_notebook_dir().glob("*.ipynb"))


def _stored(cell):
    return cell.metadata.get("slideshow", {}).get("slide_type", "-")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_section_heading_is_a_slide_and_every_subsection_a_subslide(path):
    nb = read_notebook(path)
    headings = {2: 0, 3: 0}
    for cell in nb.cells:
        first = cell.source.split("\n", 1)[0] if cell.cell_type == "markdown" else ""
        if first.startswith(("# ", "## ")):
            assert _stored(cell) == "slide", first
            headings[2] += first.startswith("## ")
        elif first.startswith(("### ", "#### ")):
            assert _stored(cell) == "subslide", first
            headings[3] += 1
    assert headings[2] >= 2 and headings[3] >= 1, headings     # sections, at least the exercises


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_setup_cells_are_skipped_and_sections_are_not(path):
    nb = read_notebook(path)
    first_section = next(i for i, c in enumerate(nb.cells) if c.source.startswith("## "))
    assert [_stored(c) for c in nb.cells[1:first_section]] == ["skip"] * (first_section - 1)
    assert "skip" not in [_stored(c) for c in nb.cells[first_section:]]
    marks = [c.metadata.get("coursekit") for c in nb.cells[1:first_section]]
    assert "install" in marks and "environment" in marks


def test_stored_slide_metadata_is_up_to_date():
    stale = apply_slide_metadata(write=False)
    assert not stale, f"run: python -m coursekit slides (out of date: {[p.name for p in stale]})"


def _small():
    v4 = nbformat.v4
    return v4.new_notebook(cells=[
        v4.new_markdown_cell("# Title"),
        v4.new_code_cell("import numpy as np"),
        v4.new_markdown_cell("## 1 Section"),
        v4.new_markdown_cell("Text."),
        v4.new_code_cell("x = 1"),
        v4.new_markdown_cell("More text after code."),
        v4.new_code_cell("y = 2"),
        v4.new_markdown_cell("### 1.1 Subsection"),
        v4.new_markdown_cell("#hashtag is not a heading"),
    ])


def test_slide_types_follow_the_rules():
    assert slide_types(_small()) == ["slide", "skip", "slide", "-", "-", "subslide", "-", "subslide", "-"]


def test_dash_cells_carry_no_metadata_and_rewriting_changes_nothing():
    nb = with_slide_metadata(_small())
    assert ["slideshow" in c.metadata for c in nb.cells] == [True, True, True, False, False, True, False,
                                                              True, False]
    again = nbformat.writes(with_slide_metadata(nbformat.reads(nbformat.writes(nb), as_version=4)))
    assert again == nbformat.writes(nb)


def test_cli_slides_check_and_write(tmp_path, capsys):
    nbformat.write(_small(), str(tmp_path / "a.ipynb"))
    assert main(["slides", "--notebooks", str(tmp_path), "--check"]) == 1
    assert "slide metadata out of date: a.ipynb" in capsys.readouterr().out
    assert main(["slides", "--notebooks", str(tmp_path)]) == 0
    assert main(["slides", "--notebooks", str(tmp_path), "--check"]) == 0
    assert [_stored(c) for c in read_notebook(tmp_path / "a.ipynb").cells] == slide_types(_small())


def test_cli_slides_without_notebooks(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["slides", "--notebooks", str(tmp_path)])
    assert "no notebooks (*.ipynb) found" in capsys.readouterr().err


# -- the slides built: python -m coursekit slides --out DIR ------------------------------------

def test_cli_slides_out_and_check_exclude_each_other(capsys):
    with pytest.raises(SystemExit):
        main(["slides", "--out", "somewhere", "--check"])
    assert "not allowed with argument" in capsys.readouterr().err


def test_build_refuses_a_folder_that_holds_other_files(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(SystemExit):
        main(["slides", "--out", str(out)])
    assert "holds files that are not slides built before" in capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "mine"


@pytest.mark.parametrize("kwargs, error, match", [
    ({"timeout": 0}, ValueError, "timeout must be a positive whole number"),
    ({"timeout": 1.5}, ValueError, "timeout must be a positive whole number"),
    ({"verbose": "yes"}, TypeError, "verbose must be True or False"),
])
def test_build_slides_rejects_bad_arguments(tmp_path, kwargs, error, match):
    with pytest.raises(error, match=match):
        slideshow.build_slides(tmp_path / "out", **kwargs)


def test_figures_get_their_text_alternative_from_their_data():
    figure = nbformat.v4.new_output("display_data", data={
        "image/png": "iVBOR", "text/plain": "<Figure size 640x480 with 1 Axes>",
        ALT: "Step response: y rises from 0 to 1 in 2 s."})
    explorer = nbformat.v4.new_output("display_data", data={
        "image/png": "iVBOR", "text/plain": "Euler explorer: step h = 0.1 s, error 3 %",
        WIDGET_VIEW: {"model_id": "m1", "version_major": 2, "version_minor": 0}})
    printed = nbformat.v4.new_output("stream", text="no figure here")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("", outputs=[figure, explorer, printed])])
    notebook_module.harvest_alt_texts(nb)
    assert figure.metadata["image/png"]["alt"] == "Step response: y rises from 0 to 1 in 2 s."
    assert ALT not in figure.data                   # not a type the page could show
    assert explorer.metadata["image/png"]["alt"] == "Euler explorer: step h = 0.1 s, error 3 %"
    assert "metadata" not in printed or not printed.metadata


def test_index_page_links_every_chapter_in_order():
    page = slideshow.index_page([
        {"number": "1", "title": "Signals & systems", "page": "01_a", "sections": ["1.1 Intro", "1.2 <b>"]},
        {"number": "2", "title": "Control", "page": "02_b", "sections": []}])
    assert re.findall(r'href="([^"]+)"', page) == ["01_a.slides.html", "02_b.slides.html"]
    assert "Chapter 1: Signals &amp; systems" in page and "1.2 &lt;b&gt;" in page
    assert '<html lang="en">' in page and "<title>" in page and "<main>" in page


def _skip_without_slide_tools() -> None:
    missing = slideshow.missing_slide_tools()
    if missing:
        pytest.skip("the slides extra is not installed (python -m pip install -e \".[slides]\"; missing: "
                    + ", ".join(missing) + ")")


SMALL_CHAPTER = [
    nbformat.v4.new_markdown_cell("# Chapter 7 — A small chapter\n\nIntro with $\\dot x = A x$."),
    nbformat.v4.new_code_cell("%matplotlib inline\nimport matplotlib.pyplot as plt"),
    nbformat.v4.new_markdown_cell("## 7.1 A section\n\nThe state $x(t)$ obeys $$x(t) = e^{At} x_0.$$"),
    nbformat.v4.new_code_cell(
        "plt.plot([0, 1, 2], [0, 3, 1], label='bump'); plt.xlabel('time t [s]'); plt.legend(); plt.show()"),
    nbformat.v4.new_markdown_cell("### 7.1.1 An explorer"),
    nbformat.v4.new_code_cell(
        "from IPython.display import display\n"
        "display({'image/png': 'iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR4nGNg+M/AAAAFAAIBpbfh"
        "1gAAAABJRU5ErkJggg==', 'text/plain': 'explorer (static figure)',\n"
        "         'application/vnd.jupyter.' + 'widget-view+json':\n"
        "             {'model_id': 'm1', 'version_major': 2, 'version_minor': 0}}, raw=True)"),
]


def _links(text: str) -> list[str]:
    """Every address the page or style sheet `text` loads or links to (not anchors or data)."""
    found = re.findall(r'(?:src|href)="([^"]*)"|url\(["\']?([^"\')]*)', text)
    return [re.split(r"[?#]", a or b)[0] for a, b in found if not (a or b).startswith(("#", "data:"))]


def test_small_build_from_the_command_line_needs_no_network(tmp_path):
    _skip_without_slide_tools()
    from test_site import _NO_NETWORK    # the website's guard: outside connections refused and logged
    guard, folder, out = tmp_path / "guard", tmp_path / "nb", tmp_path / "out"
    for path in (guard, folder, out):
        path.mkdir()
    (guard / "sitecustomize.py").write_text(_NO_NETWORK, encoding="utf-8")
    nb = nbformat.v4.new_notebook(cells=SMALL_CHAPTER)
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, folder / "07_small.ipynb")
    # slides built before are replaced
    for name in ("reveal.js", "mathjax"):
        (out / name).mkdir()
    (out / "index.html").write_text("old")
    (out / "06_gone.slides.html").write_text("old")
    log = tmp_path / "network.log"
    root = str(Path(slideshow.__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(guard), root]), CK_NETWORK_LOG=str(log))
    result = subprocess.run([sys.executable, "-m", "coursekit", "slides", "--out", str(out),
                             "--notebooks", str(folder)], env=env, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    assert not log.exists(), log.read_text()
    assert sorted(p.name for p in out.glob("*.html")) == ["07_small.slides.html", "index.html"]
    page = (out / "07_small.slides.html").read_text(encoding="utf-8")
    # every asset is in the folder, named by a relative address; nothing of MathJax 2 or require.js
    theme = (out / "reveal.js" / "dist" / "theme" / "white.css").read_text(encoding="utf-8")
    fonts = out / "reveal.js" / "dist" / "theme" / "fonts" / "source-sans-pro"
    for base, text in ((out, page), (out / "reveal.js" / "dist" / "theme", theme),
                       (fonts, (fonts / "source-sans-pro.css").read_text(encoding="utf-8"))):
        links = _links(text)
        assert links and all("//" not in link and (base / link).is_file() for link in links), links
    assert {"mathjax/tex-chtml-full.js", "reveal.js/dist/reveal.js", "reveal.js/plugin/notes/notes.js",
            "reveal.js/dist/theme/white.css"} <= set(_links(page))
    assert not re.search(r"MathJax\.Hub|require\(|\$\(|mermaid", page)
    # slides: the title, the section with its sub-slide; the setup cell is skipped, its code ran
    assert page.count("<section") == 2 + 3 and "import matplotlib.pyplot" not in page
    assert "<title>Chapter 7: A small chapter slides</title>" in page
    assert "The state $x(t)$ obeys $$x(t) = e^{At} x_0.$$" in page
    # figures with their text alternative; the explorer as its static figure, no widget
    alts = [html.unescape(a) for a in re.findall(r'<img[^>]*alt="([^"]*)"', page)]
    assert len(alts) == 2 and "explorer (static figure)" in alts, alts
    assert any("bump: starts at 0, highest 3 at time t [s] = 1" in a for a in alts), alts
    assert "jupyter-widgets" not in page and WIDGET_VIEW not in page
    index = (out / "index.html").read_text(encoding="utf-8")
    assert _links(index) == ["07_small.slides.html"] and "Chapter 7: A small chapter" in index


# -- in a browser: the whole course ---------------------------------------------------------------

CHAPTERS = chapter_notebooks(default_notebook_dir())

#: TeX as MathJax finds it with the template's delimiters: $$..$$, $..$, \(..\), \[..\], environments
_TEX = re.compile(r"\$\$.+?\$\$|(?<![\\$])\$(?!\$)(?:\\.|[^$\\])+?\$|\\\(.+?\\\)|\\\[.+?\\\]"
                  r"|\\begin\{(\w+\*?)\}.*?\\end\{\1\}", re.DOTALL)


def _tex_sources(page: str) -> int:
    """How many equations the slides of the HTML `page` hold as written (before MathJax runs):
    the TeX in the text of the slides, leaving out code, scripts and styles, as MathJax does."""
    from bs4 import BeautifulSoup     # nbconvert's own dependency
    slides = BeautifulSoup(page, "html.parser").select_one(".reveal .slides")
    for tag in slides.select("pre, code, script, style, textarea"):
        tag.decompose()
    return sum(len(_TEX.findall(text)) for text in slides.find_all(string=True))


def _notebook_tex(path: Path) -> int:
    """How many equations the shown markdown cells of the notebook at `path` hold (outputs, such as
    the exercises' data, add more to the page)."""
    nb = read_notebook(path)
    texts = [cell.source for cell, kind in zip(nb.cells, slide_types(nb))
             if cell.cell_type == "markdown" and kind != "skip"]
    code = re.compile(r"```.*?```|(`+).*?\1", re.DOTALL)
    return sum(len(_TEX.findall(code.sub("", text))) for text in texts)


def _expected_slides(path: Path) -> tuple[int, int]:
    """(sections, all slides): the slides reveal.js should count, from the notebook's slide types."""
    types = slide_types(read_notebook(path))
    return types.count("slide"), types.count("slide") + types.count("subslide")


@pytest.fixture(scope="module")
def course(course_builds):
    """The slides of the whole course, from the session's one build (tests/course_builds.py), with
    the command an instructor types; every chapter is replayed there from the session's one
    execution of it (tests/executed_chapters.py: the same notebooks, run after the same first cell
    and the figure checks'), which it must match cell by cell."""
    reason = lab_harness.missing_reason()
    if reason:
        pytest.skip(reason)
    _skip_without_slide_tools()
    return course_builds.slides()


@pytest.fixture(scope="module")
def chromium(course):
    from playwright.sync_api import sync_playwright
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=lab_harness.chromium_path(),
                                     args=lab_harness.CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


class Opened:
    """A page opened from the disk; every request that is not a file of the disk is refused and
    recorded (`outside`), as is every file that fails to load (`failed`) and every console error.

    axe-core runs without fetching the style sheets, which Chromium refuses to a page opened from
    the disk (`lab_harness.axe_violations`): every failure and console error is the slides'.
    """

    def __init__(self, browser, url: str, viewport: dict | None = None):
        self.context = browser.new_context(viewport=viewport or {"width": 1280, "height": 800})
        self.outside, self.failed, self.errors = [], [], []
        self.context.route("**/*", self._route)
        self.page = self.context.new_page()
        self.page.on("requestfailed", lambda r: self.failed.append(r.url) if r.url not in self.outside else None)
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(f"uncaught: {e}"))
        self.page.goto(url, wait_until="load")

    def _route(self, route):
        if route.request.url.startswith(("file:", "data:")):
            route.continue_()
        else:
            self.outside.append(route.request.url)
            route.abort()

    def wait_for_reveal(self):
        self.page.wait_for_function("window.Reveal && Reveal.isReady()", timeout=60_000)

    def assert_offline_and_clean(self):
        assert self.outside == [], f"requests to other hosts: {self.outside}"
        assert self.failed == [], f"local files that did not load: {self.failed}"
        assert self.errors == [], f"console errors: {self.errors}"

    def axe(self, selector: str) -> list[str]:
        return lab_harness.axe_violations(self.page, selector, lab_harness.axe_source(), preload=False)


@pytest.fixture(scope="module")
def chapter(course, chromium):
    """``chapter(path)``: the slides of chapter `path` in a 1,280 x 800 window, opened once for the
    module, reveal.js started (a chapter takes seconds to load and typeset; the tests that read it
    as loaded run before those that move its sliders or its slides, in the order of this file)."""
    views = {}

    def open_chapter(path):
        if path not in views:
            views[path] = Opened(chromium, (course / f"{path.stem}{slideshow.SUFFIX}").as_uri())
            views[path].wait_for_reveal()
        return views[path]

    yield open_chapter
    for view in views.values():
        view.context.close()


@pytest.fixture
def opened(chromium):
    pages = []

    def open_url(url, viewport=None):
        pages.append(Opened(chromium, url, viewport))
        return pages[-1]

    yield open_url
    for page in pages:
        page.context.close()


MATH_REPORT = """() => {
  const slides = document.querySelector('.reveal .slides');
  const rawTex = [];
  for (const root of [slides, document.querySelector('.reveal .aria-status')]) {
    const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
      if (n.parentElement.closest('pre, code, script, style, mjx-container')) continue;
      if (/\\$[^$\\s][^$]*\\$|\\$\\$|\\\\\\(|\\\\\\[|\\\\begin\\{/.test(n.textContent)) rawTex.push(n.textContent.slice(0, 80));
    }
  }
  return {inSlides: slides.querySelectorAll('mjx-container').length,
          inPage: document.querySelectorAll('mjx-container').length,
          found: Array.from(MathJax.startup.document.math).length,
          mathjax2: document.querySelectorAll('.MathJax_Preview, .MathJax_Display, script[type^="math/tex"]').length,
          rawTex};
}"""

FIGURE_REPORT = """() => ({
  images: [...document.querySelectorAll('.reveal .slides img')].map(i => ({
    loaded: i.complete && i.naturalWidth > 0, alt: i.getAttribute('alt') || ''})),
  explorers: [...document.querySelectorAll('.reveal .slides .ck-static-explorer')]
    .map(e => e.querySelectorAll('img').length),
  widgets: document.querySelectorAll('.jupyter-widgets, script[type*="widget"]').length})"""


@pytest.mark.browser
@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_chapter_slides_work_offline_with_each_equation_typeset_once(path, course, chapter):
    slides = course / f"{path.stem}{slideshow.SUFFIX}"
    view = chapter(path)
    view.page.evaluate("MathJax.startup.promise.then(() => true)")
    view.assert_offline_and_clean()
    # equations: every TeX source of the page rendered, once, in place; no MathJax 2 preview
    math = view.page.evaluate(MATH_REPORT)
    sources = _tex_sources(slides.read_text(encoding="utf-8"))
    assert sources >= _notebook_tex(path) > 0, "equations of the notebook's text are missing from the page"
    assert math["inSlides"] == math["inPage"] == math["found"] == sources, (math, sources)
    assert math["mathjax2"] == 0 and math["rawTex"] == [], math
    # figures: every image shown and described; each explorer as its static figure, no widget
    figures = view.page.evaluate(FIGURE_REPORT)
    assert figures["images"] and all(image["loaded"] for image in figures["images"])
    assert all(len(image["alt"]) > 40 and "No description" not in image["alt"] for image in figures["images"])
    explorers = sum(bool(re.search(r"\b\w+_explorer\(", c.source)) for c in read_notebook(path).cells
                    if c.cell_type == "code")
    assert len(figures["explorers"]) == explorers > 0, (figures["explorers"], explorers)
    assert all(count == 1 for count in figures["explorers"]), figures["explorers"]
    assert figures["widgets"] == 0
    # reveal.js: one slide per section, one more per sub-slide (or more, a long one cut to fit the
    # screen); the keys move through them
    sections, total = _expected_slides(path)
    shown_sections, shown_total = view.page.evaluate("[Reveal.getHorizontalSlides().length, Reveal.getTotalSlides()]")
    assert shown_sections == sections and shown_total >= total, (shown_sections, shown_total, sections, total)
    view.page.keyboard.press("ArrowRight")
    view.page.wait_for_function("Reveal.getIndices().h === 1")
    view.page.keyboard.press("Space")
    view.page.wait_for_function("Reveal.getProgress() > 1 / Reveal.getTotalSlides()")
    assert re.search(r"#/\d+", view.page.url), "the address does not follow the slide shown"
    view.page.keyboard.press("Home")
    view.page.wait_for_function("Reveal.isFirstSlide()")
    view.assert_offline_and_clean()
    # reveal.js's controls, progress bar and live region, which only this view shows. The slides are
    # checked in the print view (test_every_slide_meets_wcag_aa): here axe cannot measure their
    # contrast (reveal.js's background layer overlaps every text: "incomplete", not a violation),
    # and axe over the whole deck took 4 s of a core more
    assert view.axe(".reveal > :not(.slides)") == [], "reveal.js's controls"


@pytest.mark.browser
@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_every_slide_meets_wcag_aa(path, course, opened):
    # reveal.js's print view lays every slide out, visible, one after the other
    view = opened((course / f"{path.stem}{slideshow.SUFFIX}").as_uri() + "?print-pdf")
    view.wait_for_reveal()
    assert view.page.evaluate("Reveal.isPrintView()")
    view.assert_offline_and_clean()
    assert view.axe(".reveal .slides") == []


@pytest.mark.browser
def test_index_page_opens_every_chapter(course, opened):
    view = opened((course / "index.html").as_uri())
    links = view.page.eval_on_selector_all("main a", "as => as.map(a => [a.getAttribute('href'), a.textContent])")
    assert [href for href, _ in links] == [f"{p.stem}{slideshow.SUFFIX}" for p in CHAPTERS]
    assert all(re.match(r"Chapter \d+: \w", text) for _, text in links), links
    assert view.axe("html") == []      # the index has no style sheet for axe to read
    view.page.click("main a >> nth=-1")
    view.wait_for_reveal()
    assert view.page.url.split("#")[0].endswith(f"{CHAPTERS[-1].stem}{slideshow.SUFFIX}")
    view.assert_offline_and_clean()


def _show_slide(view):
    """Bring the slide that holds an explorer on screen (reveal.js shows one slide at a time)."""
    def show(root):
        view.page.evaluate("e => { const i = Reveal.getIndices(e.closest('section')); Reveal.slide(i.h, i.v); }",
                           root.element_handle())
        view.page.wait_for_function("e => e.closest('section').classList.contains('present')",
                                    arg=root.element_handle())
        view.page.wait_for_timeout(900)          # the slide transition
        root.scroll_into_view_if_needed()
    return show


@pytest.mark.browser
@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_explorers_are_live_on_the_slides(path, course, chapter):
    """On its slide, each explorer loads, an arrow key steps its first slider (and not the
    slides), every frame its data names is on the disk, and a drag of its first slider swaps the
    figure and its alt text once per value passed and ends on the figure the explorer renders for
    those settings. The explorers' script and the making of their data are those of the website,
    whose instructor edition's check walks through every state and drags every slider
    (`static_explorer_checks`); the slides' frames, drawn for the screen, are compared with the
    explorer's own figure here and in tests/test_static_explorers.py."""
    view = chapter(path)
    checked = static_explorer_checks.check_page(view.page, course, column=False, scroll=_show_slide(view),
                                                every_state=False, render=True)
    assert checked == sum(bool(re.search(r"\b\w+_explorer\(", c.source))
                          for c in read_notebook(path).cells if c.cell_type == "code") > 0
    # the arrow keys pressed on the last explorer's sliders left its slide on screen
    assert view.page.evaluate("Reveal.getCurrentSlide().contains([...document.querySelectorAll("
                              "'.ck-static-explorer')].pop())")
    view.assert_offline_and_clean()


#: every slide shown in turn: how far its content runs past the slide (in the slide's pixels: the
#: slide is 1280 x 800, which reveal.js scales by 0.864 into a 1280 x 720 window, so a slide whose
#: content is 722 px tall there fills 624 px of the window), how far the slide or any block shown
#: on it, or the page itself, runs past the window (in the window's pixels), and the smallest zoom
#: of a block shown smaller to fit
FIT_REPORT = """() => Reveal.getSlides().map(slide => {
  const {h, v} = Reveal.getIndices(slide);
  Reveal.slide(h, v);
  const boxes = [slide, ...slide.querySelectorAll('*')].map(e => e.getBoundingClientRect())
    .filter(b => b.width > 0 && b.height > 0);
  const zooms = [...slide.querySelectorAll('[style*="zoom"]')].map(e => parseFloat(e.style.zoom));
  return {slide: `${h}/${v || 0}`, text: slide.textContent.trim().slice(0, 60),
          past: slide.scrollHeight - slide.clientHeight,
          off: Math.max(0, ...boxes.map(b => b.bottom - window.innerHeight), ...boxes.map(b => -b.top),
                        document.documentElement.scrollHeight - window.innerHeight),
          zoom: Math.min(1, ...zooms)};
})"""


@pytest.mark.browser
@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_every_slide_fits_a_1280_by_720_screen(path, course, chapter):
    """Each slide shows all it holds on a 1280 x 720 screen, without scrolling: a sub-slide too
    long for it is cut into several, and a block too tall by itself is shown a little smaller."""
    view = chapter(path)
    view.page.set_viewport_size({"width": 1280, "height": 720})
    view.page.evaluate("() => { Reveal.configure({transition: 'none'}); Reveal.layout(); }")
    slides = view.page.evaluate(FIT_REPORT)
    too_tall = [s for s in slides if s["past"] > 0 or s["off"] > 0]     # not a pixel past
    assert not too_tall, f"{len(too_tall)} of {len(slides)} slides do not fit: {too_tall}"
    assert min(s["zoom"] for s in slides) >= 0.8, [s for s in slides if s["zoom"] < 0.8]
    view.assert_offline_and_clean()
