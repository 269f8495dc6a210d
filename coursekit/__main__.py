"""Instructor tools on the command line: ``python -m coursekit COMMAND``.

``python -m coursekit site --out DIR [--student]`` builds the course website (see
:mod:`coursekit.site`; needs the ``site`` extra).
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    """Run the command named in `argv` (default: the command line) and return its exit code."""
    parser = argparse.ArgumentParser(prog="python -m coursekit",
                                     description="Instructor tools for the coursekit notebooks.")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_site(commands)
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except (ValueError, TypeError, RuntimeError) as error:
        print(f"python -m coursekit {args.command}: {error}", file=sys.stderr)
        return 1


def _add_site(commands) -> None:
    site = commands.add_parser(
        "site", help="build the course website (static, works offline)",
        description="Execute the chapter notebooks and build a static website of the course into "
                    "DIR: chapter navigation, equations typeset, every figure, explorers as "
                    "their static figures, erratum boxes, solutions folded. Needs the site "
                    "extra: python -m pip install -e \".[site]\". View it with "
                    "python -m http.server -d DIR (or open DIR/index.html).")
    site.add_argument("--out", required=True, metavar="DIR",
                      help="folder to write the site into (replaced if it exists)")
    site.add_argument("--student", action="store_true",
                      help="build from the student edition: exercises without their solutions")
    site.add_argument("--notebooks", metavar="NOTEBOOKS_DIR", default=None,
                      help="folder of the chapter notebooks (default: the repository's notebooks/)")
    site.set_defaults(run=_run_site)


def _run_site(args) -> int:
    from coursekit.site import build_site
    index = build_site(args.out, student=args.student, notebooks_dir=args.notebooks, verbose=True)
    print(f"site written to {index.parent}\n"
          f"view it: python -m http.server -b 127.0.0.1 -d {index.parent}  (then open "
          "http://127.0.0.1:8000), or open index.html in a browser")
    return 0


if __name__ == "__main__":
    sys.exit(main())
