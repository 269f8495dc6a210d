"""`check_environment()`: the first code cell of every notebook.

It prints the versions of Python and of the packages the course needs, and
warns, with the command that fixes it, about what would otherwise break later
in the notebook: a package older than the supported lower bound (the bounds of
``pyproject.toml``), or a JupyterLab without the ipywidgets front-end (the
sliders would show as text such as ``VBox(children=...``).

Where the notebook runs decides how the widget front-end can be checked:

* a JupyterLab of your own, or on Binder (repo2docker installs the kernel and
  the JupyterLab server in one environment): the front-end is a JupyterLab
  extension whose ``package.json`` the kernel can read, so it is checked;
* Google Colab: Colab draws widgets with its own widget manager, not with
  JupyterLab extensions, so there is nothing to look for and no warning;
* JupyterLite (Pyodide, ``sys.platform == "emscripten"``): the extensions live
  in the web site, out of the kernel's reach, so the check says it cannot tell
  instead of warning.

Versions are read from the installed package metadata, so the check imports
none of the heavy libraries and runs in milliseconds.
"""

from __future__ import annotations

import json
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from ._validation import as_flag

__all__ = ["check_environment", "EnvironmentReport", "MINIMUM_VERSIONS", "find_widget_frontend"]

#: lower bounds of pyproject.toml (dependencies and the dev extra); a test keeps them in sync
MINIMUM_VERSIONS = {
    "numpy": "1.25",
    "scipy": "1.10",
    "sympy": "1.12",
    "matplotlib": "3.8",
    "ipywidgets": "8.0",
    "anywidget": "0.9",
    "jupyterlab": "4.0.2",
}
MINIMUM_PYTHON = (3, 10)

#: packages that are reported when installed but not required in the kernel
_OPTIONAL = ("jupyterlab", "ipykernel", "coursekit")

#: the JupyterLab front-end of ipywidgets and the first major version that speaks ipywidgets 8
_MANAGER = ("@jupyter-widgets", "jupyterlab-manager")
_MANAGER_MIN_MAJOR = 5
#: the JupyterLab extension of anywidget (checked when anywidget is installed in the kernel)
_ANYWIDGET = ("anywidget",)

# what `detect_host` returns, with the text the report prints for each
_HOSTS = {
    "jupyter": "local Jupyter or Python",
    "binder": "Binder",
    "colab": "Google Colab",
    "jupyterlite": "JupyterLite (Pyodide)",
}


@dataclass
class EnvironmentReport:
    """What `check_environment` found: versions by package and the warnings (empty when fine)."""

    python: str
    versions: dict[str, str | None]
    widget_frontend: str | None
    warnings: list[str] = field(default_factory=list)
    host: str = "jupyter"

    @property
    def ok(self) -> bool:
        return not self.warnings

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"{len(self.warnings)} warning(s)"
        return f"<EnvironmentReport python {self.python}, {state}>"


def _version_tuple(version: str) -> tuple[int, ...]:
    """'1.26.4' -> (1, 26, 4); '2.0.0rc1' -> (2, 0, 0): enough to compare with a lower bound."""
    release = re.match(r"\d+(?:\.\d+){0,2}", version)
    return tuple(map(int, release.group().split("."))) if release else ()


def _installed_version(dist: str) -> str | None:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version(dist)
    except PackageNotFoundError:
        return None


def _server_prefix() -> Path | None:
    """The environment of the Jupyter server that started this kernel (Linux only), if any."""
    exe = Path(f"/proc/{os.getppid()}/exe")
    try:
        cmdline = Path(f"/proc/{os.getppid()}/cmdline").read_bytes().decode(errors="replace")
        target = exe.resolve()
    except OSError:
        return None
    if "jupyter" not in cmdline and "lab" not in cmdline:
        return None
    return target.parent.parent


def _labextension_dirs() -> list[Path]:
    """Every directory JupyterLab reads prebuilt extensions from, as seen from here."""
    dirs = []
    try:
        from jupyter_core.paths import jupyter_path
        dirs += [Path(p) for p in jupyter_path("labextensions")]
    except ImportError:
        dirs.append(Path(sys.prefix) / "share" / "jupyter" / "labextensions")
    server = _server_prefix()
    if server is not None:
        dirs.append(server / "share" / "jupyter" / "labextensions")
    return dirs


def detect_host() -> str:
    """Where this kernel runs: ``"colab"``, ``"jupyterlite"``, ``"binder"`` or ``"jupyter"``.

    Colab is recognised by its ``google.colab`` module, which Colab's kernel
    imports at start; JupyterLite by Pyodide's platform ``emscripten``; Binder
    by the ``BINDER_*`` variables BinderHub sets in the session's environment.
    Anything else is a Jupyter server of one's own.
    """
    if "google.colab" in sys.modules:
        return "colab"
    if sys.platform == "emscripten":
        return "jupyterlite"
    if any(name in os.environ for name in ("BINDER_LAUNCH_HOST", "BINDER_REQUEST", "BINDER_REPO_URL")):
        return "binder"
    return "jupyter"


def find_widget_frontend(dirs: list[Path] | None = None) -> str | None:
    """Version of the installed ``@jupyter-widgets/jupyterlab-manager`` labextension, or None.

    `dirs` is a list of labextension directories to search (default: the
    current environment's); a ValueError says so when it is anything else.
    """
    return _find_labextension(_MANAGER, dirs)


def _find_labextension(name: tuple[str, ...], dirs: list[Path] | None) -> str | None:
    """Version in ``<dir>/<name>/package.json`` for the first directory that has it, or None."""
    if dirs is not None and (isinstance(dirs, (str, bytes, Path)) or not isinstance(dirs, (list, tuple))
                             or not all(isinstance(d, (str, Path)) for d in dirs)):
        raise ValueError(f"dirs must be a list of directories (paths): received {dirs!r}; "
                         "wrap a single directory in a list, [Path(...)].")
    dirs = None if dirs is None else [Path(d) for d in dirs]
    for base in dirs if dirs is not None else _labextension_dirs():
        package = base.joinpath(*name, "package.json")
        if package.is_file():
            try:
                return str(json.loads(package.read_text(encoding="utf-8")).get("version", "unknown"))
            except (OSError, ValueError):
                return "unknown"
    return None


def _version_warnings(versions: dict[str, str | None]) -> list[str]:
    warnings = []
    for name, minimum in MINIMUM_VERSIONS.items():
        have = versions.get(name)
        if have is None:
            if name not in _OPTIONAL:
                warnings.append(f"{name} is not installed in this kernel's environment. "
                                f'Fix: python -m pip install "{name}>={minimum}"')
        elif _version_tuple(have) < _version_tuple(minimum):
            warnings.append(f"{name} {have} is older than the supported {minimum}; some cells will fail. "
                            f'Fix: python -m pip install -U "{name}>={minimum}", then restart the kernel.')
    return warnings


def _frontend_warnings(frontend: str | None, ipywidgets: str | None) -> list[str]:
    if ipywidgets is None:
        return []
    fix = ('Fix: python -m pip install -U "ipywidgets>=8" "jupyterlab>=4" in the environment JupyterLab '
           "runs from, then restart JupyterLab (not only the kernel) and reload the browser tab.")
    if frontend is None:
        return ["the ipywidgets front-end for JupyterLab (@jupyter-widgets/jupyterlab-manager) was not "
                "found: sliders will show as text (VBox(...)) or only as a static figure. " + fix]
    major = _version_tuple(frontend)[:1]
    if major and major[0] < _MANAGER_MIN_MAJOR and _version_tuple(ipywidgets)[:1] >= (8,):
        return [f"the JupyterLab widget front-end {frontend} is too old for ipywidgets {ipywidgets}: "
                "widgets will show 'Error displaying widget'. " + fix]
    return []


def _anywidget_warnings(anywidget: str | None) -> list[str]:
    """anywidget installed in the kernel but its JupyterLab extension not found: figures stay blank.

    (A missing anywidget is reported with the other required packages.)
    """
    if anywidget is None or _find_labextension(_ANYWIDGET, None) is not None:
        return []
    return [f"anywidget {anywidget} is installed in the kernel but its JupyterLab extension was not found: "
            "the explorers' figures will stay blank. Fix: python -m pip install -U anywidget in the "
            "environment JupyterLab runs from, then restart JupyterLab and reload the browser tab."]


def _widget_checks(host: str, versions: dict[str, str | None]) -> tuple[str | None, list[str]]:
    """(front-end description, warnings) for the widget front-end on this host."""
    if host == "colab":
        return "Colab's own widget manager", []
    if host == "jupyterlite":
        return "not checkable from a JupyterLite kernel", []
    frontend = find_widget_frontend()
    warnings = _frontend_warnings(frontend, versions.get("ipywidgets"))
    if frontend is not None:
        warnings += _anywidget_warnings(versions.get("anywidget"))
    return frontend, warnings


def check_environment(*, show: bool = True) -> EnvironmentReport:
    """Print Python's and the course packages' versions and warn about what will break.

    Warns (with the command that fixes it) when a package is older than the
    lower bound of ``pyproject.toml`` or missing, when Python is older than
    3.10, and when the JupyterLab front-end of ipywidgets (or of anywidget,
    when that is installed) is not found. On Colab and JupyterLite the
    front-end is not a JupyterLab extension the kernel can see, so it is not
    looked for there (see the module docstring). Returns an
    `EnvironmentReport`; ``show=False`` only builds it.
    """
    show = as_flag(show, "show")
    host = detect_host()
    names = [*MINIMUM_VERSIONS, *(n for n in _OPTIONAL if n not in MINIMUM_VERSIONS)]
    versions = {name: _installed_version(name) for name in names}
    python = ".".join(map(str, sys.version_info[:3]))
    warnings = []
    if sys.version_info[:2] < MINIMUM_PYTHON:
        warnings.append(f"Python {python} is older than 3.10: make a new environment with Python 3.10 "
                        "or newer (see environment.md).")
    warnings += _version_warnings(versions)
    frontend, widget_warnings = _widget_checks(host, versions)
    report = EnvironmentReport(python=python, versions=versions, widget_frontend=frontend,
                               warnings=warnings + widget_warnings, host=host)
    if show:
        _print_report(report)
    return report


def _print_report(report: EnvironmentReport) -> None:
    print(f"Python {report.python} ({_HOSTS[report.host]})")
    for name, version in report.versions.items():
        print(f"  {name:<11} {version or 'not installed'}")
    where = "" if report.host in ("colab", "jupyterlite") else "  (JupyterLab front-end of ipywidgets)"
    print(f"  {'widgets UI':<11} {report.widget_frontend or 'not found'}{where}")
    if report.ok:
        print("Environment OK.")
    for message in report.warnings:
        print(f"WARNING: {message}")
