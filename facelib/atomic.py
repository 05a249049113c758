"""Atomic file output: readers never see a half-written file, and a failure leaves any
previous file as it was."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from facelib.errors import FileError

__all__ = ["atomic_path", "write_text_atomic"]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success rename it onto
    ``path``, on any error remove it. Missing folders are made; the file gets the usual
    permissions (0666 less the umask). An ``OSError`` (no permission, disk full, ...) is
    raised as :class:`~facelib.errors.FileError` naming ``path``.

    >>> with atomic_path("out.mp4") as temp:   # doctest: +SKIP
    ...     encode_video(temp)
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.",
                                        suffix=path.suffix)
    except OSError as exc:
        raise FileError.wrap(exc, "write", path) from exc
    os.close(handle)
    temp = Path(name)
    umask = os.umask(0)
    os.umask(umask)
    temp.chmod(0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
    try:
        yield temp
        temp.replace(path)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        if isinstance(exc, FileError):
            raise
        raise FileError.wrap(exc, "write", path) from exc
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically."""
    with atomic_path(path) as temp:
        temp.write_text(text, encoding="utf-8", newline="\n")
