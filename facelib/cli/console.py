"""What every ``facelib`` command shares at run time: the exit codes, the console (data to
stdout, status and progress to stderr) and the stopping signals it watches for.

Exit codes (also in ``docs/getting-started.md``): 0 success; 1 an input or a job failed
(the message names file, line or clip); 2 usage error; 130 interrupted (Ctrl-C); 141 the
reader of stdout went away (``| head``); 143 terminated (SIGTERM).
"""

from __future__ import annotations

import signal
import sys
from dataclasses import dataclass, field

from facelib.errors import FacelibError
from facelib.progress import ConsoleProgress, ProgressCallback

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT
EXIT_PIPE = 141  # 128 + SIGPIPE
EXIT_TERMINATED = 143  # 128 + SIGTERM


class Terminated(BaseException):
    """Raised in the main thread when SIGTERM arrives, so ``finally`` blocks and atomic
    writers clean up exactly as for Ctrl-C."""


class UsageError(FacelibError):
    """A command line that cannot work (wrong suffix, missing output): exit status 2."""


@dataclass
class Signals:
    """The stopping signal a command received (SIGINT or SIGTERM), or None."""

    received: int | None = None

    def check(self) -> None:
        """Raise KeyboardInterrupt (SIGINT) or :class:`Terminated` once one was received."""
        if self.received == signal.SIGINT:
            raise KeyboardInterrupt
        if self.received is not None:
            raise Terminated


@dataclass(frozen=True)
class Console:
    """Where a command's messages go: data to stdout, status and progress to stderr.

    quiet: only errors; verbose: also log messages (``facelib.*`` loggers) and tracebacks.
    signals: the Ctrl-C / SIGTERM received, checked again at every progress step.
    """

    quiet: bool = False
    verbose: bool = False
    signals: Signals = field(default_factory=Signals)

    def status(self, message: str) -> None:
        if not self.quiet:
            print(message, file=sys.stderr, flush=True)

    def progress(self, label: str, *, unit: str = "frames", show: bool = True,
                 ) -> ProgressCallback:
        """A progress callback (silent with ``quiet``) that also stops the job at its next
        step once a signal came, should the signal's exception have been swallowed where
        it landed (a destructor, a callback from C)."""
        bar = None if self.quiet or not show else ConsoleProgress(label, unit=unit)

        def report(done: int, total: int) -> None:
            self.signals.check()
            if bar is not None:
                bar(done, total)

        return report

