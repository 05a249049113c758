"""The synchronizer's rules, read from ``facelib/data/sync.json`` (see its comments).

The numbers live in the data file only: a field left out when building :class:`HeadNoise`
or :class:`SyncRules` in code takes the data file's value.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib import data
from facelib.errors import DataError, FileError
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.sync.alive import AliveRules
from facelib.sync.nods import Nods

__all__ = ["HeadNoise", "SyncRules"]


@cache
def _default_rules() -> SyncRules:
    return _rules(data.json_data("sync.json"), str(data.path("sync.json")))


@cache
def _default_noise() -> HeadNoise:
    return _noise(data.json_data("sync.json")["head_noise"])


@dataclass(frozen=True)
class HeadNoise:
    """Idle head motion: Perlin noise of ``amplitude_deg`` (pitch, yaw, roll) at about
    ``frequency_hz``; while speaking the amplitude and frequency are multiplied by
    ``speaking_amplitude`` and ``speaking_frequency``. Defaults: ``sync.json``."""

    amplitude_deg: tuple[float, float, float] = field(
        default_factory=lambda: _default_noise().amplitude_deg)
    frequency_hz: float = field(default_factory=lambda: _default_noise().frequency_hz)
    octaves: int = field(default_factory=lambda: _default_noise().octaves)
    speaking_amplitude: float = field(
        default_factory=lambda: _default_noise().speaking_amplitude)
    speaking_frequency: float = field(
        default_factory=lambda: _default_noise().speaking_frequency)


@dataclass(frozen=True)
class SyncRules:
    """Weights of the conflict resolution. Defaults: ``sync.json``.

    mouth: (expression, viseme) weights where both drive a FAP; (1, 3) is eq. 4.11.
    mouth_faps: FAP name -> (expression, viseme) weights that replace ``mouth`` on that FAP.
    eyes_head: (expression, gaze) weights on eyelids and head; (0.75, 0.25) in the thesis.
    expression_importance, viseme_importance: name -> factor in [0, 1] on that side's weight.
    head_noise: idle head motion, or None for none.
    speech_nods: nods on stressed syllables while speaking, or None for none.
    alive: breathing, listening motion, micro-movements and the eyes' counter-rotation
        (``facelib/data/alive/idle.json``), or None for none.
    """

    mouth: tuple[float, float] = field(default_factory=lambda: _default_rules().mouth)
    mouth_faps: Mapping[str, tuple[float, float]] = field(
        default_factory=lambda: _default_rules().mouth_faps)
    eyes_head: tuple[float, float] = field(default_factory=lambda: _default_rules().eyes_head)
    expression_importance: Mapping[str, float] = field(
        default_factory=lambda: _default_rules().expression_importance)
    viseme_importance: Mapping[str, float] = field(
        default_factory=lambda: _default_rules().viseme_importance)
    head_noise: HeadNoise | None = field(default_factory=lambda: _default_rules().head_noise)
    speech_nods: Nods | None = field(default_factory=lambda: _default_rules().speech_nods)
    alive: AliveRules | None = field(default_factory=AliveRules.load)

    def mouth_weights(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-FAP (expression, viseme) weights of the mouth blend: two ``(84,) float64``
        arrays, ``mouth`` everywhere except on the FAPs that ``mouth_faps`` names."""
        weights = np.tile(np.asarray(self.mouth, np.float64), (N_FAPS, 1))
        for name, pair in self.mouth_faps.items():
            weights[fap(name).index] = pair
        return weights[:, 0], weights[:, 1]

    @classmethod
    def load(cls, path: str | Path | None = None) -> SyncRules:
        """Rules from a JSON file shaped like ``facelib/data/sync.json`` (the default).

        Raises FileError if the file cannot be read, DataError (with the file, and the
        line for invalid JSON) if it is malformed.
        """
        if path is None:
            return _default_rules()
        try:
            text = Path(path).read_text("utf-8")
        except OSError as exc:
            raise FileError.wrap(exc, "read", path) from exc
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DataError(f"invalid JSON: {exc.msg}", path=path, line=exc.lineno) from exc
        return _rules(doc, str(path))


def _noise(raw: Mapping[str, Any]) -> HeadNoise:
    return HeadNoise(
        amplitude_deg=(float(raw["amplitude_deg"]["pitch"]), float(raw["amplitude_deg"]["yaw"]),
                       float(raw["amplitude_deg"]["roll"])),
        frequency_hz=float(raw["frequency_hz"]),
        octaves=int(raw["octaves"]),
        speaking_amplitude=float(raw["speaking_amplitude"]),
        speaking_frequency=float(raw["speaking_frequency"]),
    )


def _rules(doc: Any, where: str) -> SyncRules:
    """SyncRules from a parsed rules document; DataError naming ``where`` if malformed."""
    try:
        noise = doc.get("head_noise")
        nods = doc.get("speech_nods")
        rules = SyncRules(
            mouth=(float(doc["mouth"]["expression"]), float(doc["mouth"]["viseme"])),
            mouth_faps=MappingProxyType(_mouth_faps(doc.get("mouth_faps", []))),
            eyes_head=(float(doc["eyes_head"]["expression"]), float(doc["eyes_head"]["gaze"])),
            expression_importance=MappingProxyType(
                {k.lower(): float(v) for k, v in doc.get("expression_importance", {}).items()}
            ),
            viseme_importance=MappingProxyType(
                {k: float(v) for k, v in doc.get("viseme_importance", {}).items()}
            ),
            head_noise=None if noise is None else _noise(noise),
            speech_nods=None if nods is None else Nods(
                **{k: float(nods[k]) for k in Nods.__dataclass_fields__}),
        )
    except (AttributeError, KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad synchronizer rules: {exc!r}", path=where) from exc
    for name, value in (*rules.expression_importance.items(),
                        *rules.viseme_importance.items()):
        if not 0.0 <= value <= 1.0:
            raise DataError(f"importance of {name!r} is {value}, not in [0, 1]", path=where)
    per_fap = [w for pair in rules.mouth_faps.values() for w in pair]
    if min(*rules.mouth, *rules.eyes_head, *per_fap) < 0:
        raise DataError("blend weights must not be negative", path=where)
    return rules


def _mouth_faps(groups: list[dict[str, Any]]) -> dict[str, tuple[float, float]]:
    """``mouth_faps`` groups (``faps``, ``expression``, ``viseme``, ``why``) -> FAP name ->
    (expression, viseme); a FAP named twice or not a FAP is an error."""
    out: dict[str, tuple[float, float]] = {}
    for group in groups:
        pair = (float(group["expression"]), float(group["viseme"]))
        for name in group["faps"]:
            fap(name)  # raises on an unknown name
            if name in out:
                raise ValueError(f"FAP {name!r} is in two mouth_faps groups")
            out[name] = pair
    return out
