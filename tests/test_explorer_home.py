"""HomeThread: widget callbacks that arrive on another thread (a kernel subshell) run on the
thread whose event loop built the widget (the kernel's main thread), one at a time."""

import asyncio
import threading

import pytest

from coursekit.explorers._home import HomeThread


@pytest.fixture
def home():
    """A HomeThread made inside an event loop running on its own thread (like a kernel's main
    thread), and a function to run code on that loop and wait for it."""
    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, name="home", daemon=True)
    thread.start()

    def on_home(fn):
        async def call():
            return fn()
        return asyncio.run_coroutine_threadsafe(call(), loop).result(timeout=10)

    yield on_home(HomeThread), on_home
    loop.call_soon_threadsafe(loop.stop)
    thread.join(timeout=10)
    loop.close()


def test_a_callback_from_another_thread_runs_on_the_home_thread(home):
    runner, on_home = home
    ran = []
    runner.run(lambda: ran.append((1, threading.current_thread().name)))   # from this thread
    on_home(lambda: None)                     # the loop has run what was queued before
    assert ran == [(1, "home")]


def test_a_callback_on_the_home_thread_runs_at_once(home):
    runner, on_home = home
    ran = []
    on_home(lambda: (runner.run(lambda: ran.append("now")), ran.append("after")))
    assert ran == ["now", "after"]


def test_calls_with_a_key_are_queued_once_while_one_waits(home):
    runner, on_home = home
    gate, calls = threading.Event(), []
    runner.run(lambda: gate.wait(10))         # the home thread is busy (a cell running)
    for _ in range(5):
        runner.run(lambda: calls.append("redraw"), key="refresh")
    runner.run(lambda: calls.append("other"))
    gate.set()
    on_home(lambda: None)
    assert calls == ["redraw", "other"]
    runner.run(lambda: calls.append("redraw"), key="refresh")    # queued again once it ran
    on_home(lambda: None)
    assert calls == ["redraw", "other", "redraw"]


def test_an_error_in_a_queued_callback_is_reported_and_the_next_runs(home, capsys):
    runner, on_home = home

    def fails():
        raise ValueError("m: the mass must be positive")

    ran = []
    runner.run(fails)
    runner.run(lambda: ran.append("next"))
    on_home(lambda: None)
    assert ran == ["next"]
    assert "ValueError: m: the mass must be positive" in capsys.readouterr().err


def test_without_an_event_loop_callbacks_run_where_they_arrive():
    runner = HomeThread()                     # plain Python: no loop runs here
    assert runner.loop is None
    ran = []
    worker = threading.Thread(target=lambda: runner.run(lambda: ran.append(threading.current_thread().name)),
                              name="worker")
    worker.start()
    worker.join()
    assert ran == ["worker"]
