"""Seal a grader's kernel off with bubblewrap (``bwrap``).

`Sandbox.command` wraps the command line of one submission's kernel so that it
runs with

* the whole filesystem invisible but for what Python needs, read-only: the
  system folders (``/usr``, the ``/lib`` and ``/bin`` links), a few files of
  ``/etc`` (the dynamic loader's cache, fonts, time zone), the Python
  installation and its ``sys.path`` folders, and the ``coursekit`` package;
  the instructor's home, the other submissions, the grader's own folders and
  its working folder are not there;
* one writable folder on disk, the submission's `box` (its answers file, the
  kernel's connection file and sockets, matplotlib's settings folder, which
  `Sandbox.prepare` seeds with the grader's font list so that no kernel
  spends a second building its own), through which the answers leave;
* memory-backed scratch (``/tmp`` with the working folder and ``HOME`` in it)
  of `scratch_bytes` at most;
* no network (a network namespace of its own with loopback only), its own
  process, IPC and host-name namespaces (it sees no other process, and every
  process it starts ends with it), a new session (no access to the grader's
  terminal), no environment variable but those it is given, and no
  capabilities;
* and it ends when the process that started it ends (``--die-with-parent``).

Folders given as `hidden` (the submissions, the output folder, the grader's
temporary folder) are covered by an empty folder even when they lie inside a
folder the kernel must read (a virtual environment in the course folder, say).

`check_sandbox` tries the sandbox once before a grading run, so that a machine
where bwrap is missing or cannot make namespaces (macOS, a locked-down
container) is told so at once, in one line, instead of failing every
notebook. Only Linux has bwrap.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["SandboxUnavailable", "Sandbox", "find_bwrap", "check_sandbox", "SCRATCH_BYTES"]

#: memory-backed scratch space of one kernel (its /tmp, working folder and home)
SCRATCH_BYTES = 512 * 2**20

#: files of /etc a Python kernel reads (the rest of /etc stays invisible)
_ETC = ("ld.so.cache", "ld.so.conf", "ld.so.conf.d", "alternatives", "fonts", "localtime", "passwd", "group",
        "nsswitch.conf", "mime.types")

#: top-level folders that are links into /usr on most systems (bound as they are)
_SYSTEM = ("usr", "bin", "sbin", "lib", "lib32", "lib64", "libx32")

#: the environment variables a kernel keeps from the grader (every other one is dropped)
_KEPT_ENV = ("LANG", "LC_ALL", "LC_CTYPE", "TZ", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


class SandboxUnavailable(RuntimeError):
    """The sandbox cannot be used on this machine; the message says why and what to do."""


def find_bwrap() -> str | None:
    """The path of the ``bwrap`` program, or None when it is not installed."""
    return shutil.which("bwrap")


def _inside(path: Path, folders) -> bool:
    return any(path == folder or folder in path.parents for folder in folders)


def _python_folders(package_root: Path) -> list[Path]:
    """The folders a kernel reads Python and its packages from. Never the working folder
    (``python -m`` puts it on ``sys.path``), the home folder or one of their parents: a
    ``sys.path`` entry such as these would show the instructor's files whole."""
    candidates = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix,
                  sysconfig.get_paths()["stdlib"], sysconfig.get_paths()["purelib"],
                  sysconfig.get_paths()["platlib"], os.path.dirname(os.path.realpath(sys.executable))}
    candidates.update(entry for entry in sys.path if entry and os.path.isabs(entry))
    private = [Path.cwd().resolve(), Path.home().resolve()]
    folders = set()
    for entry in candidates:
        path = Path(entry).resolve()
        if path.is_dir() and not any(path == folder or path in folder.parents for folder in private):
            folders.add(path)
    folders.add(package_root / "coursekit")
    system = [Path("/") / name for name in _SYSTEM]     # bound whole already
    return sorted(f for f in folders if not _inside(f.parent, folders) and not _inside(f, system))


@dataclass(frozen=True)
class Sandbox:
    """How one submission's kernel is sealed off (see the module docstring).

    `box` is the submission's one writable folder on disk, bound at the same
    path inside; `hidden` the folders covered even when inside a visible one;
    `package_root` the folder that holds the ``coursekit`` package the kernel
    imports (read-only).
    """

    box: Path
    package_root: Path
    hidden: tuple[Path, ...] = ()
    scratch_bytes: int = SCRATCH_BYTES
    env: dict = field(default_factory=dict)

    #: the kernel's working folder and home, in its scratch space
    workdir = "/tmp/submission"
    home = "/tmp/home"

    def _filesystem(self) -> list[str]:
        args = []
        for name in _SYSTEM:
            path = Path("/") / name
            if path.is_symlink():
                args += ["--symlink", os.readlink(path), str(path)]
            elif path.is_dir():
                args += ["--ro-bind", str(path), str(path)]
        for name in _ETC:
            args += ["--ro-bind-try", f"/etc/{name}", f"/etc/{name}"]
        args += ["--proc", "/proc", "--dev", "/dev", "--size", str(self.scratch_bytes), "--tmpfs", "/tmp",
                 "--dir", self.workdir, "--dir", self.home]
        visible = _python_folders(self.package_root)
        for folder in visible:
            args += ["--ro-bind", str(folder), str(folder)]
        for folder in self.hidden:
            folder = Path(folder).resolve()
            if _inside(folder, visible) or _inside(self.box.resolve(), [folder]):
                args += ["--tmpfs", str(folder)]
        box = str(self.box.resolve())
        return args + ["--bind", box, box]

    def _environment(self) -> list[str]:
        env = {name: os.environ[name] for name in _KEPT_ENV if name in os.environ}
        env.update({"PATH": f"{os.path.dirname(sys.executable)}:/usr/bin:/bin", "HOME": self.home,
                    "TMPDIR": "/tmp", "MPLCONFIGDIR": str(self.box.resolve() / "matplotlib"),
                    "IPYTHONDIR": f"{self.home}/ipython", "PYTHONPATH": str(self.package_root),
                    "PYTHONDONTWRITEBYTECODE": "1", **self.env})
        args = ["--clearenv"]
        for name, value in sorted(env.items()):
            args += ["--setenv", name, str(value)]
        return args

    def prepare(self) -> None:
        """Make the box's matplotlib folder, with a copy of the grader's font list when there is one."""
        folder = self.box / "matplotlib"
        folder.mkdir(parents=True, exist_ok=True)
        import matplotlib
        import matplotlib.font_manager  # noqa: F401  (writes the font list when the grader has none yet)
        for cache in Path(matplotlib.get_cachedir()).glob("fontlist-*.json"):
            shutil.copyfile(cache, folder / cache.name)

    def command(self, argv: list[str]) -> list[str]:
        """`argv` run inside the sandbox (``bwrap`` must exist: see `check_sandbox`)."""
        bwrap = find_bwrap() or "bwrap"
        isolation = ["--unshare-all", "--die-with-parent", "--new-session", "--cap-drop", "ALL",
                     "--hostname", "coursekit-grader"]
        return [bwrap, *isolation, *self._filesystem(), *self._environment(), "--chdir", self.workdir,
                "--", *argv]


def check_sandbox(sandbox: Sandbox) -> None:
    """Start Python with coursekit and ipykernel inside `sandbox` once; SandboxUnavailable if it fails."""
    if not sys.platform.startswith("linux"):
        raise SandboxUnavailable(f"the grader's sandbox (bubblewrap) runs on Linux only, this is {sys.platform}")
    if find_bwrap() is None:
        raise SandboxUnavailable("bubblewrap (bwrap) is not installed: install it (Debian, Ubuntu: "
                                 "apt-get install bubblewrap; Fedora: dnf install bubblewrap)")
    probe = [sys.executable, "-c", "import coursekit.exercises, ipykernel"]
    sandbox.prepare()
    try:
        done = subprocess.run(sandbox.command(probe), capture_output=True, text=True, timeout=120,
                              stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise SandboxUnavailable(f"bwrap could not be started: {error}") from None
    if done.returncode != 0:
        said = (done.stderr.strip().splitlines() or ["no message"])[-1][:300]
        raise SandboxUnavailable(f"bwrap could not start a sandboxed Python here: {said} (user namespaces "
                                 "may be disabled for your user: see docs/grading.md)")
