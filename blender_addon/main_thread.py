# SPDX-License-Identifier: MIT
"""Blender work asked for from the render thread and done on the main thread.

In the UI, render handlers run in the render thread. Saving the Render Result there deadlocks
Blender (5.2.2, about 1 animation render in 10): the render thread, in Image.save_render, holds
the viewer lock and waits for the Render Result image's cache mutex, while the main thread,
drawing the render window, holds that mutex and waits for the viewer lock. So a handler only
queues the work (call()); the add-on's main-thread timer does it (serve()) while the render
thread waits on an event, which holds no Blender lock and releases the GIL. The render thread
must not go on before the work is done: the next frame would replace the Render Result.

How long it waits: as long as the main thread is alive, i.e. runs serve() at least every
STALL_LIMIT seconds. A main thread that stops serving (Blender quitting during the render, the
add-on disabled) abandons the work: call() raises Abandoned, and the work is never done later
(it would read a later frame's Render Result)."""
import threading
import time

STALL_LIMIT = 30.0  # seconds the main thread may go without serving before the work is dropped

_PENDING, _TAKEN, _ABANDONED = "pending", "taken", "abandoned"


class Abandoned(RuntimeError):
    """The main thread did not do the work (see STALL_LIMIT, stop())."""


class _Call:
    def __init__(self, function, args):
        self.function, self.args = function, args
        self.state = _PENDING
        self.asked = time.monotonic()
        self.result = self.error = None
        self.done = threading.Event()


def on_main_thread():
    return threading.current_thread() is threading.main_thread()


class Handover:
    """The queue between the render thread and the main thread's timer (session.py holds the
    add-on's one)."""

    def __init__(self):
        self._lock = threading.Lock()  # guards the fields below and every call's state
        self._queue = []
        self._last_served = 0.0  # time.monotonic() of the main thread's last serve()
        self._closed = True      # no timer serves: before start(), after stop()

    def call(self, function, *args):
        """function(*args) on the main thread; returns its result or raises its exception. On
        the main thread itself (a blocking render from a script) it is called at once."""
        if on_main_thread():
            return function(*args)
        work = _Call(function, args)
        with self._lock:
            if self._closed:
                raise Abandoned("the add-on's main-thread timer is not running")
            self._queue.append(work)
        while not work.done.wait(0.1):  # releases the GIL while it waits
            with self._lock:
                if work.state != _PENDING:
                    continue  # taken: the main thread is doing it now
                silent = time.monotonic() - max(self._last_served, work.asked)
                if silent <= STALL_LIMIT and not self._closed:
                    continue
                work.state = _ABANDONED
                self._queue.remove(work)
            raise Abandoned(f"Blender's main thread did not answer for {silent:.0f} s"
                            if silent > STALL_LIMIT else "the add-on was disabled")
        if work.error is not None:
            raise work.error
        return work.result

    def pending(self):
        """True when work waits for serve()."""
        with self._lock:
            return bool(self._queue)

    def serve(self):
        """Main thread: does every queued piece of work, in the order asked."""
        with self._lock:
            self._last_served = time.monotonic()
            taken = list(self._queue)
            self._queue.clear()
            for work in taken:
                work.state = _TAKEN
        for work in taken:
            try:
                work.result = work.function(*work.args)
            except Exception as error:  # handed to the waiting thread
                work.error = error
            finally:
                work.done.set()

    def start(self):
        """register(): the timer serves from now on."""
        with self._lock:
            self._closed = False
            self._last_served = time.monotonic()

    def stop(self):
        """unregister(): no timer serves any more; queued work is abandoned, waiting threads
        go."""
        with self._lock:
            self._closed = True
            for work in self._queue:
                work.state = _ABANDONED
                work.error = Abandoned("the add-on was disabled")
                work.done.set()
            self._queue.clear()
