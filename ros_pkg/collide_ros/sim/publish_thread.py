"""The thread that writes and sends the stepping loop's publish rounds while the loop takes the next step.

C's step releases the GIL (cffi), so a round's CDR writing and its hand-over to DDS run beside the
physics of the next step instead of after it: the loop's period is bounded by the larger of the two,
not by their sum. One round at a time: ``submit`` waits for the previous round to be sent (so the rounds
go out in step order and the buffers a round reads are free again), and every other publish of the
state topics (a reset, ~/step, a new body set) waits for the pending round first (``wait_idle``)."""
from __future__ import annotations

import threading
import time
from collections.abc import Callable


class PublishThread:
    """Runs submitted rounds (callables) one after another on a daemon thread. ``on_error`` gets what a
    round raised (the thread goes on with the next round)."""

    def __init__(self, on_error: Callable[[Exception], None]) -> None:
        self._on_error = on_error
        self._cv = threading.Condition()
        self._job: Callable[[], None] | None = None  # the round submitted and not yet sent
        self._stop = False
        self._busy = 0.0  # s spent in rounds since the last take_busy_time
        self._thread = threading.Thread(target=self._run, name="sim-publish", daemon=True)
        self._thread.start()

    def submit(self, job: Callable[[], None]) -> None:
        """Hand a round over, after the previous one was sent."""
        with self._cv:
            while self._job is not None:
                self._cv.wait()
            self._job = job
            self._cv.notify_all()

    def wait_idle(self) -> None:
        """Return once the submitted round (if any) was sent."""
        with self._cv:
            while self._job is not None:
                self._cv.wait()

    def take_busy_time(self) -> float:
        """Seconds spent sending rounds since the last call."""
        with self._cv:
            busy, self._busy = self._busy, 0.0
        return busy

    def stop(self, timeout: float = 2.0) -> None:
        """Send the pending round, then end the thread."""
        self.wait_idle()
        with self._cv:
            self._stop = True
            self._cv.notify_all()
        self._thread.join(timeout)

    def _run(self) -> None:
        while True:
            with self._cv:
                while self._job is None and not self._stop:
                    self._cv.wait()
                if self._job is None:
                    return
                job = self._job
            t0 = time.perf_counter()
            try:
                job()
            except Exception as exc:  # a round must not end the thread: the loop would wait forever
                self._on_error(exc)
            with self._cv:
                self._busy += time.perf_counter() - t0
                self._job = None
                self._cv.notify_all()
