"""``ex.progress(1)``: which exercises of a chapter are done in this session.

Each exercise is in one of three states, from the last answer its check got
in this kernel session: "not tried" (its check was not run), "not yet" (the
last answer was not right) or "correct". The overview lists the chapter's
exercises with the section of the notes each practises; it shows no answer
and no solution. Jupyter shows it as a table (`Progress._repr_html_`), a
plain prompt as text (`Progress.__repr__`).
"""

from __future__ import annotations

import html

from ._catalog import STATE, Exercise, chapter_exercises, chapters

__all__ = ["progress", "Progress", "NOT_TRIED", "NOT_YET", "CORRECT"]

NOT_TRIED, NOT_YET, CORRECT = "not tried", "not yet", "correct"

_MARKS = {NOT_TRIED: "·", NOT_YET: "✗", CORRECT: "✓"}
#: each at least 4.5:1 against white and against the grey (#f5f5f5) of a table's striped rows
_COLOURS = {NOT_TRIED: "#6b6b6b", NOT_YET: "#a35200", CORRECT: "#1a7f37"}


def _state(check: str) -> str:
    if check not in STATE:
        return NOT_TRIED
    return CORRECT if STATE[check] else NOT_YET


class Progress:
    """The state of each exercise of some chapters, as it was when `progress` was called."""

    def __init__(self, rows: list[tuple[Exercise, str]]):
        self.rows = tuple(rows)

    def count(self, state: str) -> int:
        """How many exercises are in `state` (`CORRECT`, `NOT_YET` or `NOT_TRIED`)."""
        return sum(1 for _, s in self.rows if s == state)

    def summary(self) -> str:
        """ "Chapter 1: 2 of 5 exercises correct, 1 not yet, 2 not tried"."""
        numbers = sorted({e.chapter for e, _ in self.rows})
        where = f"Chapter {numbers[0]}" if len(numbers) == 1 else "Chapters " + ", ".join(map(str, numbers))
        return (f"{where}: {self.count(CORRECT)} of {len(self.rows)} exercises correct, "
                f"{self.count(NOT_YET)} not yet, {self.count(NOT_TRIED)} not tried")

    def __repr__(self) -> str:
        width = max(len(e.title) for e, _ in self.rows) + 2
        lines = [self.summary()]
        lines += [f"  {_MARKS[s]} {e.label:<4} {e.title:<{width}} {s:<10} (section {e.section})"
                  for e, s in self.rows]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>Exercise {e.label}</td><td>{html.escape(e.title)}</td>"
            f"<td>{html.escape(e.section)}</td>"
            f"<td style='color:{_COLOURS[s]};font-weight:600'>{_MARKS[s]} {s}</td></tr>"
            for e, s in self.rows)
        return ("<table class='coursekit-progress'><caption style='text-align:left'>"
                f"{self.summary()}</caption>"
                "<thead><tr><th>Exercise</th><th>Title</th><th>Section of the notes</th>"
                f"<th>State</th></tr></thead><tbody>{rows}</tbody></table>")


def progress(chapter: int | None = None) -> Progress:
    """The exercises of `chapter` (every chapter when None) and their state in this session.

    A state is "not tried", "not yet" or "correct", from the last answer given
    to the exercise's check since the kernel started. Shown in Jupyter as a
    table; nothing in it gives an answer away.
    """
    numbers = chapters() if chapter is None else [chapter]
    rows = [(e, _state(e.check)) for n in numbers for e in chapter_exercises(n)]
    return Progress(rows)
