"""Files a storyboard names, confined to the storyboard's folder."""

from __future__ import annotations

from pathlib import Path

from facelib.errors import FdlError

__all__ = ["MAX_TEXT_BYTES", "read_text", "resolve_inside"]

MAX_TEXT_BYTES = 1024 * 1024
"""Largest script or transcript file read (1 MiB)."""


def resolve_inside(
    base_dir: Path | None,
    value: object,
    *,
    what: str,
    path: str,
    line: int | None,
    must_exist: bool = True,
) -> Path:
    """Absolute resolved path of ``value`` (relative to ``base_dir``).

    Raises FdlError (naming ``what``, the value, ``path`` and ``line``) when ``value`` is not
    a non-empty string, is absolute, leaves ``base_dir`` (also through ``..`` or symbolic
    links), or, with ``must_exist``, is not an existing file.
    """
    if not isinstance(value, str) or not value.strip():
        raise FdlError(
            f"{what} must be a file name (a string); got {value!r}", path=path, line=line
        )
    if "\0" in value:
        raise FdlError(f"{what} {value!r} contains a NUL character", path=path, line=line)
    if base_dir is None:
        raise FdlError(
            f"{what} names the file {value!r}, but this storyboard has no folder "
            "(pass base_dir= to loads())",
            path=path,
            line=line,
        )
    relative = Path(value)
    if relative.is_absolute() or relative.drive:
        raise FdlError(
            f"{what} {value!r} must be relative to the storyboard's folder", path=path, line=line
        )
    base = base_dir.resolve()
    full = (base / relative).resolve()
    if not full.is_relative_to(base):
        raise FdlError(
            f"{what} {value!r} leaves the storyboard's folder {str(base)!r}", path=path, line=line
        )
    if must_exist and not full.is_file():
        raise FdlError(
            f"{what} {value!r} not found (looked for {str(full)!r})", path=path, line=line
        )
    if not must_exist and full.is_dir():
        raise FdlError(f"{what} {value!r} is a folder, not a file", path=path, line=line)
    return full


def read_text(file: Path, *, what: str, path: str, line: int | None) -> str:
    """Text of ``file`` (UTF-8, at most 1 MiB; a leading BOM is dropped)."""
    try:
        size = file.stat().st_size
        if size > MAX_TEXT_BYTES:
            raise FdlError(
                f"{what} {file.name!r} is larger than {MAX_TEXT_BYTES} bytes", path=path, line=line
            )
        data = file.read_bytes()
    except OSError as exc:
        raise FdlError(
            f"{what} {file.name!r} cannot be read: {exc.strerror}", path=path, line=line
        ) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FdlError(
            f"{what} {file.name!r} is not UTF-8 text (byte {exc.start})", path=path, line=line
        ) from None
