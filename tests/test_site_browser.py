"""The course website in a real browser: both editions built, served on loopback, every page opened.

Builds the site twice (``build_site`` for the instructor, ``student=True`` for the student
edition; one build each for the whole module), serves the two folders with ``http.server`` on a
free 127.0.0.1 port and opens every HTML page in headless Chromium (Playwright, the system
Chromium, no browser download). A page fails on: a console error or an uncaught exception, a
request to any host but 127.0.0.1 (each is recorded and aborted, so the site must work with no
network), a broken image, an equation MathJax did not typeset (or TeX left in the text), an
explorer without its figure or with a widget area, a missing or unstyled erratum box, section
numbers other than the notebook's own, a solution that is not folded (instructor) or that is
present at all (student). At a window 1,280 px wide, the smallest text of every figure is shown at
11 CSS px at least: its size in points, which the build records for each image, times the image's
pixels per point, times the scale the browser shows it at. Skipped, with the reason, without
Playwright, Chromium or the site extra.
"""

from __future__ import annotations

import hashlib
import html
import json
import re
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import nbformat
import pytest
from PIL import Image

from coursekit.tools import site
from coursekit.tools.notebooks import chapter_notebooks

import lab_harness  # the browser test's Chromium location and settings
import static_explorer_checks  # the explorers' sliders on a static page

pytestmark = pytest.mark.browser

NOTEBOOKS = Path(__file__).parents[1] / "notebooks"
CHAPTERS = [p.stem for p in chapter_notebooks(NOTEBOOKS)]
PAGES = ["index", *CHAPTERS, "genindex", "search"]
EDITIONS = ["instructor", "student"]
ERRATUM_BACKGROUND = "rgb(255, 247, 237)"   # coursekit.tools.site.CSS, light mode
_ERRATUM_SOURCE = re.compile(r"\*\*(?:Erratum|Remark\s*/\s*erratum)\b", re.IGNORECASE)
_EXPLORER_CALL = re.compile(r"\b\w+_explorer\(")


def _skip_reason() -> str | None:
    reason = lab_harness.missing_reason()
    if reason:
        return reason
    missing = site.missing_site_tools()
    if missing:
        return "the site extra is not installed (python -m pip install -e \".[site]\"; missing: " \
               + ", ".join(missing) + ")"
    return None


@pytest.fixture(scope="module")
def built(course_builds):
    """Both editions, from the session's one build of the site (tests/course_builds.py): {edition: folder}."""
    reason = _skip_reason()
    if reason:
        pytest.skip(reason)
    return course_builds.site()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server(built):
    """http.server on a free loopback port serving both editions: its base URL."""
    root = next(iter(built.values())).parent
    port = _free_port()
    proc = subprocess.Popen([sys.executable, "-m", "http.server", "--bind", "127.0.0.1",
                             "--directory", str(root), str(port)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                urllib.request.urlopen(f"{url}/instructor/index.html", timeout=2).close()
                break
            except OSError:
                if proc.poll() is not None or time.monotonic() > deadline:
                    pytest.fail(f"http.server did not answer on {url} (exit code {proc.poll()})")
                time.sleep(0.2)
        yield url
    finally:
        proc.terminate()
        proc.wait(timeout=10)


@pytest.fixture(scope="module")
def browser(built):
    from playwright.sync_api import sync_playwright
    with sync_playwright() as pw:
        chromium = pw.chromium.launch(executable_path=lab_harness.chromium_path(), args=lab_harness.CHROMIUM_ARGS, headless=True)
        yield chromium
        chromium.close()


class Visit:
    """One page opened with every outside request refused and every error recorded."""

    def __init__(self, browser, url: str, width: int = 1300):
        self.context = browser.new_context(viewport={"width": width, "height": 900})
        self.outside, self.errors = [], []
        self.context.route("**/*", self._route)
        self.page = self.context.new_page()
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(f"uncaught: {e}"))
        self.page.on("response", lambda r: self.errors.append(f"{r.status} for {r.url}") if r.status >= 400 else None)
        self.page.goto(url, wait_until="load")
        if self.page.query_selector("script[src*='mathjax']") is not None:
            self.page.wait_for_function("window.MathJax && MathJax.startup && MathJax.startup.promise",
                                        timeout=60_000)
            self.page.evaluate("MathJax.startup.promise.then(() => true)")

    def _route(self, route):
        url = route.request.url
        if re.match(r"^(https?|wss?)://127\.0\.0\.1(:\d+)?/", url) or url.startswith(("file:", "data:")):
            route.continue_()
        else:
            self.outside.append(url)
            route.abort()

    def close(self):
        self.context.close()


@pytest.fixture(scope="module")
def opened(browser, server):
    """``opened(edition, name)``: the page `name` of `edition`, opened once for the module at a
    window of `FIGURE_WINDOW` px (a chapter page, its math typeset, takes seconds to load and is
    checked by five tests; those that move its sliders or open a solution run after those that
    read it as loaded, in the order of this file)."""
    pages = {}

    def open_page(edition: str, name: str) -> Visit:
        if (edition, name) not in pages:
            pages[edition, name] = Visit(browser, f"{server}/{edition}/{name}.html", FIGURE_WINDOW)
        return pages[edition, name]

    yield open_page
    for v in pages.values():
        v.close()


@pytest.fixture
def visit(browser):
    opened = []

    def open_page(url, width=1300):
        opened.append(Visit(browser, url, width))
        return opened[-1]

    yield open_page
    for v in opened:
        v.close()


PAGE_REPORT = """() => {
  const article = document.querySelector('article') || document.body;
  const broken = [...document.images].filter(i => !(i.complete && i.naturalWidth > 0))
                                      .map(i => i.getAttribute('src'));
  const math = [...document.querySelectorAll('.math')];
  const untypeset = math.filter(m => !m.querySelector('mjx-container')).map(m => m.textContent.slice(0, 80));
  const rawTex = [];
  const walker = document.createTreeWalker(article, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    if (n.parentElement.closest('pre, code, script, style, mjx-container')) continue;
    if (/\\$[^$\\s][^$]*\\$|\\\\\\(|\\\\\\[|\\\\begin\\{|\\*\\*Erratum/i.test(n.textContent)) rawTex.push(n.textContent.slice(0, 80));
  }
  const widgets = document.querySelectorAll(
    'script[type*="widget"], .jupyter-widgets, .widget-area, .jp-OutputArea-output:empty').length;
  const headings = [...article.querySelectorAll('h1, h2, h3, h4')]
                     .map(h => h.textContent.replace(/#$/, '').trim());
  const searchFields = [...document.querySelectorAll('.search-button-field')].filter(e => e.checkVisibility()).length;
  return {broken, untypeset, rawTex, widgets, headings, searchFields, math: math.length};
}"""

EXPLORER_REPORT = """() => [...document.querySelectorAll('.cell')]
  .filter(c => /\\b\\w+_explorer\\(/.test((c.querySelector('.cell_input') || {}).textContent || ''))
  .map(c => [...c.querySelectorAll('.cell_output img')].filter(i => i.naturalWidth >= 200).length)"""

#: the window width at which the site's figures show their smallest text at `SMALLEST_TEXT_PX`
FIGURE_WINDOW = 1280
SMALLEST_TEXT_PX = 11.0

FIGURE_REPORT = """() => [...document.querySelectorAll('article img')].map(i => ({
  src: i.getAttribute('src'), natural: i.naturalWidth, shown: i.getBoundingClientRect().width}))"""

ERRATUM_REPORT = """() => [...document.querySelectorAll('div.erratum.admonition')].map(box => ({
  title: box.querySelector('.admonition-title').textContent.trim(),
  background: getComputedStyle(box).backgroundColor,
  height: box.getBoundingClientRect().height}))"""


def _notebook(name: str):
    return nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)


def _markdown(nb) -> str:
    return "\n\n".join(c.source for c in nb.cells if c.cell_type == "markdown")


def _count_errata(markdown: str) -> int:
    """Paragraphs (in a blockquote or not) that start with a bold "Erratum" lead."""
    unquoted = re.sub(r"^> ?", "", markdown, flags=re.MULTILINE)
    paragraphs = re.split(r"\n\s*\n", unquoted)
    return sum(bool(_ERRATUM_SOURCE.match(p.strip())) for p in paragraphs)


def _solution_lines(nb) -> list[str]:
    """One distinctive line of each solution cell: its longest line of code."""
    lines = []
    for cell in nb.cells:
        if "solution" not in cell.metadata.get("tags", []):
            continue
        code = cell.source
        if cell.cell_type == "markdown":
            code = "\n".join(re.findall(r"```[a-z]*\n(.*?)```", code, re.DOTALL))
        candidates = [line.strip() for line in code.splitlines() if len(line.strip()) >= 15]
        assert candidates, f"a solution cell without a line of code to look for: {cell.source[:80]!r}"
        lines.append(max(candidates, key=len))
    return lines


def test_every_page_and_only_those_are_built(built):
    for edition, folder in built.items():
        assert sorted(p.stem for p in folder.glob("*.html")) == sorted(PAGES), edition


@pytest.mark.parametrize("edition", EDITIONS)
@pytest.mark.parametrize("name", PAGES)
def test_page_loads_offline_with_images_and_typeset_math(name, edition, opened):
    v = opened(edition, name)
    report = v.page.evaluate(PAGE_REPORT)
    assert v.outside == [], f"requests to hosts other than 127.0.0.1: {v.outside}"
    assert v.errors == [], f"console errors: {v.errors}"
    assert report["broken"] == [], f"broken images: {report['broken']}"
    assert report["untypeset"] == [], f"equations not typeset: {report['untypeset'][:5]}"
    assert report["rawTex"] == [], f"TeX or markdown left in the text: {report['rawTex'][:5]}"
    assert report["widgets"] == 0, "an empty widget area is on the page"
    assert report["searchFields"] <= 1, "the search field is shown twice (a second top bar)"
    # WCAG 2.1 AA (axe-core), and every figure described in words, not by its file name
    violations = lab_harness.axe_violations(v.page, "html", lab_harness.axe_source())
    assert violations == [], "\n".join(violations)
    alts = v.page.evaluate("() => [...document.querySelectorAll('article img')].map(i => i.alt)")
    assert all(len(alt) > 40 and "_images/" not in alt and ".png" not in alt for alt in alts), alts[:3]
    if name in CHAPTERS:
        _check_chapter(v, name, report)


def _check_chapter(v, name: str, report: dict) -> None:
    nb = _notebook(name)
    text = _markdown(nb)
    assert report["math"] > 20, "a chapter page without equations: math is not parsed"
    # section numbers: exactly the notebook's headings, no second numbering added
    prose = re.sub(r"```.*?```", "", text, flags=re.DOTALL)    # a "# comment" in code is no heading
    source_headings = re.findall(r"^#{1,4} (.+?)\s*$", prose, re.MULTILINE)
    page_headings = [re.sub(r"\s+", " ", h) for h in report["headings"]]
    assert len(page_headings) == len(source_headings), (page_headings, source_headings)
    numbers = [re.match(r"[\d.–]*", h).group() for h in page_headings]
    assert numbers == [re.match(r"[\d.–]*", h).group() for h in source_headings]
    chapter = name.split("_")[0].lstrip("0")
    assert all(n.startswith(f"{chapter}.") for n in numbers if n), numbers
    # explorers: every one shows its figure
    explorers = v.page.evaluate(EXPLORER_REPORT)
    calls = sum(bool(_EXPLORER_CALL.search(c.source)) for c in nb.cells if c.cell_type == "code")
    assert len(explorers) == calls > 0
    assert all(count >= 1 for count in explorers), f"explorers without a figure: {explorers}"
    # errata: one styled box per erratum of the notebook (a chapter has them where its notes have a
    # slip, README; the course's own chapters all do: test_the_course_s_chapters_have_errata_to_show)
    boxes = v.page.evaluate(ERRATUM_REPORT)
    assert len(boxes) == _count_errata(text)
    for box in boxes:
        assert re.match(r"(Remark / )?[Ee]rratum", box["title"]) and box["height"] > 30, box
        assert box["background"] == ERRATUM_BACKGROUND, box


def test_the_course_s_chapters_have_errata_to_show():
    """The course's own four chapters each correct slips of the notes, so the page check compares
    styled boxes with errata, not zero with zero (a chapter added later may have none)."""
    errata = {name: _count_errata(_markdown(_notebook(name))) for name in CHAPTERS[:4]}
    assert len(errata) == 4 and all(errata.values()), errata


@pytest.mark.parametrize("edition", EDITIONS)
@pytest.mark.parametrize("name", CHAPTERS)
def test_figure_text_is_11_css_px_or_more_in_a_1280_px_window(name, edition, built, opened):
    folder = built[edition]
    figures = json.loads((folder / "_static" / site.FIGURE_RECORD).read_text(encoding="utf-8"))
    record, dpi = figures["smallest_text_pt"], figures["dpi"]
    v = opened(edition, name)
    images = v.page.evaluate(FIGURE_REPORT)
    assert images, "a chapter page without a figure"
    small, unknown = [], []
    for image in images:
        path = folder / image["src"]
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        points = record.get(digest)
        if points is None:
            unknown.append(image["src"])
            continue
        with Image.open(path) as png:      # an explorer's WebP frame: its resolution is recorded
            pixels_per_point = png.info.get("dpi", (dpi.get(digest),))[0] / 72
        shown = points * pixels_per_point * image["shown"] / image["natural"]
        if shown < SMALLEST_TEXT_PX:
            small.append(f"{image['src']}: {points:g} pt at {pixels_per_point * 72:.0f} dpi, shown "
                         f"{image['shown']:.0f} of {image['natural']} px wide: {shown:.1f} CSS px")
    assert not unknown, f"images without a recorded smallest text: {unknown}"
    assert not small, "figure text below 11 CSS px:\n" + "\n".join(small)


@pytest.mark.parametrize("edition", EDITIONS)
@pytest.mark.parametrize("name", CHAPTERS)
def test_explorers_are_live_without_a_kernel(name, edition, built, opened):
    """Every state a reader reaches shows its frame; dragging each slider swaps the figure and its
    alt text once per value passed and ends on the figure the explorer renders for those settings
    (`static_explorer_checks`), at the window the figures are drawn for. The student edition's
    explorers hold the instructor edition's data and frames (byte for byte) and run the same
    script, so what the instructor edition's check shows holds for them; on the student page each
    explorer loads, and a drag of its first slider swaps its frames as its data says."""
    v = opened(edition, name)
    before = len(v.errors)      # axe-core's own fetch of a theme's imported style sheet 404s
    if edition == "student":
        assert static_explorer_checks.explorer_data(v.page, built["student"]) == \
            static_explorer_checks.explorer_data(opened("instructor", name).page, built["instructor"])
    checked = static_explorer_checks.check_page(v.page, built[edition], column=True,
                                                every_state=edition == "instructor")
    assert checked == len(v.page.evaluate(EXPLORER_REPORT)) > 0
    assert v.outside == [] and v.errors[before:] == []


@pytest.mark.parametrize("name", CHAPTERS)
def test_instructor_solutions_are_folded_and_open_with_a_click(name, opened):
    lines = _solution_lines(_notebook(name))
    assert lines, f"{name} has no solution cell"
    v = opened("instructor", name)
    hidden = v.page.evaluate("""(lines) => lines.map(line => {
        const pre = [...document.querySelectorAll('pre')].find(p => p.textContent.includes(line));
        return pre ? (pre.closest('details') !== null && pre.checkVisibility() === false) : null;
      })""", lines)
    assert hidden == [True] * len(lines), f"solutions missing (null) or not folded (false): {hidden}"
    summary = v.page.locator("details:has(pre) > summary").first
    summary.click()
    assert v.page.locator("details[open] pre").first.is_visible()


def _page_text(path: Path) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", path.read_text(encoding="utf-8")))


@pytest.mark.parametrize("name", CHAPTERS)
def test_student_site_has_no_solution(name, built):
    lines = _solution_lines(_notebook(name))
    instructor = _page_text(built["instructor"] / f"{name}.html")
    student = _page_text(built["student"] / f"{name}.html")
    assert [line for line in lines if line not in instructor] == []
    assert [line for line in lines if line in student] == []
    assert "Show solution" not in student and "Exercise" in student


@pytest.mark.parametrize("edition", EDITIONS)
def test_landing_page_links_every_chapter(edition, opened):
    v = opened(edition, "index")
    links = v.page.eval_on_selector_all("article table a", "as => as.map(a => a.getAttribute('href'))")
    assert links == [f"{name}.html" for name in CHAPTERS]
    body = v.page.inner_text("article")
    assert 'pip install -e ".[lab]"' in body and "jupyterlab notebooks/" in body
    assert ("student edition" in body) == (edition == "student")


def test_site_works_opened_as_a_file(built, visit):
    """index.html opened straight from the disk (no server) typesets its math too."""
    v = visit((built["instructor"] / f"{CHAPTERS[0]}.html").as_uri())
    report = v.page.evaluate(PAGE_REPORT)
    assert v.outside == [] and v.errors == []
    assert report["math"] > 20 and report["untypeset"] == [] and report["broken"] == []
