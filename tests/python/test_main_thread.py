#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""blender_addon/main_thread.py without Blender: work asked for from another thread (Blender's
render thread) is done by the thread that calls serve() (the main thread's timer), and the
asking thread never goes on before it is done, nor waits for ever.

    /usr/bin/python3 tests/python/test_main_thread.py
"""
import os
import sys
import threading
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "blender_addon"))
import main_thread  # noqa: E402


class Asker(threading.Thread):
    """A render thread: handover.call(function, *args), keeping the outcome."""

    def __init__(self, handover, function, *args):
        super().__init__(daemon=True)
        self.handover, self.function, self.args = handover, function, args
        self.result = self.error = None
        self.ended_at = None

    def run(self):
        try:
            self.result = self.handover.call(self.function, *self.args)
        except Exception as error:
            self.error = error
        self.ended_at = time.monotonic()


def serve_until(handover, condition, seconds=10.0):
    """The main thread's timer: serve() every 10 ms until condition() or the time is up."""
    end = time.monotonic() + seconds
    while not condition() and time.monotonic() < end:
        handover.serve()
        time.sleep(0.01)


class MainThreadTest(unittest.TestCase):
    def setUp(self):
        self.handover = main_thread.Handover()
        self.handover.start()
        self.stall_limit = main_thread.STALL_LIMIT

    def tearDown(self):
        self.handover.stop()
        main_thread.STALL_LIMIT = self.stall_limit

    def test_work_runs_on_the_serving_thread_and_its_result_comes_back(self):
        ran_on = []
        asker = Asker(self.handover,
                      lambda a, b: ran_on.append(threading.current_thread()) or a + b, 2, 3)
        asker.start()
        serve_until(self.handover, lambda: asker.ended_at is not None)
        asker.join(5)
        self.assertEqual(asker.result, 5)
        self.assertIsNone(asker.error)
        self.assertEqual(ran_on, [threading.main_thread()])

    def test_the_asker_waits_until_the_work_is_done(self):
        finished = []

        def slow():
            time.sleep(0.3)
            finished.append(time.monotonic())

        asker = Asker(self.handover, slow)
        asker.start()
        time.sleep(0.2)  # nobody serves yet: the asker must still wait
        self.assertTrue(asker.is_alive())
        serve_until(self.handover, lambda: asker.ended_at is not None)
        asker.join(5)
        self.assertEqual(len(finished), 1)
        self.assertGreaterEqual(asker.ended_at, finished[0])

    def test_an_exception_reaches_the_asker(self):
        def failing():
            raise ValueError("cannot save")

        asker = Asker(self.handover, failing)
        asker.start()
        serve_until(self.handover, lambda: asker.ended_at is not None)
        asker.join(5)
        self.assertIsInstance(asker.error, ValueError)
        self.assertEqual(str(asker.error), "cannot save")

    def test_on_the_main_thread_the_work_is_done_at_once(self):
        # A blocking render from a script runs its handlers on the main thread: waiting for
        # the timer there would wait for itself.
        self.assertEqual(self.handover.call(lambda: threading.current_thread()),
                         threading.main_thread())
        self.assertFalse(self.handover.pending())

    def test_a_silent_main_thread_abandons_the_work_which_then_never_runs(self):
        main_thread.STALL_LIMIT = 0.3
        ran = []
        asker = Asker(self.handover, lambda: ran.append(1))
        start = time.monotonic()
        asker.start()
        asker.join(5)
        self.assertIsInstance(asker.error, main_thread.Abandoned)
        self.assertIn("did not answer", str(asker.error))
        self.assertGreaterEqual(asker.ended_at - start, 0.3)
        self.assertLess(asker.ended_at - start, 2.0)
        self.handover.serve()  # late: the frame it was for is gone
        self.assertEqual(ran, [])
        self.assertFalse(self.handover.pending())

    def test_work_being_done_is_waited_for_past_the_stall_limit(self):
        main_thread.STALL_LIMIT = 0.2
        asker = Asker(self.handover, time.sleep, 0.6)  # longer than the limit, but taken at once
        asker.start()
        serve_until(self.handover, lambda: asker.ended_at is not None)
        asker.join(5)
        self.assertIsNone(asker.error)

    def test_stop_releases_a_waiting_asker_and_refuses_new_work(self):
        ran = []
        asker = Asker(self.handover, lambda: ran.append(1))
        asker.start()
        time.sleep(0.2)
        self.handover.stop()  # the add-on disabled during the render
        asker.join(5)
        self.assertFalse(asker.is_alive())
        self.assertIsInstance(asker.error, main_thread.Abandoned)
        late = Asker(self.handover, lambda: ran.append(2))
        late.start()
        late.join(5)
        self.assertIsInstance(late.error, main_thread.Abandoned)
        self.handover.serve()
        self.assertEqual(ran, [])

    def test_many_askers_each_get_their_own_result(self):
        askers = [Asker(self.handover, lambda i=i: i * i) for i in range(50)]
        for asker in askers:
            asker.start()
        serve_until(self.handover, lambda: all(a.ended_at is not None for a in askers))
        for i, asker in enumerate(askers):
            asker.join(5)
            self.assertEqual(asker.result, i * i)


if __name__ == "__main__":
    unittest.main(verbosity=2)
