"""What a reader meets in the built outputs of ``python -m coursekit site``, ``slides``, ``release``
and ``grade``, as a comparable record (tests/test_build_structure.py).

`structure(folder)` gives, for every file under `folder` (by its path there): for an HTML page its
headings, images (address, or a digest of the image it holds, and ``alt``), erratum and other boxes' titles, folded blocks' summaries,
links and a digest of its visible text; for a notebook its cells' types, tags and a digest of each
source; for the grader's CSV and feedback their text; for any other file only that it is there.
The addresses Sphinx gives downloads (a digest of the build folder's path) are made neutral.

``python tests/build_structure.py OUT RELEASE GRADE SITE STUDENT_SITE SLIDES`` writes the record
of folders built before a change into OUT (tests/build_structure.json).
"""

from __future__ import annotations

import hashlib
import json
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

__all__ = ["structure", "record", "PARTS"]

#: the parts of the record: the command each folder comes from
PARTS = ("release", "grade", "site", "student_site", "slides")

_DOWNLOAD = re.compile(r"_downloads/[0-9a-f]{32}/")
_TEXT = ("h1", "h2", "h3", "h4", "h5", "h6", "summary")


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


class _Page(HTMLParser):
    """The headings, images, box titles, summaries, links and visible text of one page."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.found, self.text, self._open, self._skip = [], [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag in ("script", "style"):
            self._skip += 1
        elif tag == "img":
            src = attrs.get("src", "")
            src = "data:" + _digest(src) if src.startswith("data:") else _DOWNLOAD.sub("_downloads/*/", src)
            self.found.append(["img", src, attrs.get("alt")])
        elif tag == "a" and attrs.get("href", "").startswith(("_downloads/", "http")):
            self.found.append(["a", _DOWNLOAD.sub("_downloads/*/", attrs["href"])])
        if tag in _TEXT or "admonition-title" in (attrs.get("class") or ""):
            self._open.append([tag if tag in _TEXT else "box", ""])

    def handle_endtag(self, tag):
        if tag in ("script", "style"):
            self._skip = max(0, self._skip - 1)
        elif self._open and (tag == self._open[-1][0] or (self._open[-1][0] == "box" and tag == "p")):
            kind, text = self._open.pop()
            self.found.append([kind, " ".join(text.replace("#", "").split())])

    def handle_data(self, data):
        if self._skip:
            return
        for entry in self._open:
            entry[1] += data
        self.text.append(data)


def _page(text: str) -> dict:
    parser = _Page()
    parser.feed(text)
    return {"found": parser.found, "text": _digest(" ".join(" ".join(parser.text).split()))}


def _notebook(text: str) -> list:
    cells = json.loads(text)["cells"]
    return [[c["cell_type"], c.get("metadata", {}).get("tags", []), _digest("".join(c["source"]))]
            for c in cells]


def _summary(path: Path):
    if path.suffix == ".html":
        return _page(path.read_text(encoding="utf-8"))
    if path.suffix == ".ipynb":
        return _notebook(path.read_text(encoding="utf-8"))
    if path.suffix in (".csv", ".md"):
        return path.read_text(encoding="utf-8")
    return None


def structure(folder) -> dict:
    """``{path under folder: summary}`` for every file of `folder` (see the module docstring)."""
    folder = Path(folder)
    return {_DOWNLOAD.sub("_downloads/*/", p.relative_to(folder).as_posix()): _summary(p)
            for p in sorted(folder.rglob("*")) if p.is_file()}


def record(folders: dict) -> dict:
    """``{part: structure(folder)}`` for the folders built by each command of `PARTS`."""
    return {part: structure(folders[part]) for part in PARTS}


if __name__ == "__main__":
    out, *built = sys.argv[1:]
    Path(out).write_text(json.dumps(record(dict(zip(PARTS, built))), indent=0, sort_keys=True) + "\n",
                         encoding="utf-8")
