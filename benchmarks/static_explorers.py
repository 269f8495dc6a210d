"""The static explorers' benchmark: how fast a page without a kernel follows a drag.

``python benchmarks/static_explorers.py [--site DIR]`` opens every chapter of a built course
website (``python -m coursekit site --out DIR``; without ``--site`` it builds one in a temporary
folder) in headless Chromium at a 1,280-px window (the harness of the browser tests,
``tests/lab_harness.py``, with every request but the page's own files refused). For each explorer,
once its frames are loaded, it drags each range input from one end of its track to the other and
back, one stored value per mouse move, a move every 16 ms (a fast hand: 60 values a second), and
counts on the page's clock:

* values/s: the values the hand passed per second (what a perfect page would show);
* swaps/s: the frames the script put in the ``<img>`` per second;
* painted/s: the animation frames per second in which a new frame was on screen, decoded (the
  figure the reader sees change).

The row of an explorer is its slowest slider. The target (issue 34) is 30 painted frames a
second during a drag.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import lab_harness as lab_h  # noqa: E402  (lives with the browser tests)

__all__ = ["TARGET_PER_S", "measure_site", "table"]

TARGET_PER_S = 30.0
MOVE_S = 0.016

_PROBE_JS = """root => {
  const img = root.querySelector('img.ck-static-figure');
  const probe = root.ckProbe = {painted: 0, last: img.currentSrc || img.src, running: true};
  function tick() {
    if (!probe.running) return;
    if (img.complete && img.currentSrc !== probe.last) { probe.painted += 1; probe.last = img.currentSrc; }
    requestAnimationFrame(tick);
  }
  requestAnimationFrame(tick);
  probe.swaps0 = root.ckSwaps; probe.t0 = performance.now();
}"""

_STOP_JS = """root => { const p = root.ckProbe; p.running = false;
  return {painted: p.painted, swaps: root.ckSwaps - p.swaps0, seconds: (performance.now() - p.t0) / 1000}; }"""


def _drag(page, root, j: int, values: int) -> dict:
    """One drag of range input `j` over its `values` stops, end to end and back; the counts."""
    box = root.locator("input[type=range]").nth(j).bounding_box()
    y, left, right = box["y"] + box["height"] / 2, box["x"] + 8, box["x"] + box["width"] - 8
    root.locator("input[type=range]").nth(j).evaluate(
        "i => { i.value = '0'; i.dispatchEvent(new Event('input', {bubbles: true})); }")
    page.wait_for_timeout(200)
    root.evaluate(_PROBE_JS)
    page.mouse.move(left, y)
    page.mouse.down()
    start, moves = time.perf_counter(), 0
    path = [left + (right - left) * k / (values - 1) for k in range(values)]
    for x in path[1:] + path[-2::-1]:
        page.mouse.move(x, y)
        moves += 1
        time.sleep(max(0.0, start + MOVE_S * moves - time.perf_counter()))
    page.mouse.up()
    page.wait_for_timeout(100)
    counts = root.evaluate(_STOP_JS)
    counts["values"] = 2 * (values - 1)
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
                    stops = int(root.locator("input[type=range]").nth(j).get_attribute("max")) + 1
                    counts.append(_drag(page, root, j, stops))
                per_s = [{key: c[key] / c["seconds"] for key in ("values", "swaps", "painted")} for c in counts]
                rows[title] = min(per_s, key=lambda c: c["painted"])
            context.close()
        browser.close()
    return rows


def table(rows: dict) -> list[str]:
    lines = ["| explorer | values/s passed | swaps/s | painted/s |", "|---|---|---|---|"]
    for title, c in rows.items():
        lines.append(f"| {title.split(':')[0].split(' (')[0]} | {c['values']:.0f} | {c['swaps']:.0f} | "
                     f"{c['painted']:.0f} |")
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
