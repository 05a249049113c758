"""Atomic file output: readers never see a half-written file, and a failure leaves any
previous file as it was.

The temporary file is written beside the target as
``.facelib-tmp-<pid>-<token>-<check><suffix>``: a fixed prefix, the writing process's id, 12
random hex digits and 8 hex digits of a keyed hash of the pid and token. A temporary left by
a process that no longer runs (killed with SIGKILL, say) is removed by the next write to the
same folder; the sweep removes only regular files of this user whose whole name has this
shape and whose check matches, so no file a user made (``.photo.2019.holidays.jpg``) is ever
touched, whatever numbers its name holds. Only regular files are ever replaced: a device,
pipe, folder or symbolic link at the target is refused, so ``-o /dev/null`` can never turn a
device into a file.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

from facelib.errors import FileError

__all__ = [
    "atomic_path",
    "check_output_path",
    "is_temporary",
    "output_folder",
    "publish",
    "temp_beside",
    "write_text_atomic",
]

_PREFIX = ".facelib-tmp-"
_TEMP = re.compile(r"\.facelib-tmp-(?P<pid>[1-9][0-9]{0,9})-(?P<token>[0-9a-f]{12})"
                   r"-(?P<check>[0-9a-f]{8})(?:\.[A-Za-z0-9]{1,16})?")
_MAX_PID = 2**31 - 1  # pid_t; a larger number in a name is never a process of ours
_KEY = b"facelib atomic temporary v1"


def _check(pid: int, token: str) -> str:
    """The 8 hex digits that mark a temporary name as facelib's own."""
    return hashlib.blake2s(f"{pid}-{token}".encode(), key=_KEY, digest_size=4).hexdigest()


def _temp_name(suffix: str) -> str:
    pid = os.getpid()
    token = secrets.token_hex(6)
    return f"{_PREFIX}{pid}-{token}-{_check(pid, token)}{suffix}"


def is_temporary(name: str) -> bool:
    """Whether ``name`` (a file name, no folder) is one facelib's writers made: the prefix,
    a pid that fits ``pid_t``, the token and its matching check, an optional short suffix."""
    match = _TEMP.fullmatch(name)
    if match is None or int(match["pid"]) > _MAX_PID:
        return False
    return secrets.compare_digest(match["check"], _check(int(match["pid"]), match["token"]))


def check_output_path(path: str | os.PathLike[str]) -> Path:
    """``path`` as a Path, if a file may be written there; FileError naming it if it is
    empty, an existing folder, device, pipe or symbolic link, or in a parent that is a file."""
    text = os.fspath(path)
    if not str(text).strip():
        raise FileError("the output path is empty")
    target = Path(text)
    try:
        info = target.lstat()
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise FileError.wrap(exc, "write", target) from exc
    if info is not None and not stat.S_ISREG(info.st_mode):
        kind = ("a folder" if stat.S_ISDIR(info.st_mode) else "a symbolic link"
                if stat.S_ISLNK(info.st_mode) else "a device or pipe")
        raise FileError(f"will not replace it: it is {kind}, not a file", path=target)
    return target


def output_folder(path: str | os.PathLike[str]) -> Path:
    """The folder ``path``, created with its parents if missing; FileError naming it if it
    is empty, exists as something other than a folder (a file, a link), or cannot be made
    (a parent is a file, no permission)."""
    text = os.fspath(path)
    if not str(text).strip():
        raise FileError("the output folder is empty")
    folder = Path(text)
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise FileError("exists and is not a folder; give a folder to write into", path=folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileError.wrap(exc, "write", folder) from exc
    return folder


def _sweep(folder: Path) -> None:
    """Remove temporary files of earlier writes whose process has ended."""
    uid = os.getuid() if hasattr(os, "getuid") else None
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if not entry.name.startswith(_PREFIX) or not is_temporary(entry.name):
                continue
            with contextlib.suppress(OSError):
                info = entry.stat(follow_symlinks=False)
                if not stat.S_ISREG(info.st_mode) or (uid is not None and info.st_uid != uid):
                    continue
                if not _alive(int(entry.name[len(_PREFIX):].split("-", 1)[0])):
                    Path(entry.path).unlink()


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True
    return True


def temp_beside(path: str | os.PathLike[str], *, suffix: str | None = None) -> Path:
    """A new empty temporary file beside ``path`` (its folder created), named so that a later
    write can sweep it if this process dies; ``suffix`` defaults to ``path``'s.

    Raises FileError if ``path`` is not a place a file may be written
    (:func:`check_output_path`) or the folder cannot be written.
    """
    path = check_output_path(path)
    ending = path.suffix if suffix is None else suffix
    if not re.fullmatch(r"(\.[A-Za-z0-9]{1,16})?", ending):
        ending = ""  # the sweep must recognise every name made here
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _sweep(path.parent)
        while True:
            temp = path.parent / _temp_name(ending)
            try:
                handle = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            except FileExistsError:
                continue
            break
    except OSError as exc:
        raise FileError.wrap(exc, "write", Path(path)) from exc
    os.close(handle)
    return temp


def publish(temp: Path, path: str | os.PathLike[str]) -> Path:
    """Give ``temp`` the permissions of a normally created file and rename it onto ``path``."""
    umask = os.umask(0)
    os.umask(umask)
    temp.chmod(0o666 & ~umask)  # mkstemp makes 0600
    target = check_output_path(path)
    temp.replace(target)
    return target


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success rename it onto
    ``path``, on any error (KeyboardInterrupt included) remove it. The file gets the usual
    permissions (0666 less the umask).

    Raises FileError naming ``path`` if it is not a place a file may be written
    (:func:`check_output_path`), its folder cannot be created, or writing fails with an
    ``OSError`` (no permission, disk full, ...).

    >>> with atomic_path("out.mp4") as temp:   # doctest: +SKIP
    ...     encode_video(temp)
    """
    temp = temp_beside(path)
    try:
        yield temp
        publish(temp, path)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        if isinstance(exc, FileError):
            raise
        raise FileError.wrap(exc, "write", Path(path)) from exc
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically (see
    :func:`atomic_path` for the errors)."""
    with atomic_path(path) as temp:
        temp.write_text(text, encoding="utf-8", newline="\n")
