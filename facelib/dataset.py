"""Synthetic face datasets: N seeded clips with labels, locally or on a Dask cluster.

A dataset spec (TOML, see ``docs/batch.md``) gives ranges; clip ``i`` draws its cues from
``numpy.random.default_rng([spec.seed, i])`` and becomes a storyboard (kept as
``clip.fdl``), an animation, rendered frames and labels. The draw depends only on the spec
and ``i``, so a local run and a cluster run write the same bytes, and any subset of clips
can be (re)made in any order.

Layout of ``OUT_DIR``::

    spec.json                the spec's settings (a rerun must use the same)
    spec.toml                the spec file it was read from (when it was)
    index.jsonl              one line per clip: id, seed, frames, its draw (written last)
    clip_000000/
        clip.fdl             the storyboard drawn for the clip (run it with facelib)
        clip.fap             the animation's FAP stream (standard .fap, FAP 1/2 decoded)
        clip.extended.fap    when the clip uses extended FAPs 69-84 (the nose) or FAP 1/2:
                             every FAP (facelib's extended dialect)
        frames/frame_NNNNNN.png, or clip.mp4 (``media``)
        frames.jsonl         per frame: time, expressions, eye behaviour, viseme, head
                             pose, and 2-D pixel positions of every feature point
        meta.json            the clip's draw, camera, image size and fps

Each clip is made in a hidden temporary folder and renamed into place when complete, so
``clip_NNNNNN/`` either is whole or does not exist; a rerun skips the clips that exist.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import tempfile
import time
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from facelib.atomic import output_folder, write_text_atomic
from facelib.checks import check_count, check_number, check_seed
from facelib.errors import FacelibError, ParameterError
from facelib.progress import ProgressCallback, progress_callback

__all__ = ["ClipDraw", "DatasetReport", "DatasetSpec", "draw_clip", "generate", "load_spec",
           "make_clip"]

MEDIA = ("png", "mp4", "none")
CLIP_PATTERN = "clip_{:06d}"
# head pose FAPs 48-50 (pitch, yaw, roll) in angle units of 1e-5 rad
_HEAD_FAPS = (48, 49, 50)
_AU_PER_DEG = math.pi / 180 * 1e5


_DEFAULT_HEAD_DEG = ((-8.0, 8.0), (-15.0, 15.0), (-5.0, 5.0))
"""Pitch, yaw and roll ranges of the head in degrees unless a spec says otherwise."""

@dataclass(frozen=True)
class DatasetSpec:
    """What to generate. Ranges are ``(low, high)`` drawn uniformly.

    clips: number of clips; seed: the dataset's seed; fps; seconds: clip length;
    width, height: image size in pixels; media: ``"png"`` frames, ``"mp4"`` or ``"none"``
    (labels and FAPs only). expressions: names drawn from (default: the whole library);
    expressions_per_clip: ``(min, max)`` cues; intensity: range. behaviours: eye behaviours
    drawn per clip (each with a mode, ``talking`` or ``listening``). head_deg: ranges of the
    head's pitch, yaw, roll offset in degrees. texts: sentences a clip may say (text-only
    speech timed by phone durations); speech_probability: chance that a clip speaks.
    zoom, shift: camera framing: the framed box scaled by ``zoom`` and moved by ``shift``
    times the face's size, horizontally and vertically.
    """

    clips: int
    seed: int = 0
    fps: float = 25.0
    seconds: float = 2.0
    width: int = 256
    height: int = 256
    media: str = "png"
    expressions: tuple[str, ...] = ()
    expressions_per_clip: tuple[int, int] = (1, 2)
    intensity: tuple[float, float] = (0.5, 1.0)
    behaviours: tuple[str, ...] = ("default",)
    head_deg: tuple[tuple[float, float], ...] = _DEFAULT_HEAD_DEG
    texts: tuple[str, ...] = ()
    speech_probability: float = 0.5
    zoom: tuple[float, float] = (0.9, 1.2)
    shift: tuple[float, float] = (-0.05, 0.05)
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        for name, value in (("clips", self.clips), ("width", self.width),
                            ("height", self.height)):
            low, high = _LIMITS[name]
            if check_count(name, value, low=int(low)) > high:
                raise ParameterError(f"{name} must be an integer in [{low:g}, {high:g}], "
                                     f"got {value!r}")
        check_seed(self.seed)
        check_number("fps", self.fps, low=_LIMITS["fps"][0], high=_LIMITS["fps"][1])
        check_number("seconds", self.seconds, low=0, low_open=True, high=_LIMITS["seconds"][1])
        if self.media not in MEDIA:
            raise ParameterError(f"media must be one of {MEDIA}, got {self.media!r}")
        self._check_ranges()
        check_number("speech_probability", self.speech_probability, low=0, high=1)
        if not self.behaviours:
            raise ParameterError("behaviours must name at least one eye behaviour")
        for name, words in (("expressions", self.expressions), ("behaviours", self.behaviours),
                            ("texts", self.texts)):
            _check_words(name, words)

    def _check_ranges(self) -> None:
        """Every ``(low, high)`` field: two numbers, ``low <= high``, inside its limits."""
        counts = self.expressions_per_clip
        if (len(counts) != 2 or not all(isinstance(c, int | np.integer)
                                        and not isinstance(c, bool) for c in counts)):
            raise ParameterError(f"expressions_per_clip must be two integers [min, max], got "
                                 f"{counts!r}")
        for name, pair in (("expressions_per_clip", counts), ("intensity", self.intensity),
                           ("zoom", self.zoom), ("shift", self.shift),
                           *zip(("pitch", "yaw", "roll"), self.head_deg, strict=True)):
            low, high = _LIMITS[name]
            if (len(pair) != 2 or not all(isinstance(v, int | float | np.number)
                                          and not isinstance(v, bool) for v in pair)
                    or not low <= pair[0] <= pair[1] <= high):
                raise ParameterError(f"{name} must be a range [low, high] with {low:g} <= low "
                                     f"<= high <= {high:g}, got {list(pair)!r}")


# The limits of a spec's numbers (inclusive), each with its reason. A count or range
# outside sizes the work by itself: clips = 10^12 or per_clip = [10^9, 10^9] ran for minutes
# before this table.
_LIMITS: dict[str, tuple[float, float]] = {
    "clips": (1, 1_000_000),          # clip folders are numbered with six digits
    "width": (8, 8192),               # the renderer's image size limits
    "height": (8, 8192),
    "fps": (1, 1000),                 # a storyboard's frame rate limits
    "seconds": (0, 3600),             # an hour per clip
    "expressions_per_clip": (0, 100),  # far more cues than a clip can show apart
    "intensity": (0, 1),              # an FDL expression cue's intensity
    "zoom": (0.1, 10),                # the face from a tenth to ten times its framed size
    "shift": (-1, 1),                 # at most the face's size off the centre
    "pitch": (-90, 90),               # head offsets in degrees: a quarter turn
    "yaw": (-90, 90),
    "roll": (-90, 90),
}
_MAX_WORDS = 10_000
"""At most this many names or texts in one list of a spec."""
_MAX_TEXT = 100_000
"""Characters in one name or text (a storyboard's limit for one speech cue's text)."""


def _check_words(name: str, words: Sequence[object]) -> None:
    """``words`` (names or texts) as at most :data:`_MAX_WORDS` strings of at most
    :data:`_MAX_TEXT` characters each."""
    if len(words) > _MAX_WORDS:
        raise ParameterError(f"{name} may hold at most {_MAX_WORDS} entries, got {len(words)}")
    for i, word in enumerate(words):
        if not isinstance(word, str) or not 0 < len(word) <= _MAX_TEXT:
            raise ParameterError(f"{name}[{i}] must be a non-empty text of at most "
                                 f"{_MAX_TEXT} characters, got {word!r:.60}")


def _pair(value: Any, key: str, path: str) -> tuple[float, float]:
    if (not isinstance(value, list) or len(value) != 2
            or not all(isinstance(v, int | float) for v in value)):
        raise FacelibError(f"{key} must be a range [low, high], got {value!r}", path=path)
    return float(value[0]), float(value[1])


_TOP_KEYS = {"clips", "seed", "fps", "seconds", "width", "height", "media"}
_SECTIONS = {
    "expressions": {"names", "per_clip", "intensity"},
    "gaze": {"behaviours"},
    "head": {"pitch_deg", "yaw_deg", "roll_deg"},
    "speech": {"texts", "probability"},
    "camera": {"zoom", "shift"},
}


# (section, key in the TOML) -> (DatasetSpec field, how its value is read)
_RANGE = "range"
_FIELDS: dict[tuple[str, str], tuple[str, str]] = {
    ("expressions", "names"): ("expressions", "names"),
    ("expressions", "per_clip"): ("expressions_per_clip", "counts"),
    ("expressions", "intensity"): ("intensity", _RANGE),
    ("gaze", "behaviours"): ("behaviours", "names"),
    ("speech", "texts"): ("texts", "names"),
    ("speech", "probability"): ("speech_probability", "number"),
    ("camera", "zoom"): ("zoom", _RANGE),
    ("camera", "shift"): ("shift", _RANGE),
}


_MAX_SPEC_BYTES = 1024 * 1024
"""A dataset spec file's size limit (a storyboard's)."""


def _read_toml(path: str | os.PathLike[str]) -> tuple[dict[str, Any], str]:
    where = str(path)
    try:
        with Path(path).open("rb") as file:
            data = file.read(_MAX_SPEC_BYTES + 1)
        if len(data) > _MAX_SPEC_BYTES:
            raise FacelibError(f"a dataset spec is at most {_MAX_SPEC_BYTES} bytes", path=where)
        text = data.decode("utf-8")
        return tomllib.loads(text), text
    except OSError as exc:
        raise FacelibError(f"cannot read the dataset spec ({exc.strerror})", path=where) from None
    except UnicodeDecodeError as exc:
        raise FacelibError(f"not UTF-8 text (byte {exc.start})", path=where) from None
    except tomllib.TOMLDecodeError as exc:
        raise FacelibError(f"not valid TOML: {exc}", path=where) from None


def _check_keys(raw: Mapping[str, Any], where: str) -> None:
    for key, value in raw.items():
        allowed = _SECTIONS.get(key)
        if allowed is None and key not in _TOP_KEYS:
            raise FacelibError(f"unknown setting {key!r}; expected one of "
                               f"{sorted(_TOP_KEYS | set(_SECTIONS))}", path=where)
        if allowed is not None and (not isinstance(value, dict) or set(value) - allowed):
            raise FacelibError(f"[{key}] takes {sorted(allowed)}, got {value!r}", path=where)


def _convert(value: Any, kind: str, name: str, where: str) -> Any:
    if kind == _RANGE:
        return _pair(value, name, where)
    if kind == "counts":
        if not isinstance(value, list) or len(value) != 2:
            raise FacelibError(f"{name} must be [min, max], got {value!r:.80}", path=where)
        return tuple(value)  # checked (integers, limits) by DatasetSpec
    if kind == "names":
        if not isinstance(value, list):
            raise FacelibError(f"{name} must be a list, got {value!r:.80}", path=where)
        return tuple(value)  # checked (texts, lengths) by DatasetSpec
    return value


# DatasetSpec's field names as a spec file spells them, for its error messages
_SPEC_KEYS = {field_name: f"{section}.{key}"
              for (section, key), (field_name, _) in _FIELDS.items()} | {
    "pitch": "head.pitch_deg", "yaw": "head.yaw_deg", "roll": "head.roll_deg"}


def _spec_error(exc: ParameterError, where: str) -> FacelibError:
    """``exc`` from DatasetSpec as a FacelibError naming ``where`` and the field as the spec
    file spells it (``expressions.per_clip``, not ``expressions_per_clip``)."""
    message = exc.message
    for field_name, key in _SPEC_KEYS.items():
        if message.startswith(field_name) and message[len(field_name)] in " [":
            message = key + message[len(field_name):]
            break
    return FacelibError(message, path=where)


def load_spec(path: str | os.PathLike[str]) -> DatasetSpec:
    """Read a dataset spec (TOML, see ``docs/batch.md``); unknown keys and bad values raise
    FacelibError naming the file."""
    where = str(path)
    raw, text = _read_toml(path)
    _check_keys(raw, where)
    options: dict[str, Any] = {k: raw[k] for k in _TOP_KEYS if k in raw}
    for (section, key), (field_name, kind) in _FIELDS.items():
        if key in raw.get(section, {}):
            options[field_name] = _convert(raw[section][key], kind, f"{section}.{key}", where)
    head = raw.get("head", {})
    options["head_deg"] = tuple(
        _pair(head[k], f"head.{k}", where) if k in head else default
        for k, default in zip(("pitch_deg", "yaw_deg", "roll_deg"), _DEFAULT_HEAD_DEG,
                              strict=True))
    try:
        return DatasetSpec(**options, source=text)
    except ParameterError as exc:
        raise _spec_error(exc, where) from None
    except TypeError as exc:
        raise FacelibError(str(exc), path=where) from None


@dataclass(frozen=True)
class ClipDraw:
    """What clip ``index`` shows: its seed (for the gaze and sync processes), expression cues
    ``(name, start_s, duration_s, intensity)``, eye behaviour and mode, the sentence it
    says (or None), head offset ``(pitch, yaw, roll)`` in degrees, camera zoom and shift."""

    index: int
    seed: int
    expressions: tuple[tuple[str, float, float, float], ...]
    behaviour: str
    mode: str
    text: str | None
    head_deg: tuple[float, float, float]
    zoom: float
    shift: tuple[float, float]


def _library_names() -> tuple[str, ...]:
    from facelib.expressions import default_library

    return default_library().names


def draw_clip(spec: DatasetSpec, index: int) -> ClipDraw:
    """The draw of clip ``index``: a pure function of ``spec`` and ``index``."""
    rng = np.random.default_rng([spec.seed, index])
    names = spec.expressions or _library_names()
    n_cues = int(rng.integers(spec.expressions_per_clip[0], spec.expressions_per_clip[1] + 1))
    cues = []
    for _ in range(n_cues):
        start = float(rng.uniform(0, spec.seconds * 0.6))
        duration = float(rng.uniform(0.3, spec.seconds - start)) if start < spec.seconds - 0.3 \
            else spec.seconds - start
        cues.append((str(names[int(rng.integers(len(names)))]), round(start, 3),
                     round(duration, 3), round(float(rng.uniform(*spec.intensity)), 3)))
    cues.sort(key=lambda c: c[1])
    behaviour = str(spec.behaviours[int(rng.integers(len(spec.behaviours)))])
    mode = ("talking", "listening")[int(rng.integers(2))]
    speaks = bool(spec.texts) and float(rng.random()) < spec.speech_probability
    text = str(spec.texts[int(rng.integers(len(spec.texts)))]) if speaks else None
    head = tuple(round(float(rng.uniform(*r)), 3) for r in spec.head_deg)
    zoom = round(float(rng.uniform(*spec.zoom)), 4)
    shift = (round(float(rng.uniform(*spec.shift)), 4), round(float(rng.uniform(*spec.shift)), 4))
    return ClipDraw(index, int(rng.integers(2**31 - 1)), tuple(cues), behaviour, mode, text,
                    (head[0], head[1], head[2]), zoom, shift)


def clip_storyboard(spec: DatasetSpec, draw: ClipDraw) -> str:
    """The FDL text of a clip: settings, the speech, expression and gaze cues. Every name
    and text is a Lua string literal (:func:`facelib.fdl.literals.lua_string`), so a
    hostile name in a spec stays a name."""
    from facelib.fdl.literals import lua_string

    lines = [f"-- clip {draw.index} of a facelib dataset (seed {spec.seed})",
             f"fps = {spec.fps:g}", f"seed = {draw.seed}"]
    if draw.text is not None:
        lines.append(f"say {{ {lua_string(draw.text)}, at = 0 }}")
    for name, start, duration, intensity in draw.expressions:
        lines.append(f"show {{ {lua_string(name)}, at = {start:g}, dur = {duration:g}, "
                     f"intensity = {intensity:g} }}")
    behaviour_args = {"default": f"{lua_string(draw.mode)}, 1.0, "}.get(draw.behaviour, "")
    lines.append(f"look {{ {lua_string(draw.behaviour)}, {behaviour_args}at = 0, "
                 f"dur = {spec.seconds:g} }}")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class DatasetReport:
    """``written`` clips made now, ``skipped`` ones already there, ``failed`` as
    ``(clip index, message)``, and the wall-clock ``seconds`` it took."""

    written: int
    skipped: int
    failed: tuple[tuple[int, str], ...]
    seconds: float


def _with_head(stream: Any, head_deg: Sequence[float]) -> Any:
    """``stream`` with the head pose offset added to FAPs 48-50 in every frame, rounded to
    whole FAP units as ``clip.fap`` stores them, so the frames show exactly that file (and
    last-bit differences of floating point between machines cannot reach the pixels)."""
    from facelib.mpeg4 import FapStream

    values = np.array(stream.values, np.float64)
    mask = np.array(stream.mask)
    for fap_id, degrees in zip(_HEAD_FAPS, head_deg, strict=True):
        values[:, fap_id - 1] += degrees * _AU_PER_DEG
        mask[:, fap_id - 1] = True
    return FapStream(stream.fps, np.rint(values), mask, stream.viseme, stream.expression)


def _framing(face: Any, zoom: float, shift: Sequence[float]) -> np.ndarray:
    """``(8, 3)`` corners of the box the camera frames: the neutral face's box scaled by
    ``1 / zoom`` (zoom > 1 comes closer) and moved by ``shift`` times its size."""
    vertices = np.asarray(face.vertices, np.float64)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo) / 2 / zoom
    centre = centre + np.array([shift[0] * (hi - lo)[0], shift[1] * (hi - lo)[1], 0.0])
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    return centre + signs * half


def _frame_labels(animation: Any, stream: Any) -> list[dict[str, Any]]:
    """Per frame: time, active expression cues with intensity, eye behaviour, viseme and
    head pose in degrees (from the final FAPs 48-50)."""
    storyboard = animation.storyboard
    spans = list(animation.visemes or ())
    head = stream.values[:, [f - 1 for f in _HEAD_FAPS]] / _AU_PER_DEG
    labels = []
    for i in range(stream.n_frames):
        ms = i * 1000 / stream.fps
        labels.append({
            "frame": i,
            "time_s": round(i / stream.fps, 6),
            "expressions": {c.name: c.intensity for c in storyboard.expressions
                            if c.start_ms <= ms < c.end_ms},
            "behaviour": next((g.behaviour for g in storyboard.gaze
                               if g.start_ms <= ms < g.end_ms), None),
            "viseme": next((s.name for s in spans if s.start_ms <= ms < s.end_ms), None),
            "head_deg": [round(float(v), 4) for v in head[i]],
        })
    return labels


def _render_clip(spec: DatasetSpec, draw: ClipDraw, stream: Any, folder: Path,
                 labels: list[dict[str, Any]]) -> None:
    """Render frames (or the mp4) and add each frame's feature-point pixels to ``labels``."""
    from facelib.engine import default_face
    from facelib.rendering.scene import FaceRenderer
    from facelib.rendering.video import open_writer

    face = default_face()
    points = sorted(face.feature_points.items(), key=lambda kv: [int(p) for p in
                                                                 kv[0].split(".")])
    ids = np.array([v for _, v in points])
    out = folder / ("clip.mp4" if spec.media == "mp4" else "frames")
    with FaceRenderer(face, width=spec.width, height=spec.height,
                      framing=_framing(face, draw.zoom, draw.shift)) as renderer:
        writer = None if spec.media == "none" else open_writer(
            out, fps=stream.fps, width=spec.width, height=spec.height)
        try:
            for start in range(0, stream.n_frames, 32):
                vertices = np.asarray(face.deform(stream[start:start + 32]), np.float32)
                for k, frame_vertices in enumerate(vertices):
                    pixels = renderer.project(frame_vertices[ids])
                    labels[start + k]["landmarks"] = {
                        fp: [round(float(x), 3), round(float(y), 3)]
                        for (fp, _), (x, y) in zip(points, pixels, strict=True)}
                    if writer is not None:
                        writer.write(renderer.frame(
                            frame_vertices, faps=stream.values[start + k]))
        except BaseException:
            if writer is not None:
                writer.abort()
            raise
        if writer is not None:
            writer.commit()


def make_clip(spec: DatasetSpec, index: int, out_dir: str | os.PathLike[str]) -> str:
    """Make clip ``index`` in ``out_dir`` unless it exists; returns ``"written"`` or
    ``"skipped"``. Safe to run anywhere that sees ``out_dir`` (a Dask worker)."""
    from facelib.animation import animate
    from facelib.fdl import loads
    from facelib.mpeg4 import write_fap_complete

    final = Path(out_dir) / CLIP_PATTERN.format(index)
    if final.is_dir():
        return "skipped"
    draw = draw_clip(spec, index)
    text = clip_storyboard(spec, draw)
    temp = Path(tempfile.mkdtemp(dir=out_dir, prefix=f".{final.name}.", suffix=".tmp"))
    try:
        animation = animate(loads(text, name=f"{final.name}/clip.fdl"))
        stream = _with_head(animation.faps, draw.head_deg)
        stream = stream[: max(1, round(spec.seconds * spec.fps))]
        (temp / "clip.fdl").write_text(text, encoding="utf-8")
        write_fap_complete(stream, temp / "clip.fap", name=final.name)
        labels = _frame_labels(animation, stream)
        _render_clip(spec, draw, stream, temp, labels)
        (temp / "frames.jsonl").write_text(
            "".join(json.dumps(row, sort_keys=True) + "\n" for row in labels), encoding="utf-8")
        meta = {"draw": asdict(draw), "fps": spec.fps, "frames": stream.n_frames,
                "width": spec.width, "height": spec.height, "media": spec.media}
        (temp / "meta.json").write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n",
                                        encoding="utf-8")
        temp.chmod(0o755)
        temp.rename(final)
    except BaseException:
        shutil.rmtree(temp, ignore_errors=True)
        raise
    return "written"


def _clip_task(spec: DatasetSpec, index: int, out_dir: str) -> tuple[int, str, str | None]:
    """``(index, "written"/"skipped"/"failed", error)``: one clip, errors caught."""
    try:
        return index, make_clip(spec, index, out_dir), None
    except FacelibError as exc:
        return index, "failed", str(exc)
    except Exception as exc:  # a worker must report, not die  # noqa: BLE001
        return index, "failed", f"{type(exc).__name__}: {exc}"


# Dask's nanny starts workers with these at 1; the local pool does the same, so dense
# products sum in the same order (and the pixels match to the bit) either way.
_ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _environment(values: Mapping[str, str]) -> Iterator[None]:
    """``os.environ`` updated with ``values`` inside (for the processes started there)."""
    saved = {key: os.environ.get(key) for key in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _run_local(spec: DatasetSpec, todo: Sequence[int], out_dir: str, jobs: int,
               report: ProgressCallback | None) -> list[tuple[int, str, str | None]]:
    """The clips ``todo`` on ``jobs`` spawned worker processes, one BLAS thread each."""
    from facelib.batch import spawn_map

    with _environment(_ONE_THREAD):  # read by the workers as they start
        return spawn_map(_star_clip_task, [(spec, i, out_dir) for i in todo], jobs=jobs,
                         report=report)


def _star_clip_task(args: tuple[DatasetSpec, int, str]) -> tuple[int, str, str | None]:
    return _clip_task(*args)


def _run_dask(spec: DatasetSpec, todo: Sequence[int], out_dir: str, scheduler: Any,
              report: ProgressCallback | None, *, security: Any,
              trust: bool) -> list[tuple[int, str, str | None]]:
    """The clips ``todo`` as tasks on a Dask cluster (``scheduler``: an address such as
    ``tcp://host:8786``, or a ``distributed.Client``) through facelib's plain-data client
    (:func:`facelib.cluster.open_client`); workers write into ``out_dir``, which they must
    see at the same path (a shared file system), and answer with JSON text."""
    from facelib.cluster import open_client

    with open_client(scheduler, security=security, trust=trust) as client:
        from distributed import as_completed

        futures = client.map(_clip_task_text, [spec] * len(todo), list(todo),
                             [out_dir] * len(todo), pure=False)
        index_of = {future.key: index for future, index in zip(futures, todo, strict=True)}
        results = []
        try:
            for future in as_completed(futures, loop=client.loop):
                results.append(_cluster_result(future, index_of[future.key]))
                if report is not None:
                    report(len(results), len(todo))
        except BaseException:
            client.cancel(futures)
            raise
        return results


_MAX_RESULT_CHARS = 8192
"""The longest clip result (JSON text) read from a cluster."""
_MAX_ERROR_CHARS = 2000
"""The longest clip error message kept."""
_STATUSES = ("written", "skipped", "failed")


def _clip_task_text(spec: DatasetSpec, index: int, out_dir: str) -> str:
    """:func:`_clip_task` as the JSON text a cluster sends back: ``{"clip": index,
    "status": ..., "error": text or null}``."""
    clip, status, error = _clip_task(spec, index, out_dir)
    return json.dumps({"clip": clip, "status": status,
                       "error": None if error is None else error[:_MAX_ERROR_CHARS]})


def _cluster_result(future: Any, index: int) -> tuple[int, str, str | None]:
    """The result of clip ``index``'s task: a failed task (its error is never read) is a
    failed clip; anything but a valid result text is a FacelibError."""
    from facelib.cluster import TASK_FAILED

    if future.status == "error":
        return index, "failed", TASK_FAILED
    if future.status == "cancelled":
        return index, "failed", "the task was cancelled on the cluster"
    return parse_clip_result(future.result(), index)


def parse_clip_result(text: object, index: int) -> tuple[int, str, str | None]:
    """``(index, status, error)`` from the JSON text a worker sent for clip ``index``;
    refuses (FacelibError) anything else: data facelib's client refused (a pickle), text
    that is not such JSON, another clip's number, an unknown status."""
    from facelib.cluster import refused
    from facelib.fdl.sandbox import one_line

    if refused(text):
        raise FacelibError(f"clip {index}: the cluster sent {text} instead of the clip's "
                           f"result (facelib reads only plain data from a cluster)")
    try:
        if not isinstance(text, str) or len(text) > _MAX_RESULT_CHARS:
            raise ValueError(text)
        row = json.loads(text)
        clip, status, error = row["clip"], row["status"], row["error"]
        if (set(row) != {"clip", "status", "error"} or type(clip) is not int
                or clip != index or status not in _STATUSES
                or (status == "failed") != isinstance(error, str)
                or (error is not None and not isinstance(error, str))):
            raise ValueError(text)
    except (ValueError, TypeError, KeyError, RecursionError):
        shown = one_line(text if isinstance(text, str) else repr(text), limit=120)
        raise FacelibError(f"clip {index}: the cluster's answer is not a clip result: "
                           f"{shown}") from None
    return index, status, None if error is None else one_line(error, limit=_MAX_ERROR_CHARS)


def _claim(spec: DatasetSpec, out: Path) -> None:
    """Record the spec in ``out`` (``spec.json``, and ``spec.toml`` when read from one);
    refuse a folder holding a dataset made from a different spec."""
    settings = {k: v for k, v in asdict(spec).items() if k != "source"}
    text = json.dumps(settings, indent=1, sort_keys=True) + "\n"
    previous = out / "spec.json"
    if previous.is_file() and previous.read_text(encoding="utf-8") != text:
        raise FacelibError("this folder holds a dataset made from another spec; use a new "
                           "folder (or delete this one)", path=str(previous))
    write_text_atomic(previous, text)
    if spec.source:
        write_text_atomic(out / "spec.toml", spec.source)


def _clean_stale(out: Path) -> None:
    """Remove temporary clip folders left by a killed run (``.clip_NNNNNN.*.tmp``)."""
    for stale in out.glob(".clip_*.tmp"):
        shutil.rmtree(stale, ignore_errors=True)


def _check_made(out: Path, result: tuple[int, str, str | None]) -> tuple[int, str, str | None]:
    """``result`` as it was, or failed if it says the clip is made and its folder is not
    in ``out`` (workers that do not see the dataset folder, or do not tell the truth)."""
    index, status, _ = result
    folder = out / CLIP_PATTERN.format(index)
    if status != "failed" and not folder.is_dir():
        return index, "failed", (f"reported as made, but {folder} is not there (do the "
                                 f"workers see this folder at the same path?)")
    return result


def write_index(spec: DatasetSpec, out_dir: str | os.PathLike[str]) -> Path:
    """Write ``index.jsonl`` (one line per finished clip, in clip order) from the clips'
    ``meta.json`` files; returns its path."""
    out = Path(out_dir)
    rows = []
    for index in range(spec.clips):
        meta_path = out / CLIP_PATTERN.format(index) / "meta.json"
        if meta_path.is_file():
            meta = json.loads(meta_path.read_text(encoding="utf-8"))
            rows.append(json.dumps({"clip": CLIP_PATTERN.format(index), **meta},
                                   sort_keys=True))
    path = out / "index.jsonl"
    write_text_atomic(path, "".join(r + "\n" for r in rows))
    return path


def generate(
    spec: DatasetSpec,
    out_dir: str | os.PathLike[str],
    *,
    jobs: int | None = None,
    scheduler: Any = None,
    security: Any = None,
    trust_cluster: bool = False,
    progress: bool | ProgressCallback | None = None,
) -> DatasetReport:
    """Make every clip of ``spec`` in ``out_dir`` that is not there yet.

    Locally with ``jobs`` spawned processes (default: the CPU count), or, given
    ``scheduler`` (a Dask scheduler address or a ``distributed.Client``), as one task per
    clip on that cluster: a ``tcp://`` scheduler must be on this machine, another one needs
    ``tls://`` and ``security`` (``facelib.cluster.tls_security``) unless ``trust_cluster``;
    results come back as plain data only (``docs/security.md``).
    ``progress(clips_done, clips_to_make)``. Finished clips are
    skipped, so an interrupted run is resumed by running it again. A failing clip is
    reported in the result and the others are made. Writes ``spec.toml`` and, at the end,
    ``index.jsonl``.
    """
    from facelib.batch import default_jobs

    started = time.perf_counter()
    out = output_folder(out_dir)
    _claim(spec, out)
    _clean_stale(out)
    todo = [i for i in range(spec.clips) if not (out / CLIP_PATTERN.format(i)).is_dir()]
    report = progress_callback(progress, "dataset", unit="clips")
    if not todo:
        results: list[tuple[int, str, str | None]] = []
    elif scheduler is not None:
        results = _run_dask(spec, todo, str(out.resolve()), scheduler, report,
                            security=security, trust=trust_cluster)
    else:
        n_jobs = default_jobs() if jobs is None else check_count("jobs", jobs, low=1)
        results = _run_local(spec, todo, str(out.resolve()), min(n_jobs, len(todo)), report)
    results = [_check_made(out, result) for result in results]
    write_index(spec, out)
    failed = tuple(sorted((i, str(e)) for i, status, e in results if status == "failed"))
    written = sum(status == "written" for _, status, _ in results)
    return DatasetReport(written, spec.clips - len(todo) + sum(
        status == "skipped" for _, status, _ in results), failed,
        time.perf_counter() - started)

