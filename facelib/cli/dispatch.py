"""The ``facelib`` parser and what runs a command: the subcommands in the order ``--help``
lists them, the stopping signals (SIGINT raises KeyboardInterrupt, SIGTERM
:class:`~facelib.cli.console.Terminated`, so ``finally`` blocks and atomic writers clean up),
a closed stdout, and the one line an error, an interruption or a warning prints.

A new subcommand is one module with ``add(commands)``, which declares its arguments and sets
``run`` to the function doing the work, plus one entry in :data:`COMMANDS`.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import traceback
from collections.abc import Callable, Iterator, Sequence
from types import ModuleType

import facelib
from facelib.cli import (
    align,
    check,
    dataset,
    evaluate,
    export,
    face,
    import_arkit,
    info,
    listing,
    plot,
    render,
    serve,
    track,
    view,
)
from facelib.cli import run as run_command
from facelib.cli.console import (
    EXIT_ERROR,
    EXIT_INTERRUPTED,
    EXIT_PIPE,
    EXIT_TERMINATED,
    EXIT_USAGE,
    Console,
    Signals,
    Terminated,
    UsageError,
)
from facelib.cli.options import COMMON
from facelib.errors import FacelibError, facelib_warnings

# The subcommands, each a module with ``add(commands)``, in the order ``--help`` lists them.
COMMANDS: tuple[ModuleType, ...] = (
    info, check, run_command, render, view, plot, align, listing, dataset, evaluate, track, export,
    import_arkit, face, serve,
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="facelib", description="Scriptable MPEG-4 facial animation.", parents=[COMMON],
        epilog="exit status: 0 ok, 1 error, 2 usage, 130 Ctrl-C, 141 closed pipe, "
               "143 SIGTERM",
    )
    parser.add_argument("--version", action="version", version=f"facelib {facelib.__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for command in COMMANDS:
        command.add(commands)
    return parser


@contextlib.contextmanager
def _stopping_signals(signals: Signals) -> Iterator[None]:
    """While inside, SIGINT raises KeyboardInterrupt and SIGTERM :class:`Terminated`, and
    ``signals`` remembers which came (main thread only)."""
    def stop(signum: int, frame: object) -> None:
        signals.received = signum
        signals.check()

    try:
        previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread: leave signals alone
        yield
        return
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _stdout_gone() -> int:
    """The reader of stdout went away: point stdout at /dev/null so the interpreter's
    final flush does not fail again, and end quietly."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    return EXIT_PIPE


def _stopped(signum: int) -> int:
    """One line and the exit status for a command stopped by ``signum``."""
    if signum == signal.SIGINT:
        print("facelib: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    print("facelib: terminated", file=sys.stderr)
    return EXIT_TERMINATED


def dispatch(run: Callable[[argparse.Namespace, Console], int], args: argparse.Namespace,
              console: Console) -> int:
    try:
        with _stopping_signals(console.signals):
            status = run(args, console)
            console.signals.check()  # a signal whose exception was swallowed on the way
            return status
    except BrokenPipeError:
        return _stdout_gone()
    except KeyboardInterrupt:
        return _stopped(signal.SIGINT)
    except Terminated:
        return _stopped(signal.SIGTERM)
    except Exception as exc:
        if console.signals.received is not None:  # a library turned the signal into an error
            return _stopped(console.signals.received)  # (ctypes: into an ArgumentError)
        if not isinstance(exc, FacelibError):
            raise
        if console.verbose:
            traceback.print_exc()
        print(f"facelib: error: {exc}", file=sys.stderr)
        return EXIT_USAGE if isinstance(exc, UsageError) else EXIT_ERROR


def _axis_values_joined(argv: Sequence[str]) -> list[str]:
    """``argv`` with ``--up -y`` written ``--up=-y`` (and ``--forward`` alike): argparse
    takes a value starting with '-' for an option of its own and refuses the documented
    spelling otherwise."""
    out: list[str] = []
    for item in argv:
        if out and out[-1] in ("--up", "--forward") and item in ("-x", "-y", "-z"):
            out[-1] = f"{out[-1]}={item}"
        else:
            out.append(item)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (see :mod:`facelib.cli.console`)."""
    parser = build_parser()
    args = parser.parse_args(_axis_values_joined(sys.argv[1:] if argv is None else argv))
    run: Callable[[argparse.Namespace, Console], int] | None = getattr(args, "run", None)
    if run is None:
        parser.print_help()
        return EXIT_USAGE
    console = Console(quiet=getattr(args, "quiet", False), verbose=getattr(args, "verbose", False))
    if console.verbose:
        logging.basicConfig(level=logging.INFO, format="facelib: %(name)s: %(message)s")
    with facelib_warnings() as caught:
        status = dispatch(run, args, console)
    for warning in caught:
        if not console.quiet:
            print(f"facelib: warning: {warning.message}", file=sys.stderr)
    return status

