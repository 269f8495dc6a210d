"""Widget callbacks run on the kernel's main thread, one at a time.

A front end may hand widget messages to a second kernel thread (a *subshell*: JupyterLab 4.6
with ipykernel 7), while the main thread draws; matplotlib is not safe for that. `HomeThread`
runs each callback on the thread and event loop that built the widget: at once when it arrives
there, else queued on the loop; without a loop, where it arrives.
"""

from __future__ import annotations

import asyncio
import threading
import traceback
from typing import Any, Callable, Hashable

__all__ = ["HomeThread"]


class HomeThread:
    """Runs callbacks on the thread (and event loop) that created it."""

    def __init__(self) -> None:
        self.thread = threading.current_thread()
        try:
            self.loop = asyncio.get_running_loop()
        except RuntimeError:
            self.loop = None
        self._queued: set = set()

    def run(self, fn: Callable[[], Any], *, key: Hashable | None = None) -> None:
        """Call ``fn()`` on the home thread: now when called there (or when no loop runs there),
        else queued on its loop; with `key`, not while a call with that key waits (it would do
        the same work: a redraw that reads the sliders' values when it runs)."""
        if threading.current_thread() is self.thread or self.loop is None or self.loop.is_closed():
            return fn()
        if key is None or key not in self._queued:
            self._queued.add(key)
            self.loop.call_soon_threadsafe(self._call, fn, key)

    def _call(self, fn: Callable[[], Any], key: Hashable | None) -> None:
        self._queued.discard(key)   # forgotten first: a change while it runs queues the next call
        try:
            fn()
        except Exception:   # noqa: BLE001 - as for any widget callback: reported, the kernel goes on
            traceback.print_exc()
