"""The one exception tree of facelib.

Every error facelib raises on purpose is a :class:`FacelibError`. Subclasses say which
kind of input was wrong; each message names the offending value and, where there is one,
the file and line it came from. Every warning is a :class:`FacelibWarning`;
:func:`facelib_warnings` collects them and nothing else, for a program that shows its users
facelib's warnings only.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from pathlib import Path

__all__ = [
    "ArkitFormatError",
    "DataError",
    "FaceModelError",
    "FacelibError",
    "FacelibWarning",
    "FapFormatError",
    "FdlError",
    "FdlWarning",
    "FileError",
    "MissingExtraError",
    "ParameterError",
    "RenderError",
    "SpeechError",
    "SpeechWarning",
    "TrackingError",
    "TrackingWarning",
    "facelib_warnings",
]


class FacelibError(Exception):
    """Base class of every error facelib raises on purpose.

    Parameters
    ----------
    message:
        What is wrong, naming the offending value.
    path:
        The file the problem is in, if any.
    line:
        The 1-based line number in ``path``, if known.
    """

    def __init__(self, message: str, *, path: str | Path | None = None, line: int | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        self.line = line
        super().__init__(self._format())

    def _format(self) -> str:
        if self.path is None:
            return self.message
        where = self.path if self.line is None else f"{self.path}:{self.line}"
        return f"{where}: {self.message}"


class ParameterError(FacelibError, ValueError):
    """A value passed to a facelib function is out of range or of the wrong kind."""


class DataError(FacelibError):
    """A data file (package data or a user's rules file) is missing or malformed."""


class FapFormatError(FacelibError):
    """A ``.fap`` file (or FAP data) cannot be read or is malformed."""


class ArkitFormatError(FacelibError):
    """An ARKit capture (Live Link Face CSV) or ARKit JSON file cannot be read."""


class FdlError(FacelibError):
    """An ``.fdl`` storyboard or script failed: syntax, runtime, sandbox limits, bad values."""


class FaceModelError(FacelibError):
    """A face definition (mesh, feature points, regions, pivots) is missing or inconsistent."""


class SpeechError(FacelibError):
    """Speech audio or transcript cannot be used (unreadable, silent, implausible alignment)."""


class RenderError(FacelibError):
    """Rendering or video encoding failed (no OpenGL platform, encoder error, ...)."""


class TrackingError(FacelibError):
    """A video or landmark track cannot be turned into FAPs (no face, unreadable video,
    wrong point count, missing feature points); the message names the frames."""
class FileError(FacelibError, OSError):
    """A file or folder could not be read or written: the operating system's error
    (``OSError``, kept as ``__cause__``) with the path it concerns."""

    @classmethod
    def wrap(cls, exc: OSError, what: str, path: str | Path) -> FileError:
        """``FileError`` for ``exc`` raised while doing ``what`` ("write", "read") at
        ``path``."""
        reason = exc.strerror or str(exc)
        return cls(f"cannot {what}: {reason}", path=path)


class MissingExtraError(FacelibError, ImportError):
    """An optional dependency is needed for this feature but is not installed."""

    def __init__(self, feature: str, extra: str, module: str):
        super().__init__(
            f"{feature} needs the '{module}' package, which is not installed; "
            f"install it with: pip install 'facelib[{extra}]'"
        )


class FacelibWarning(UserWarning):
    """Something was accepted but looked irregular (e.g. frames missing from a ``.fap``)."""


class FdlWarning(FacelibWarning):
    """A storyboard ran but something in it looks like a mistake (a global that is no
    setting but close to one, ``fsp = 30``), named with its file and line."""


class SpeechWarning(FacelibWarning):
    """An alignment succeeded but looks implausible (named word, reason)."""


class PronunciationWarning(SpeechWarning):
    """Words could not be pronounced as written (not in the dictionary: guessed from their
    spelling); the message names every one."""


class TrackingWarning(FacelibWarning):
    """Tracking went on but lost the face in some frames, or saw several faces (names them)."""


@contextlib.contextmanager
def facelib_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """Collect facelib's warnings raised inside the block; drop every other warning.

    Yields a list that, when the block ends (normally or by an exception), holds each
    :class:`FacelibWarning` raised inside, every time it was raised (not once per place),
    in order; the others (numpy's ``RuntimeWarning``, a third party's deprecation) are
    neither shown nor kept. Filters that turn a warning into an error still apply. The
    ``facelib`` command prints the collected ones as ``facelib: warning: MESSAGE``.

    >>> with facelib_warnings() as caught:
    ...     warnings.warn("frames missing", FacelibWarning)
    ...     warnings.warn("overflow", RuntimeWarning)
    >>> [str(w.message) for w in caught]
    ['frames missing']
    """
    kept: list[warnings.WarningMessage] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FacelibWarning)
        try:
            yield kept
        finally:
            kept.extend(w for w in caught if issubclass(w.category, FacelibWarning))
