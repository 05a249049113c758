"""Where a command's product goes: a file (written atomically, its suffix checked against
the format) or stdout for ``-``, and the default name when ``-o`` is left out."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from facelib.cli.console import Console, UsageError

STDOUT = "-"
RENDER_SUFFIXES = (".mp4", ".gif", ".png")


def check_suffix(out: str, allowed: Sequence[str], what: str) -> None:
    """Refuse an output whose suffix does not match the format the command writes."""
    if out == STDOUT:
        return
    suffix = Path(out).suffix.lower()
    if suffix not in allowed:
        raise UsageError(
            f"{what} writes {' or '.join(allowed)}, not {Path(out).name!r}: "
            f"name the output {Path(out).with_suffix(allowed[0]).name!r} or '-' for stdout"
        )


def emit_text(text: str, out: str, console: Console, summary: str) -> None:
    """Write ``text`` to the file ``out`` (atomically) or to stdout for ``-``."""
    if out == STDOUT:
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    from facelib.atomic import write_text_atomic

    write_text_atomic(out, text)
    console.status(f"wrote {out} {summary}".rstrip())


def default_output(story: str, storyboard_output: Path | None, suffix: str) -> Path:
    """Where a storyboard's product goes without ``-o``: its ``output`` (the loader resolved
    it inside the storyboard's folder, like every file a storyboard names), else
    ``STEM{suffix}`` in the current directory."""
    if storyboard_output is None:
        return Path.cwd() / (Path(story).stem + suffix)
    return storyboard_output

