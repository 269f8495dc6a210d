"""Grade a folder of submitted notebooks (``python -m coursekit grade``), each sealed off.

* `grader`: `grade` runs every submission and writes the grade book and the feedback; the
  answers are checked again here, outside the notebook;
* `runner`: runs one notebook's cells (``python -m coursekit.tools.grading.runner JOB``), outside
  the sandbox, and reports its outcome;
* `kernel`: starts a kernel with memory, CPU-time and file-size limits
  (``python -m coursekit.tools.grading.kernel``);
* `sandbox`: seals a kernel off with bubblewrap.

The answers' format, written in the kernel and read here, is `coursekit.exercises._answers`.
The names below come from `grader`, imported when first used, so that the runner and the
kernel, which start as modules of this package, do not load the checks.
"""

from __future__ import annotations

import importlib

__all__ = ["STATUSES", "Outcome", "grade", "parse_memory", "grade_answers", "student_id", "SandboxUnavailable"]


def __getattr__(name: str):
    if name in __all__:
        return getattr(importlib.import_module(".grader", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
