"""Rendering many storyboards (or ``.fap`` files) at once, on a pool of processes.

Each source is rendered in its own worker process (OpenGL contexts are per process) to
``OUT_DIR/STEM.mp4`` (or ``.gif``); a failure in one source is reported in its
:class:`BatchResult` and the others finish. Outputs are written atomically, so a batch
that is interrupted leaves finished files and no partial ones.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from facelib.atomic import output_folder
from facelib.checks import check_count
from facelib.errors import FacelibError, ParameterError
from facelib.progress import ProgressCallback, progress_callback

T = TypeVar("T")
R = TypeVar("R")

__all__ = ["BatchResult", "RenderJob", "default_jobs", "render_batch", "render_job", "spawn_map"]

BATCH_SUFFIXES = (".mp4", ".gif")


@dataclass(frozen=True, slots=True)
class RenderJob:
    """One source to render: everything a worker process needs (picklable)."""

    source: str
    output: str
    width: int = 640
    height: int = 480
    fps: float | None = None
    seed: int | None = None
    face: str | None = None
    hair: str | None = None


@dataclass(frozen=True, slots=True)
class BatchResult:
    """The outcome of one source: ``output`` written in ``seconds``, or ``error`` (the
    message of the :class:`FacelibError`, or the type and message of anything else)."""

    source: str
    output: Path | None
    seconds: float
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


def default_jobs() -> int:
    """Worker processes by default: the CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def render_job(job: RenderJob) -> BatchResult:
    """Render one :class:`RenderJob` in this process; errors become the result's ``error``."""
    from facelib.animation import run_fdl
    from facelib.clip import face_for
    from facelib.mpeg4 import read_fap
    from facelib.rendering.frames import render

    started = time.perf_counter()
    try:
        source = (read_fap(job.source) if Path(job.source).suffix.lower() == ".fap"
                  else run_fdl(job.source, seed=job.seed))
        out = render(source, face=face_for(source, job.face, job.hair), out=job.output,
                     width=job.width, height=job.height, fps=job.fps, progress=False)
    except FacelibError as exc:
        return BatchResult(job.source, None, time.perf_counter() - started, str(exc))
    except Exception as exc:  # a bug or an environment failure: report it, keep going  # noqa: BLE001
        return BatchResult(job.source, None, time.perf_counter() - started,
                           f"{type(exc).__name__}: {exc}")
    assert isinstance(out, Path), "render with out= returns the path written"
    return BatchResult(job.source, out, time.perf_counter() - started)


def _raise_on_sigterm() -> None:
    """Pool initializer: SIGTERM (sent by ``Pool.terminate``) raises SystemExit in the
    worker, so atomic writers remove their temporary files before it exits."""
    def stop(signum: int, frame: object) -> None:
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, stop)


def plan_jobs(
    sources: Sequence[str | os.PathLike[str]], out_dir: str | os.PathLike[str], *,
    suffix: str = ".mp4", width: int = 640, height: int = 480, fps: float | None = None,
    seed: int | None = None, face: str | os.PathLike[str] | None = None,
    hair: str | None = None,
) -> list[RenderJob]:
    """One :class:`RenderJob` per source, writing ``out_dir/STEM{suffix}``; refuses two
    sources with the same stem (they would overwrite each other)."""
    if suffix not in BATCH_SUFFIXES:
        raise ParameterError(f"a batch writes {' or '.join(BATCH_SUFFIXES)}, not {suffix!r}")
    folder = Path(out_dir)
    seen: dict[str, str] = {}
    jobs = []
    for source in sources:
        stem = Path(source).stem
        if stem in seen:
            raise ParameterError(f"{seen[stem]!r} and {str(source)!r} would both write "
                                 f"{stem}{suffix}: rename one or render them separately")
        seen[stem] = str(source)
        jobs.append(RenderJob(str(source), str(folder / f"{stem}{suffix}"), width, height,
                              fps, seed, None if face is None else str(face), hair))
    return jobs


def render_batch(
    sources: Sequence[str | os.PathLike[str]],
    out_dir: str | os.PathLike[str],
    *,
    jobs: int | None = None,
    suffix: str = ".mp4",
    width: int = 640,
    height: int = 480,
    fps: float | None = None,
    seed: int | None = None,
    face: str | os.PathLike[str] | None = None,
    hair: str | None = None,
    progress: bool | ProgressCallback | None = None,
) -> tuple[BatchResult, ...]:
    """Render every source (``.fdl`` or ``.fap``) to ``out_dir/STEM{suffix}`` with ``jobs``
    worker processes (default :func:`default_jobs`, never more than there are sources).

    Returns one :class:`BatchResult` per source, in the order given. ``progress`` is called
    as ``progress(sources_done, n_sources)``. Workers are fresh (spawned) processes, so the
    caller's OpenGL state never leaks into them; Ctrl-C or SIGTERM stops them all, and
    their atomic writers leave no partial files. ``face`` and ``hair`` as
    :func:`facelib.clip.face_for` takes them (``hair``: every source's face wears it).
    """
    planned = plan_jobs(sources, out_dir, suffix=suffix, width=width, height=height,
                        fps=fps, seed=seed, face=face, hair=hair)
    n_jobs = default_jobs() if jobs is None else check_count("jobs", jobs, low=1)
    n_jobs = min(n_jobs, max(len(planned), 1))
    output_folder(out_dir)
    report = progress_callback(progress, "batch", unit="files")
    done = spawn_map(_indexed, list(enumerate(planned)), jobs=n_jobs, report=report,
                     max_tasks_per_child=8)
    results = dict(done)
    return tuple(results[i] for i in range(len(planned)))


def spawn_map(function: Callable[[T], R], tasks: Sequence[T], *, jobs: int,
              report: ProgressCallback | None = None,
              max_tasks_per_child: int | None = None) -> list[R]:
    """``function`` over ``tasks`` on ``jobs`` spawned worker processes; the results in the
    order they finish. ``report(done, len(tasks))`` follows each one. Ctrl-C, SIGTERM or any
    error terminates the workers, whose SIGTERM raises SystemExit so that their atomic
    writers remove their temporary files."""
    results: list[R] = []
    pool = multiprocessing.get_context("spawn").Pool(
        jobs, initializer=_raise_on_sigterm, maxtasksperchild=max_tasks_per_child)
    try:
        for result in pool.imap_unordered(function, tasks):
            results.append(result)
            if report is not None:
                report(len(results), len(tasks))
        pool.close()
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()
    return results


def _indexed(item: tuple[int, RenderJob]) -> tuple[int, BatchResult]:
    return item[0], render_job(item[1])
