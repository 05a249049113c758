"""The synchronizer's rules, read from ``facelib/data/sync.json`` (see its comments)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib.errors import ParameterError
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.sync.nods import Nods

__all__ = ["HeadNoise", "SyncRules"]


@dataclass(frozen=True)
class HeadNoise:
    """Idle head motion: Perlin noise of ``amplitude_deg`` (pitch, yaw, roll) at about
    ``frequency_hz``; while speaking the amplitude and frequency are multiplied by
    ``speaking_amplitude`` and ``speaking_frequency``."""

    amplitude_deg: tuple[float, float, float] = (1.5, 2.0, 1.0)
    frequency_hz: float = 0.25
    octaves: int = 2
    speaking_amplitude: float = 1.6
    speaking_frequency: float = 1.6


@dataclass(frozen=True)
class SyncRules:
    """Weights of the conflict resolution.

    mouth: (expression, viseme) weights where both drive a FAP; (1, 3) is eq. 4.11.
    mouth_faps: FAP name -> (expression, viseme) weights that replace ``mouth`` on that FAP.
    eyes_head: (expression, gaze) weights on eyelids and head; (0.75, 0.25) in the thesis.
    expression_importance, viseme_importance: name -> factor in [0, 1] on that side's weight.
    head_noise: idle head motion, or None for none.
    speech_nods: nods on stressed syllables while speaking, or None for none.
    """

    mouth: tuple[float, float] = (1.0, 3.0)
    mouth_faps: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    eyes_head: tuple[float, float] = (0.75, 0.25)
    expression_importance: Mapping[str, float] = field(default_factory=dict)
    viseme_importance: Mapping[str, float] = field(default_factory=dict)
    head_noise: HeadNoise | None = HeadNoise()
    speech_nods: Nods | None = field(default_factory=Nods)

    def mouth_weights(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-FAP (expression, viseme) weights of the mouth blend: two ``(84,) float64``
        arrays, ``mouth`` everywhere except on the FAPs that ``mouth_faps`` names."""
        weights = np.tile(np.asarray(self.mouth, np.float64), (N_FAPS, 1))
        for name, pair in self.mouth_faps.items():
            weights[fap(name).index] = pair
        return weights[:, 0], weights[:, 1]

    @classmethod
    def load(cls, path: str | Path | None = None) -> SyncRules:
        """Rules from a JSON file shaped like ``facelib/data/sync.json`` (the default)."""
        if path is None:
            text = resources.files("facelib.data").joinpath("sync.json").read_text("utf-8")
            where = "facelib/data/sync.json"
        else:
            text, where = Path(path).read_text("utf-8"), str(path)
        try:
            data: dict[str, Any] = json.loads(text)
            noise = data.get("head_noise")
            nods = data.get("speech_nods")
            rules = cls(
                mouth=(float(data["mouth"]["expression"]), float(data["mouth"]["viseme"])),
                mouth_faps=MappingProxyType(_mouth_faps(data.get("mouth_faps", []))),
                eyes_head=(float(data["eyes_head"]["expression"]),
                           float(data["eyes_head"]["gaze"])),
                expression_importance=MappingProxyType(
                    {k.lower(): float(v) for k, v in data.get("expression_importance", {}).items()}
                ),
                viseme_importance=MappingProxyType(
                    {k: float(v) for k, v in data.get("viseme_importance", {}).items()}
                ),
                head_noise=None if noise is None else HeadNoise(
                    amplitude_deg=tuple(float(noise["amplitude_deg"][k])  # type: ignore[arg-type]
                                        for k in ("pitch", "yaw", "roll")),
                    frequency_hz=float(noise["frequency_hz"]),
                    octaves=int(noise["octaves"]),
                    speaking_amplitude=float(noise["speaking_amplitude"]),
                    speaking_frequency=float(noise["speaking_frequency"]),
                ),
                speech_nods=None if nods is None else Nods(
                    **{k: float(nods[k]) for k in Nods.__dataclass_fields__}),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(f"bad synchronizer rules: {exc!r}", path=where) from exc
        for name, value in (*rules.expression_importance.items(),
                            *rules.viseme_importance.items()):
            if not 0.0 <= value <= 1.0:
                raise ParameterError(f"importance of {name!r} is {value}, not in [0, 1]",
                                     path=where)
        per_fap = [w for pair in rules.mouth_faps.values() for w in pair]
        if min(*rules.mouth, *rules.eyes_head, *per_fap) < 0:
            raise ParameterError("blend weights must not be negative", path=where)
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
