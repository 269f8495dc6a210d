"""What a reader meets in the built outputs of ``python -m coursekit site``, ``slides``, ``release``
and ``grade``, as a comparable record (tests/test_build_structure.py).

`structure(folder)` gives, for every file under `folder` (by its path there): for an HTML page its
headings, images (address, or a digest of the image it holds, and ``alt``), erratum and other boxes' titles, folded blocks' summaries,
links and a digest of its visible text; for a notebook its cells' types, tags and a digest of each
source; for the grader's CSV and feedback their text; for any other file only that it is there.
The addresses Sphinx gives downloads (a digest of the build folder's path) are made neutral.

The record also names its chapters (the notebooks' stems, ``NN_name``). A chapter added since is
compared by the rule every chapter's outputs follow (`chapter_files`, `template`, `listed`): its
files are those whose path names it (and the figures only its page shows); left out of the pages
that list it (`structure(..., leave_out=...)`: the navigation entry, table row or next-page link
that links to it), the rest of the course must show what the record holds.

``python tests/build_structure.py OUT RELEASE GRADE SITE STUDENT_SITE SLIDES`` writes the record
of folders built before a change into OUT (tests/build_structure.json).
"""

from __future__ import annotations

import hashlib
import json
import re
import sys
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path

__all__ = ["structure", "record", "PARTS", "listed", "chapter_files", "template"]

#: the parts of the record: the command each folder comes from
PARTS = ("release", "grade", "site", "student_site", "slides")

_DOWNLOAD = re.compile(r"_downloads/[0-9a-f]{32}/")
_TEXT = ("h1", "h2", "h3", "h4", "h5", "h6", "summary")
#: a link to a chapter's page (website or slides): the chapter's name
_CHAPTER_LINK = re.compile(r"^(\d+_\w+?)(?:\.slides)?\.html(?:#.*)?$")
#: the elements that hold one entry of a list of chapters (navigation, table of chapters)
_ENTRY = ("li", "tr")


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


class _Page(HTMLParser):
    """The headings, images, box titles, summaries, links and visible text of one page, without
    the entries (`_ENTRY`, or a link outside one) that link to a chapter of `leave_out`."""

    def __init__(self, leave_out=()):
        super().__init__(convert_charrefs=True)
        self.found, self.text, self._open, self._skip = [], [], [], 0
        self.leave_out, self.left_out, self.linked = set(leave_out), Counter(), Counter()
        self._held = []     # open entries: [tag, found, text, chapter of leave_out it links to]

    def _sink(self):
        return (self._held[-1][1], self._held[-1][2]) if self._held else (self.found, self.text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        chapter = _CHAPTER_LINK.match(attrs.get("href") or "") if tag == "a" else None
        if chapter:
            self.linked[chapter.group(1)] += 1
        if tag in _ENTRY or (chapter and chapter.group(1) in self.leave_out and not self._held):
            self._held.append([tag, [], [], None])
        if chapter and chapter.group(1) in self.leave_out:
            self._held[-1][3] = self._held[-1][3] or chapter.group(1)
        found = self._sink()[0]
        if tag in ("script", "style"):
            self._skip += 1
        elif tag == "img":
            src = attrs.get("src", "")
            src = "data:" + _digest(src) if src.startswith("data:") else _DOWNLOAD.sub("_downloads/*/", src)
            found.append(["img", src, attrs.get("alt")])
        elif tag == "a" and attrs.get("href", "").startswith(("_downloads/", "http")):
            found.append(["a", _DOWNLOAD.sub("_downloads/*/", attrs["href"])])
        if tag in _TEXT or "admonition-title" in (attrs.get("class") or ""):
            self._open.append([tag if tag in _TEXT else "box", ""])

    def handle_endtag(self, tag):
        if tag in ("script", "style"):
            self._skip = max(0, self._skip - 1)
        elif self._open and (tag == self._open[-1][0] or (self._open[-1][0] == "box" and tag == "p")):
            kind, text = self._open.pop()
            self._sink()[0].append([kind, " ".join(text.replace("#", "").split())])
        if self._held and tag == self._held[-1][0]:
            _, found, text, chapter = self._held.pop()
            if chapter:
                self.left_out[chapter] += 1
            else:
                sink = self._sink()
                sink[0].extend(found)
                sink[1].extend(text)

    def handle_data(self, data):
        if self._skip:
            return
        for entry in self._open:
            entry[1] += data
        self._sink()[1].append(data)


def _page(text: str, leave_out=()) -> dict:
    parser = _Page(leave_out)
    parser.feed(text)
    return {"found": parser.found, "text": _digest(" ".join(" ".join(parser.text).split()))}


def _notebook(text: str) -> list:
    cells = json.loads(text)["cells"]
    return [[c["cell_type"], c.get("metadata", {}).get("tags", []), _digest("".join(c["source"]))]
            for c in cells]


def _summary(path: Path, leave_out=()):
    if path.suffix == ".html":
        return _page(path.read_text(encoding="utf-8"), leave_out)
    if path.suffix == ".ipynb":
        return _notebook(path.read_text(encoding="utf-8"))
    if path.suffix in (".csv", ".md"):
        return path.read_text(encoding="utf-8")
    return None


def _files(folder: Path):
    return [(_DOWNLOAD.sub("_downloads/*/", p.relative_to(folder).as_posix()), p)
            for p in sorted(folder.rglob("*")) if p.is_file()]


def structure(folder, leave_out=()) -> dict:
    """``{path under folder: summary}`` for every file of `folder` (see the module docstring); the
    pages without their entries that link to a chapter of `leave_out`."""
    return {name: _summary(p, leave_out) for name, p in _files(Path(folder))}


def listed(folder, chapters) -> dict:
    """``{page: {"entries": {chapter: n}, "linked": {chapter: n}}}`` for each page of `folder`: its
    entries (a navigation entry, a table row, a next-page link) that link to each of `chapters`,
    and its links to each chapter at all."""
    out = {}
    for name, path in _files(Path(folder)):
        if path.suffix == ".html":
            parser = _Page(chapters)
            parser.feed(path.read_text(encoding="utf-8"))
            out[name] = {"entries": dict(parser.left_out), "linked": dict(parser.linked)}
    return out


def _names(chapter: str) -> re.Pattern:
    return re.compile(rf"(?:^|/){re.escape(chapter)}(?=\.|-\d+/)")


def chapter_files(summaries: dict, chapter: str) -> set:
    """The files of `chapter` among `summaries` (one part's `structure`): those whose path names it,
    and the figures (``_images/``) that its page shows and no other page does."""
    own = {path for path in summaries if _names(chapter).search(path)}
    shown = {path: {f[1] for f in s["found"] if f[0] == "img"} for path, s in summaries.items()
             if path.endswith(".html") and isinstance(s, dict)}
    mine = set().union(*(shown[path] for path in own if path in shown))
    others = set().union(*(images for path, images in shown.items() if path not in own))
    return own | {path for path in mine - others if path.startswith("_images/") and path in summaries}


def template(path: str, chapter: str) -> str:
    """`path` with the chapter's name as ``{chapter}``, explorer and frame numbers as ``{n}`` and
    ``{i}``, a figure's digest as ``{image}``: the same for every chapter's file of one kind."""
    path = _names(chapter).sub(lambda m: m.group(0)[: -len(chapter)] + "{chapter}", path)
    path = re.sub(r"\{chapter\}-\d+/\d+\.", "{chapter}-{n}/{i}.", path)
    return re.sub(r"^_images/[0-9a-f]+\.", "_images/{image}.", path)


def record(folders: dict) -> dict:
    """``{part: structure(folder)}`` for the folders built by each command of `PARTS`, and under
    ``"chapters"`` the chapters of the release (the notebooks' stems)."""
    out = {part: structure(folders[part]) for part in PARTS}
    out["chapters"] = sorted(Path(name).stem for name in out["release"] if name.endswith(".ipynb"))
    return out


if __name__ == "__main__":
    out, *built = sys.argv[1:]
    Path(out).write_text(json.dumps(record(dict(zip(PARTS, built))), indent=0, sort_keys=True) + "\n",
                         encoding="utf-8")
