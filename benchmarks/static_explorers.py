"""The static explorers' benchmark: how fast a page without a kernel follows a drag.

``python benchmarks/static_explorers.py [--site DIR]`` opens every chapter of a built course
website (``python -m coursekit site --out DIR``; without ``--site`` it builds one in a temporary
folder) in headless Chromium at a 1,280-px window (the harness of the browser tests,
``tests/lab_harness.py``, with every request but the page's own files refused). For each explorer,
once its frames are loaded, it drags each range input from one end of its track to the other and
back, one stored value per animation frame (a drag as fast as the screen, about 60 values a
second, driven by the page itself: Playwright's mouse moves are slower than a hand on a loaded
machine), and counts on the page's clock:

* values/s: the values the slider passed per second (what a perfect page would show);
* swaps/s: the frames the script put in the ``<img>`` per second;
* painted/s: the animation frames per second in which a new frame was on screen, decoded (the
  figure the reader sees change);
* floor: the animation frames per second the same page reaches right after, over as many frames,
  with nothing moved (what the browser can paint on this machine at the time).

The row of an explorer is its slowest slider. The target (issue 34) is 30 painted frames a
second during a drag.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import lab_harness as lab_h  # noqa: E402  (lives with the browser tests)

__all__ = ["TARGET_PER_S", "measure_site", "table"]

TARGET_PER_S = 30.0

#: a drag as fast as the screen: the slider moves one stored value per animation frame, end to end
#: and back, by the page itself (Playwright's mouse is slower than a hand on a loaded machine);
#: a frame counts as painted when the next animation frame finds it decoded in the <img>
_DRAG_JS = """([root, j]) => new Promise(done => {
  const input = root.querySelectorAll('input[type=range]')[j];
  const shown = () => root.querySelector('img.ck-static-figure');
  const top = Number(input.max);
  const path = [...Array(top + 1).keys(), ...[...Array(top).keys()].reverse()];
  input.value = '0'; input.dispatchEvent(new Event('input', {bubbles: true}));
  let k = 1, painted = 0, last = shown().getAttribute('src');
  const swaps0 = root.ckSwaps, t0 = performance.now();
  function tick() {
    const img = shown();
    if (img.complete && img.naturalWidth > 0 && img.getAttribute('src') !== last) {
      painted += 1; last = img.getAttribute('src');
    }
    if (k < path.length) {
      input.value = String(path[k++]);
      input.dispatchEvent(new Event('input', {bubbles: true}));
      requestAnimationFrame(tick);
    } else {
      done({values: path.length - 1, swaps: root.ckSwaps - swaps0, painted,
            seconds: (performance.now() - t0) / 1000});
    }
  }
  requestAnimationFrame(tick);
})"""


#: the floor: animation frames per second of the same page over as many frames, nothing moved
_FLOOR_JS = """count => new Promise(done => {
  let k = 0; const t0 = performance.now();
  function tick() { if (++k < count) requestAnimationFrame(tick); else done(k / ((performance.now() - t0) / 1000)); }
  requestAnimationFrame(tick);
})"""


def _drag(page, root, j: int) -> dict:
    """One drag of range input `j` over all its stops, end to end and back; the counts."""
    counts = page.evaluate(_DRAG_JS, [root.element_handle(), j])
    counts["floor"] = page.evaluate(_FLOOR_JS, counts["values"])
    return counts


def measure_site(folder: Path) -> dict:
    """{explorer title: the counts of its slowest slider (per second)} for the site in `folder`."""
    from playwright.sync_api import sync_playwright
    rows = {}
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=lab_h.chromium_path(), args=lab_h.CHROMIUM_ARGS,
                                     headless=True)
        for chapter in sorted(folder.glob("0*.html")):
            context = browser.new_context(viewport={"width": 1280, "height": 900})
            context.route("**/*", lambda route: route.continue_() if route.request.url.startswith("file:")
                          else route.abort())
            page = context.new_page()
            page.goto(chapter.as_uri(), wait_until="load")
            roots = page.locator(".ck-static-explorer")
            for n in range(roots.count()):
                root = roots.nth(n)
                root.scroll_into_view_if_needed()
                page.wait_for_function("r => r.dataset.ckLoaded === 'true'", arg=root.element_handle(),
                                       timeout=60_000)
                title = root.locator(".ck-static-title").inner_text().strip()
                counts = []
                for j in range(root.locator("input[type=range]").count()):
                    counts.append(_drag(page, root, j))
                per_s = [{"floor": c["floor"], **{key: c[key] / c["seconds"] for key in ("values", "swaps", "painted")}}
                         for c in counts]
                rows[title] = min(per_s, key=lambda c: c["painted"])
            context.close()
        browser.close()
    return rows


def table(rows: dict) -> list[str]:
    lines = ["| explorer | values/s passed | swaps/s | painted/s | floor: frames/s, nothing moved |",
             "|---|---|---|---|---|"]
    for title, c in rows.items():
        lines.append(f"| {title.split(':')[0].split(' (')[0]} | {c['values']:.0f} | {c['swaps']:.0f} | "
                     f"{c['painted']:.0f} | {c['floor']:.0f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--site", type=Path, default=None, metavar="DIR", help="a built course website")
    args = parser.parse_args()
    reason = lab_h.missing_reason()
    if reason:
        sys.exit(f"the static explorers' benchmark needs Chromium and Playwright: {reason}")
    with tempfile.TemporaryDirectory(prefix="coursekit-static-bench-") as tmp:
        folder = args.site
        if folder is None:
            from coursekit.tools.site import build_site
            folder = build_site(Path(tmp) / "site").parent
        rows = measure_site(folder)
    print("\n".join(table(rows)))
    slowest = min(c["painted"] for c in rows.values())
    print(f"\nslowest: {slowest:.0f} painted frames per second during a drag (target {TARGET_PER_S:.0f})")


if __name__ == "__main__":
    main()
