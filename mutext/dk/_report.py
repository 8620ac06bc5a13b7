r"""Printing the iteration tables and the heartbeat of steps that cannot report themselves."""
from __future__ import annotations

import time


def _print(out, text):
    if out is not None:
        print(text, file=out, flush=True)


class _Heartbeat:
    """While a step that cannot report itself runs (the K step's SDP solve), call
    ``progress(stage(elapsed), fraction)`` at its start and about every ``period``
    seconds from a helper thread."""

    def __init__(self, progress, stage, fraction: float, period: float = 1.0):
        self.progress, self.stage, self.fraction, self.period = progress, stage, fraction, period
        self.thread = None

    def __enter__(self):
        if self.progress is None:
            return self
        import threading
        self.t0 = time.perf_counter()
        self.stop = threading.Event()
        self.progress(self.stage(0.0), self.fraction)

        def beat():
            while not self.stop.wait(self.period):
                self.progress(self.stage(time.perf_counter() - self.t0), self.fraction)
        self.thread = threading.Thread(target=beat, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc):
        if self.thread is not None:
            self.stop.set()
            self.thread.join()
        return False
