"""docs/extending.md applied to a copy of the project: its ``python`` blocks, in order.

A block whose first line is ``# file: PATH`` is written to PATH; every other ``python`` block
runs, in order, in one interpreter started at the copy's root. `tests/test_extending.py` checks
the copy; ``python tests/extending_doc.py DEST`` makes one to run the README's whole test command in.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

__all__ = ["ROOT", "DOC", "BUILT", "doc_blocks", "copy_project", "run_in", "extend", "is_extended"]

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "extending.md"
_BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)
#: what clones, installs, checks and builds leave in a project, never copied
BUILT = {".git", "__pycache__", ".pytest_cache", ".hypothesis", "build", "site", "site-student",
         ".ipynb_checkpoints", ".venv"}


def doc_blocks() -> list[tuple[str, str]]:
    """The doc's fenced blocks as (language, body), in order."""
    return _BLOCK.findall(DOC.read_text(encoding="utf-8"))


def is_extended(root: Path = ROOT) -> bool:
    """Whether `root` already holds the doc's chapter 5 (a copy made by `extend`)."""
    return (root / "coursekit" / "exercises" / "ch5.py").exists()


def copy_project(to: Path) -> None:
    """The project's files as a fresh clone has them (no caches, builds or git data)."""
    shutil.copytree(ROOT, to, ignore=shutil.ignore_patterns(*BUILT, "*.egg-info"))


def run_in(args: list[str], root: Path, timeout: float) -> subprocess.CompletedProcess:
    """Run `args` at `root` with `root` first on the import path and figures off screen."""
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg")
    return subprocess.run(args, cwd=root, env=env, capture_output=True, text=True, timeout=timeout)


def extend(to: Path) -> None:
    """Copy the project to `to` and apply every ``python`` block of the doc there, in order.

    Raises ``RuntimeError`` with the blocks' output when they fail.
    """
    copy_project(to)
    script = []
    for lang, body in doc_blocks():
        if lang != "python":
            continue
        if body.startswith("# file: "):
            path = to / body.splitlines()[0].removeprefix("# file: ").strip()
            path.write_text(body.split("\n", 1)[1], encoding="utf-8")
        else:
            script.append(body)
    blocks = to / "extending_blocks.py"
    blocks.write_text("\n\n".join(script), encoding="utf-8")
    result = run_in([sys.executable, blocks.name], to, timeout=600)
    blocks.unlink()
    if result.returncode != 0:
        raise RuntimeError(f"the doc's blocks failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")


def main(argv: list[str]) -> int:
    if len(argv) != 1 or Path(argv[0]).exists():
        print("usage: python tests/extending_doc.py DEST  (DEST: a folder that does not exist yet)",
              file=sys.stderr)
        return 2
    extend(Path(argv[0]))
    print(f"docs/extending.md applied in {argv[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
