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

from facelib import data
from facelib.errors import DataError, FileError

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
    eyes_head: (expression, gaze) weights on eyelids and head; (0.75, 0.25) in the thesis.
    expression_importance, viseme_importance: name -> factor in [0, 1] on that side's weight.
    head_noise: idle head motion, or None for none.
    """

    mouth: tuple[float, float] = field(default_factory=lambda: _default_rules().mouth)
    eyes_head: tuple[float, float] = field(default_factory=lambda: _default_rules().eyes_head)
    expression_importance: Mapping[str, float] = field(
        default_factory=lambda: _default_rules().expression_importance)
    viseme_importance: Mapping[str, float] = field(
        default_factory=lambda: _default_rules().viseme_importance)
    head_noise: HeadNoise | None = field(default_factory=lambda: _default_rules().head_noise)

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
        rules = SyncRules(
            mouth=(float(doc["mouth"]["expression"]), float(doc["mouth"]["viseme"])),
            eyes_head=(float(doc["eyes_head"]["expression"]), float(doc["eyes_head"]["gaze"])),
            expression_importance=MappingProxyType(
                {k.lower(): float(v) for k, v in doc.get("expression_importance", {}).items()}
            ),
            viseme_importance=MappingProxyType(
                {k: float(v) for k, v in doc.get("viseme_importance", {}).items()}
            ),
            head_noise=None if noise is None else _noise(noise),
        )
    except (AttributeError, KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad synchronizer rules: {exc!r}", path=where) from exc
    for name, value in (*rules.expression_importance.items(),
                        *rules.viseme_importance.items()):
        if not 0.0 <= value <= 1.0:
            raise DataError(f"importance of {name!r} is {value}, not in [0, 1]", path=where)
    if min(*rules.mouth, *rules.eyes_head) < 0:
        raise DataError("blend weights must not be negative", path=where)
    return rules
