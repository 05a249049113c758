"""Deformers compared: the second seed's roughness evaluation (Peña Araya 2012, chapter 4).

Runs a set of poses (the 15 visemes, the six universal expressions and the seed's 27
syllables, each a consonant -> vowel transition) through the default head with one region
group (the lips) switched to each deformer, and measures the lip region's roughness (eq.
3.2-3.3) and the triangles that turn over. :func:`write_evaluation` writes the table as CSV
and Markdown, the seed's per-frame rows (one per lip feature point plus the summary row -1),
and a contact sheet of the mouth for each deformer.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from facelib.atomic import atomic_path, write_text_atomic
from facelib.data import csv_rows
from facelib.engine import Face, load_face
from facelib.engine.deformers import deformer_names
from facelib.engine.roughness import flipped_triangles, region_roughness, roughness_report
from facelib.errors import DataError, ParameterError

__all__ = ["DEFORMERS", "EXPRESSIONS", "Evaluation", "Pose", "evaluate_deformers",
           "evaluation_poses", "summary_table", "write_contact_sheet", "write_evaluation"]

DEFORMERS: tuple[str, ...] = ("rbf", "raised_cosine", "inverse_distance", "feature_point",
                              "barycentric", "soffd", "planar_bones")
"""The seven deformers compared by default (``rbf`` with its defaults is today's lips)."""

EXPRESSIONS = ("joy", "sadness", "anger", "fear", "disgust", "surprise")
LIP_POINTS = ("2.2", "2.3", "2.4", "2.5", "2.6", "2.7", "2.8", "2.9",
              "8.1", "8.2", "8.3", "8.4", "8.5", "8.6", "8.7", "8.8", "8.9", "8.10")
"""The 18 MPEG-4 lip feature points (the seed used 18 CANDIDE lip vertices); a face that
lacks some (the default head has no 8.9, 8.10) reports the others."""

POSE_KINDS = ("viseme", "expression", "syllable")
SYLLABLE_STEPS = (0.0, 0.5, 1.0)
"""Frames of a syllable: the consonant, half-way, the vowel (weights of the vowel)."""


@dataclass(frozen=True, eq=False)
class Pose:
    """kind: ``viseme``, ``expression`` or ``syllable``; frames: (k, 84) float32 FAP values."""

    kind: str
    name: str
    frames: np.ndarray


def _syllables() -> list[tuple[str, str, str]]:
    from facelib.mpeg4.visemes import viseme_id

    out = []
    for line, row in csv_rows("evaluation/syllables.csv"):
        try:
            out.append((row["syllable"], row["consonant"], row["vowel"]))
            viseme_id(row["consonant"]), viseme_id(row["vowel"])
        except (KeyError, ParameterError) as exc:
            raise DataError(f"bad syllable row: {exc}", path="evaluation/syllables.csv",
                            line=line) from exc
    return out


def evaluation_poses(kinds: Sequence[str] = ("viseme", "expression", "syllable")) -> list[Pose]:
    """The default poses: 15 visemes and 6 expressions at full intensity, 27 syllables."""
    unknown = [k for k in kinds if k not in POSE_KINDS]
    if unknown or not kinds:
        raise ParameterError(f"pose kinds must be some of {POSE_KINDS}, got {tuple(kinds)}")
    from facelib.expressions.library import default_library
    from facelib.mpeg4.visemes import viseme_id, viseme_names
    from facelib.visemes.tables import viseme_targets

    targets = viseme_targets()
    poses = []
    if "viseme" in kinds:
        poses += [Pose("viseme", n, targets[i][None]) for i, n in enumerate(viseme_names())]
    if "expression" in kinds:
        library = default_library()
        poses += [Pose("expression", n, library.get(n).values[None]) for n in EXPRESSIONS]
    if "syllable" in kinds:
        for name, consonant, vowel in _syllables():
            c, v = targets[viseme_id(consonant)], targets[viseme_id(vowel)]
            frames = np.stack([(1 - s) * c + s * v for s in SYLLABLE_STEPS]).astype(np.float32)
            poses.append(Pose("syllable", name, frames))
    return poses


@dataclass(frozen=True, eq=False)
class Evaluation:
    """Results: ``rows`` of (deformer, kind, pose, mean, min, max, flipped) with the
    roughness over the pose's frames (mean of the per-frame means, min of minima, max of
    maxima) and the most flipped triangles in a frame; ``reports``: deformer -> the seed's
    per-frame rows over the syllable frames; ``linearisation_mm``: deformer -> the largest
    vertex distance between its linearised and exact forms over all poses (frame-based
    deformers only)."""

    rows: tuple[tuple[str, str, str, float, float, float, int], ...]
    reports: Mapping[str, list[tuple[int, float, str, float, float, float]]]
    linearisation_mm: Mapping[str, float]
    rest: float

    def values(self, deformer: str, kind: str) -> np.ndarray:
        """(k,) mean roughness of each pose of ``kind`` for ``deformer``."""
        return np.array([r[3] for r in self.rows if r[0] == deformer and r[1] == kind])


def _lip_ids(face: Face, group: str) -> np.ndarray:
    ids = [r.vertices for r in face.regions if group in (r.group, r.name)]
    if not ids:
        raise ParameterError(f"the face has no region or group {group!r}")
    return np.unique(np.concatenate(ids))


def _measure(face: Face, poses: Sequence[Pose], lips: np.ndarray, name: str
             ) -> tuple[list[tuple[str, str, str, float, float, float, int]], np.ndarray]:
    rows = []
    deformed = []
    for pose in poses:
        frames = np.stack([face.deform_frame(f) for f in pose.frames])
        stats = region_roughness(frames, face.triangles, lips)
        flips = max(flipped_triangles(face.vertices, v, face.triangles) for v in frames)
        rows.append((name, pose.kind, pose.name, float(stats[:, 2].mean()),
                     float(stats[:, 0].min()), float(stats[:, 1].max()), flips))
        deformed.append(frames)
    return rows, np.concatenate(deformed)


def evaluate_deformers(
    deformers: Sequence[str] = DEFORMERS, *, group: str = "lips",
    poses: Sequence[Pose] | None = None, face_path: str | Path | None = None,
) -> Evaluation:
    """Measure each deformer on ``group`` of the face over ``poses`` (default: all)."""
    unknown = [d for d in deformers if d not in deformer_names()]
    if unknown:
        raise ParameterError(f"unknown deformer {unknown[0]!r}; known: {deformer_names()}")
    poses = list(evaluation_poses() if poses is None else poses)
    rows: list[tuple[str, str, str, float, float, float, int]] = []
    reports = {}
    lin_error = {}
    rest = float("nan")
    for name in deformers:
        face = load_face(face_path, deformers={group: name})
        lips = _lip_ids(face, group)
        rest = float(region_roughness(face.vertices[None], face.triangles, lips)[0, 2])
        got, _ = _measure(face, poses, lips, name)
        rows += got
        syllables = [p for p in poses if p.kind == "syllable"]
        if syllables:
            frames = np.stack([face.deform_frame(f) for p in syllables for f in p.frames])
            points = {k: face.feature_points[k] for k in LIP_POINTS if k in face.feature_points}
            reports[name] = roughness_report(frames, face.triangles, points).rows()
        if name in ("soffd", "planar_bones"):
            exact = load_face(face_path, deformers={group: {"deformer": name, "mode": "exact"}})
            lin_error[name] = 1000.0 * max(
                float(np.abs(face.deform_frame(f) - exact.deform_frame(f)).max())
                for p in poses for f in p.frames)
    return Evaluation(tuple(rows), reports, lin_error, rest)


def _csv(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([f"{v:.6g}" if isinstance(v, float) else v for v in row])
    return buf.getvalue()


def summary_table(ev: Evaluation) -> list[dict[str, Any]]:
    """One dict per deformer: means and variances per pose kind, the worst viseme ratio to
    the first deformer (today's), the most flipped triangles, the linearisation error."""
    names = list(dict.fromkeys(r[0] for r in ev.rows))
    base = ev.values(names[0], "viseme")
    out = []
    for name in names:
        vis, expr, syl = (ev.values(name, k) for k in ("viseme", "expression", "syllable"))
        flips = max(r[6] for r in ev.rows if r[0] == name)
        out.append({
            "deformer": name,
            "visemes_mean": float(vis.mean()) if vis.size else float("nan"),
            "visemes_var": float(vis.var()) if vis.size else float("nan"),
            "expressions_mean": float(expr.mean()) if expr.size else float("nan"),
            "syllables_mean": float(syl.mean()) if syl.size else float("nan"),
            "syllables_var": float(syl.var()) if syl.size else float("nan"),
            "worst_viseme_ratio": float((vis / base).max()) if vis.size else float("nan"),
            "max_flipped": flips,
            "linearisation_mm": ev.linearisation_mm.get(name, float("nan")),
        })
    return out


def _markdown(ev: Evaluation) -> str:
    table = summary_table(ev)
    key = "syllables_mean" if not np.isnan(table[0]["syllables_mean"]) else "visemes_mean"
    ranked = sorted(table, key=lambda r: r[key])
    lines = [
        ("| rank | deformer | visemes mean | visemes var | expressions mean | syllables mean "
         "| syllables var | worst viseme / rbf | max flipped | linearised vs exact (mm) |"),
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for i, r in enumerate(ranked, 1):
        lin = "" if np.isnan(r["linearisation_mm"]) else f"{r['linearisation_mm']:.2f}"
        lines.append(
            f"| {i} | `{r['deformer']}` | {r['visemes_mean']:.5f} | {r['visemes_var']:.3g} | "
            f"{r['expressions_mean']:.5f} | {r['syllables_mean']:.5f} | "
            f"{r['syllables_var']:.3g} | {r['worst_viseme_ratio']:.3f} | {r['max_flipped']} "
            f"| {lin} |")
    lines.append("")
    what = "syllables'" if key == "syllables_mean" else "visemes'"
    lines.append(f"Lip region at rest: {ev.rest:.5f}. Ranked by the {what} mean (the seed's "
                 "table E.1 ranks by the syllables').")
    return "\n".join(lines) + "\n"


def write_evaluation(ev: Evaluation, folder: str | Path, *, sheet: bool = True,
                     frames: bool = True, stem: str = "deformers",
                     face_path: str | Path | None = None) -> list[Path]:
    """Write ``<stem>.csv`` (every pose), ``<stem>.md`` (the summary), with ``frames``
    ``<stem>_frames.csv`` (the seed's per-frame rows) and with ``sheet``
    ``<stem>_mouths.png``. Returns the paths written."""
    folder = Path(folder)
    out = [folder / f"{stem}.csv", folder / f"{stem}.md"]
    write_text_atomic(out[0], _csv(("deformer", "kind", "pose", "mean", "min", "max",
                                    "flipped"), ev.rows))
    write_text_atomic(out[1], _markdown(ev))
    if frames:
        out.append(folder / f"{stem}_frames.csv")
        rows = [(name, *row) for name, report in ev.reports.items() for row in report]
        write_text_atomic(out[-1], _csv(("deformer", "frame", "time_s", "point", "min", "max",
                                         "mean"), rows))
    if sheet:
        out.append(folder / f"{stem}_mouths.png")
        write_contact_sheet(list(dict.fromkeys(r[0] for r in ev.rows)), out[-1],
                            face_path=face_path)
    return out


SHEET_POSES = ("sil", "PP", "aa", "ih", "ou", "joy")


def write_contact_sheet(deformers: Sequence[str], path: str | Path, *, group: str = "lips",
                        poses: Sequence[str] = SHEET_POSES, size: int = 200,
                        face_path: str | Path | None = None) -> Path:
    """A grid PNG of the mouth: one row per deformer, one column per pose (a viseme or an
    expression name). Needs the ``render`` extra."""
    from PIL import Image, ImageDraw

    from facelib.rendering.scene import FaceRenderer

    lookup = {p.name: p.frames[-1] for p in evaluation_poses(("viseme", "expression"))}
    missing = [p for p in poses if p not in lookup]
    if missing:
        raise ParameterError(f"unknown pose {missing[0]!r} for the contact sheet")
    label_w = 130
    sheet = Image.new("RGB", (label_w + size * len(poses), 24 + size * len(deformers)), "white")
    draw = ImageDraw.Draw(sheet)
    for j, pose in enumerate(poses):
        draw.text((label_w + j * size + 6, 6), pose, fill="black")
    for i, name in enumerate(deformers):
        face = load_face(face_path, deformers={group: name})
        lips = _lip_ids(face, group)
        draw.text((6, 24 + i * size + size // 2), name, fill="black")
        framing = np.asarray(face.vertices[lips], np.float32)
        with FaceRenderer(face, width=size, height=size, framing=framing) as renderer:
            for j, pose in enumerate(poses):
                image = renderer.frame(face.deform_frame(lookup[pose]))
                sheet.paste(Image.fromarray(image), (label_w + j * size, 24 + i * size))
    path = Path(path)
    with atomic_path(path) as temp:
        sheet.save(temp, format="PNG")
    return path
