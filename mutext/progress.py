"""A progress line on stderr for long library steps (the library reports through a callback)."""
from __future__ import annotations

import sys
import time


class ProgressLine:
    """Callable ``(stage, fraction)``: one updating line on a terminal, a line per stage otherwise.

    It is also a writable stream (``write``, ``flush``): pass it as the ``out``
    log of a library call that reports progress too (``identify(..., out=line,
    progress=line)``), and the log's lines appear below the bar instead of
    through it.

    Parameters
    ----------
    stream : file-like, optional
        Where the line is written (default: ``sys.stderr``).
    enabled : bool, optional
        False: the progress calls draw nothing (a ``--quiet`` run); log text passed to
        :meth:`write` is still written.
    """

    def __init__(self, stream=None, enabled: bool = True):
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.t0 = time.perf_counter()
        self.last = None
        self.last_tenth = -1
        self.bar_shown = False      # an unfinished bar is on the terminal's current line

    def write(self, text: str):
        """Write log text, clearing the bar first so that the text does not run through it.

        Parameters
        ----------
        text : str
            Text of the log, written below the bar.
        """
        if self.bar_shown:
            self.stream.write("\r" + " " * 110 + "\r")
            self.bar_shown = False
        self.stream.write(text)

    def flush(self):
        self.stream.flush()

    def __call__(self, stage: str, fraction: float):
        if not self.enabled:
            return
        el = time.perf_counter() - self.t0
        width = 24
        bar = "#" * int(round(width * fraction)) + "-" * (width - int(round(width * fraction)))
        line = f"[{bar}] {100 * fraction:3.0f} %  {el:5.1f} s  {stage}"
        if self.tty:
            self.stream.write("\r" + line[:110].ljust(110))
            self.bar_shown = fraction < 1.0
            if fraction >= 1.0:
                self.stream.write("\n")
        else:
            # a log, not a bar: a line when the stage changes, at every further tenth of the work, and at the end
            # (one line per stage alone jumped from the first case of a batch to 100 %)
            head = stage.split(" ")[0]
            tenth = int(10 * fraction + 1e-9)
            if head == self.last and tenth <= self.last_tenth and fraction < 1.0:
                return
            self.last, self.last_tenth = head, tenth
            self.stream.write(line + "\n")
        self.stream.flush()
