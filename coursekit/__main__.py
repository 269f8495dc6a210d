"""Instructor tools on the command line: ``python -m coursekit COMMAND ...``.

Each command is one small function ``_add_<command>(commands)`` that adds its
parser to the subparsers `commands` and sets ``run`` to a function taking the
parsed arguments and returning the exit status; `COMMANDS` lists them in the
order ``--help`` shows them. The work itself lives in a module of the package
(`coursekit.tools.release`, `coursekit.tools.slides`, ...) whose functions take paths, so
the same work is done from Python and tested there.

A bad argument (a folder that is not empty, a missing notebooks folder) stops
with ``coursekit COMMAND: error: ...`` and exit status 2, as argparse does for
its own errors.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["main", "build_parser", "COMMANDS"]


def _add_release(commands) -> None:
    parser = commands.add_parser(
        "release", help="write the student edition of the notebooks (no worked solutions)",
        description="Write the student edition of the course notebooks into a folder: every cell "
                    "tagged 'solution' removed, outputs cleared, the exercises and their check_* cells "
                    "kept, and a note in the first cell saying the worked solutions are in the "
                    "instructor edition. The edition runs top to bottom without errors.")
    parser.add_argument("--out", required=True, type=Path, metavar="DIR",
                        help="folder to write the notebooks to (created when missing; must be empty "
                             "unless --force is given)")
    parser.add_argument("--notebooks", type=Path, default=None, metavar="DIR",
                        help="folder of the instructor notebooks (default: the repository's notebooks/)")
    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty --out folder, overwriting notebooks of the same "
                             "names (other files there are left alone)")
    parser.set_defaults(run=_run_release)


def _run_release(args) -> int:
    from .tools.release import build_release
    written = build_release(args.out, notebooks=args.notebooks, force=args.force)
    print(f"student edition: {len(written)} notebooks written to {args.out}")
    for path in written:
        print(f"  {path.name}")
    return 0


def _add_slides(commands) -> None:
    parser = commands.add_parser(
        "slides", help="build every chapter's slides (--out DIR), or set the notebooks' slide metadata",
        description="With --out DIR: execute every chapter notebook and write it as a reveal.js slide "
                    "show into DIR, with an index page linking the chapters; reveal.js and MathJax are "
                    "copied into DIR, so the slides work offline (open DIR/index.html). Explorers show "
                    "their figure for the default slider values. Needs the slides extra: python -m pip "
                    "install -e \".[slides]\". Without --out: give every cell of the notebooks its slide "
                    "type (one slide per section, ## heading; a sub-slide per subsection, ### heading, "
                    "and per paragraph with its code), rewriting them in place; --check only reports the "
                    "notebooks that are out of date. With --kernel-metadata, also store the kernel "
                    "metadata JupyterLab writes when it opens a notebook with this environment's python3 "
                    "kernel (its Python version included), so that a notebook opened and closed "
                    "untouched asks nothing.")
    parser.add_argument("--notebooks", type=Path, default=None, metavar="DIR",
                        help="folder of the notebooks (default: the repository's notebooks/)")
    action = parser.add_mutually_exclusive_group()
    action.add_argument("--out", type=Path, default=None, metavar="DIR",
                        help="build the slides into DIR (created when missing; earlier slides there are "
                             "replaced, any other non-empty folder is refused)")
    action.add_argument("--check", action="store_true",
                        help="change nothing; exit with status 1 when a notebook's slide metadata (and, "
                             "with --kernel-metadata, its kernel metadata) is out of date")
    parser.add_argument("--kernel-metadata", action="store_true",
                        help="also store the kernel metadata of this environment's python3 kernel (run "
                             "it with the course's reference Python; see CONTRIBUTING.md)")
    parser.set_defaults(run=_run_slides)


def _run_slides(args) -> int:
    if args.out is not None:
        from .tools.slideshow import build_slides
        index = build_slides(args.out, notebooks_dir=args.notebooks, verbose=True)
        print(f"slides written to {index.parent}\nopen {index} in a browser (no network needed)")
        return 0
    from .tools.slides import apply_slide_metadata
    changed = apply_slide_metadata(args.notebooks, write=not args.check)
    if args.check:
        for path in changed:
            print(f"slide metadata out of date: {path.name} (run: python -m coursekit slides)")
    else:
        print(f"slide metadata updated in {len(changed)} notebook(s)" if changed else
              "slide metadata already up to date")
    stale = _run_kernel_metadata(args) if args.kernel_metadata else []
    return 1 if args.check and (changed or stale) else 0


def _run_kernel_metadata(args) -> list:
    from .tools.kernel_metadata import apply_kernel_metadata, kernel_metadata
    metadata = kernel_metadata()
    changed = apply_kernel_metadata(args.notebooks, write=not args.check, metadata=metadata)
    python = metadata["language_info"].get("version", "?")
    for path in changed if args.check else []:
        print(f"kernel metadata out of date for Python {python}: {path.name} "
              "(run: python -m coursekit slides --kernel-metadata)")
    if not args.check:
        print(f"kernel metadata of Python {python} stored in {len(changed)} notebook(s)" if changed else
              f"kernel metadata already that of Python {python}")
    return changed


def _add_colab(commands) -> None:
    parser = commands.add_parser(
        "colab", help="write the repository's address into the notebooks' install cell (for Colab)",
        description="Colab opens a notebook without the rest of the repository, so the first code cell "
                    "of every notebook installs coursekit from the repository where it is missing. This "
                    "writes the repository's https address into that cell (it does nothing where "
                    "coursekit is installed). Default address: the git remote 'origin'.")
    parser.add_argument("--repository", default=None, metavar="URL",
                        help="https address of the course repository, e.g. https://github.com/OWNER/NAME "
                             "(default: the address of the git remote 'origin')")
    parser.add_argument("--notebooks", type=Path, default=None, metavar="DIR",
                        help="folder of the notebooks (default: the repository's notebooks/)")
    parser.set_defaults(run=_run_colab)


def _run_colab(args) -> int:
    from .tools.colab import apply_install_cell, repository_from_git
    from .tools.notebooks import default_notebook_dir
    folder = args.notebooks or default_notebook_dir()
    repository = args.repository or repository_from_git(folder)
    if repository is None:
        raise ValueError("no --repository given and the git remote 'origin' has no https or ssh address; "
                         "pass --repository https://github.com/OWNER/NAME")
    changed = apply_install_cell(folder, repository=repository)
    print(f"install cell now installs from {repository}: {len(changed)} notebook(s) changed")
    return 0


def _add_site(commands) -> None:
    parser = commands.add_parser(
        "site", help="build the course website (static, works offline)",
        description="Execute the chapter notebooks and build a static website of the course into "
                    "DIR: chapter navigation, equations typeset, every figure, explorers as "
                    "their static figures, erratum boxes, solutions folded. Needs the site "
                    "extra: python -m pip install -e \".[site]\". View it with "
                    "python -m http.server -d DIR (or open DIR/index.html).")
    parser.add_argument("--out", required=True, type=Path, metavar="DIR",
                        help="folder to write the site into (an earlier site there is replaced)")
    edition = parser.add_mutually_exclusive_group()
    edition.add_argument("--student", action="store_true",
                         help="build from the student edition: exercises without their solutions")
    edition.add_argument("--student-out", type=Path, default=None, metavar="DIR2",
                         help="also build the student edition into DIR2, from the same execution of the "
                              "notebooks (both editions in the time of one)")
    parser.add_argument("--notebooks", type=Path, default=None, metavar="DIR",
                        help="folder of the chapter notebooks (default: the repository's notebooks/)")
    parser.set_defaults(run=_run_site)


def _run_site(args) -> int:
    from .tools.site import build_site
    index = build_site(args.out, student=args.student, student_out=args.student_out,
                       notebooks_dir=args.notebooks, verbose=True)
    also = f" and its student edition to {args.student_out}" if args.student_out else ""
    print(f"site written to {index.parent}{also}\n"
          f"view it: python -m http.server -b 127.0.0.1 -d {index.parent}  (then open "
          "http://127.0.0.1:8000), or open index.html in a browser")
    return 0


_SANDBOX = (
    "Each notebook's kernel runs sealed off with bubblewrap (bwrap; Debian/Ubuntu: apt-get install "
    "bubblewrap): the filesystem read-only and reduced to what Python needs, one private writable folder, "
    "no network, no other process visible, nothing left running after it. Where bwrap cannot run (not "
    "Linux, not installed, user namespaces refused) the grader stops and says so; --no-sandbox then runs "
    "the notebooks with your rights, or run the grader in a container (docker or podman run --rm "
    "--network none ...). See docs/grading.md.")


def _add_grade(commands) -> None:
    parser = commands.add_parser(
        "grade", help="grade a folder of submitted notebooks (grades.csv and feedback per student)",
        description="Execute each submitted notebook of SUBMISSIONS (file name stem = student id) top to "
                    "bottom in a fresh kernel of its own, sealed off in a sandbox, "
                    "with time, memory and file-size limits; record the answers its check_* calls receive and "
                    "check the last answer to each exercise again with the course's own checks, outside "
                    "the notebook (a check replaced or patched in the notebook awards nothing). Writes "
                    "DIR/grades.csv (one row per student: 1 or 0 per exercise, total, status) and "
                    "DIR/feedback/STUDENT.md (what each check says about the answer, never the solution). "
                    "Needs the grade extra: python -m pip install -e \".[grade]\". "
                    "Statuses: " + "; ".join(f"{k}: {v}" for k, v in _statuses().items()) + ". "
                    + _SANDBOX)
    parser.add_argument("submissions", type=Path, metavar="SUBMISSIONS",
                        help="folder of the submitted notebooks (*.ipynb), one per student")
    parser.add_argument("--chapter", required=True, type=int, metavar="N",
                        help="the chapter the notebooks are (one of the chapters with exercises)")
    parser.add_argument("--out", required=True, type=Path, metavar="DIR",
                        help="folder for grades.csv and feedback/ (created when missing; an earlier "
                             "grades.csv and feedback/*.md there are replaced)")
    parser.add_argument("--timeout", type=float, default=300, metavar="SECONDS",
                        help="time limit of each notebook, all cells together (default: 300)")
    parser.add_argument("--memory", default="4G", metavar="SIZE",
                        help="address-space limit of each notebook's kernel, e.g. 4G or 512M (default: 4G)")
    parser.add_argument("--jobs", type=int, default=None, metavar="N",
                        help="notebooks run at once (default: the number of cores)")
    parser.add_argument("--no-sandbox", dest="sandbox", action="store_false",
                        help="run the notebooks WITHOUT the bubblewrap sandbox, with your own rights: they "
                             "can read, change or delete your files and use the network (only for "
                             "notebooks you trust, or inside a container)")
    parser.set_defaults(run=_run_grade)


def _statuses() -> dict:
    from .tools.grading import STATUSES
    return STATUSES


def _run_grade(args) -> int:
    from .tools.grading import grade
    table = grade(args.submissions, args.out, chapter=args.chapter, timeout=args.timeout,
                  memory=args.memory, jobs=args.jobs, sandbox=args.sandbox)
    print(f"grades written to {table}, feedback to {table.parent / 'feedback'}")
    return 0


#: one function per command, in the order of --help
COMMANDS = (_add_release, _add_slides, _add_colab, _add_site, _add_grade)


def build_parser() -> argparse.ArgumentParser:
    """The ``python -m coursekit`` parser with one subcommand per entry of `COMMANDS`."""
    parser = argparse.ArgumentParser(
        prog="python -m coursekit",
        description="Instructor tools of the coursekit course companion. "
                    "Run 'python -m coursekit COMMAND --help' for the options of a command.")
    commands = parser.add_subparsers(title="commands", dest="command", metavar="COMMAND", required=True)
    for add in COMMANDS:
        add(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Parse `argv` (default: the command line), run the command and return its exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except (ValueError, TypeError, RuntimeError, OSError) as error:
        parser.exit(2, f"{parser.prog} {args.command}: error: {error}\n")


if __name__ == "__main__":
    from .tools.notebooks import leave_out_the_iri_grammar
    leave_out_the_iri_grammar()      # this process is the tools' own: 0.8 s of a core less
    sys.exit(main())
