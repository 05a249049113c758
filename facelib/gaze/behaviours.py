"""Eye behaviours as parameter sets over the statistical model, and binding of eye-script
tuples (``{"discomfort", 0.99, 0.6, 500}``) to them.

The library is ``facelib/data/gaze/behaviours.json``; storyboards add or override
behaviours with plain mappings of the same shape (see ``docs/gaze.md``).
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType
from typing import Any

from facelib import data
from facelib.checks import did_you_mean
from facelib.errors import FdlError
from facelib.gaze.model import GAZE_MODES, mode_stats
from facelib.gaze.norms import BLINK_STATES, head_eye_rule

__all__ = [
    "DIRECTION_NAMES",
    "BoundBehaviour",
    "behaviour_library",
    "bind_behaviour",
    "merge_behaviours",
]

ENGINES = ("statistical", "look", "pursuit")
ARG_KINDS = ("choice", "number", "yesno", "direction")
_NUMERIC = (
    "magnitude_scale",
    "magnitude_max_deg",
    "p_mutual",
    "interval_scale",
    "lid_closure",
    "blink_scale",
    "head_coupling",
    "head_threshold_deg",
)
_PAIRS = ("gaze_offset_deg", "head_offset_deg")
PARAM_KEYS = ("engine", "mode", "blink_state", "direction_percent", *_NUMERIC, *_PAIRS)
_SLOTS = ("p_away", "intensity", "direction", "angle", "head")
_BEHAVIOUR_KEYS = ("description", "args", "params", "base")


@cache
def _library_json() -> dict[str, Any]:
    library: dict[str, Any] = data.json_data("gaze/behaviours.json")
    return library


@cache
def _library_text() -> str:
    return json.dumps(_library_json())


def behaviour_library() -> dict[str, dict[str, Any]]:
    """A fresh copy of the built-in behaviours: name -> {description, args, params} (parsed
    anew from the cached JSON text: several times quicker than a deep copy)."""
    library: dict[str, dict[str, Any]] = json.loads(_library_text())
    return library


@cache
def _directions() -> Mapping[str, float | None]:
    return MappingProxyType(dict(data.json_data("gaze/directions.json")["directions"]))


def _direction_names() -> Mapping[str, float | None]:
    return _directions()


DIRECTION_NAMES = tuple(_direction_names())


def _suggest(word: str, options: Sequence[str]) -> str:
    hint = did_you_mean(word, options, cutoff=0.5)
    if hint:
        return hint
    return f"; expected one of {', '.join(repr(o) for o in options)}"


def merge_behaviours(
    overrides: Mapping[str, Mapping[str, Any]] | None,
) -> dict[str, dict[str, Any]]:
    """The built-in library with storyboard behaviours merged over it.

    An override of an existing name replaces the keys it gives (``params`` key by key); a new
    name starts from ``base`` (default ``"default"``). Raises :class:`FdlError` naming the
    behaviour and key for anything malformed.
    """
    library = behaviour_library()
    for name, spec in (overrides or {}).items():
        if not isinstance(spec, Mapping):
            raise FdlError(f"eye behaviour {name!r} must be a table, got {spec!r}")
        for key in spec:
            if key not in _BEHAVIOUR_KEYS and key not in PARAM_KEYS:
                raise FdlError(
                    f"eye behaviour {name!r}: unknown key {key!r}"
                    + _suggest(str(key), (*_BEHAVIOUR_KEYS, *PARAM_KEYS))
                )
        _check_shape(str(name), spec)
        base_name = spec.get("base", name if name in library else "default")
        if base_name not in library:
            raise FdlError(
                f"eye behaviour {name!r}: unknown base {base_name!r}"
                + _suggest(str(base_name), sorted(library))
            )
        merged = copy.deepcopy(library[base_name])
        params = dict(merged.get("params", {}))
        params.update(spec.get("params", {}))
        params.update({k: v for k, v in spec.items() if k in PARAM_KEYS})
        merged["params"] = params
        if "args" in spec:
            merged["args"] = [dict(a) for a in spec["args"]]
        if "description" in spec:
            merged["description"] = str(spec["description"])
        _validate(str(name), merged)
        library[str(name)] = merged
    return library


def _validate(name: str, spec: Mapping[str, Any]) -> None:
    """FdlError naming behaviour ``name`` for any malformed parameter or argument."""
    params = spec.get("params", {})
    for key, value in params.items():
        _validate_param(name, key, value)
    for arg in spec.get("args", []):
        if arg.get("kind") not in ARG_KINDS:
            raise FdlError(
                f"eye behaviour {name!r}: argument kind {arg.get('kind')!r}"
                + _suggest(str(arg.get("kind")), ARG_KINDS)
            )
        if arg.get("sets") not in (*PARAM_KEYS, *_SLOTS):
            raise FdlError(
                f"eye behaviour {name!r}: argument sets {arg.get('sets')!r}"
                + _suggest(str(arg.get("sets")), (*PARAM_KEYS, *_SLOTS))
            )


@cache
def _limits() -> dict[str, tuple[float, float]]:
    """Parameter key -> inclusive (low, high) from ``gaze/parameter_limits.csv``."""
    return {row["key"]: (float(row["low"]), float(row["high"]))
            for _, row in data.csv_rows("gaze/parameter_limits.csv")}


def _in_limits(key: str, value: Any) -> bool:
    """Whether ``value`` is a finite number (not a bool) within ``key``'s limits."""
    low, high = _limits()[key]
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value) and low <= value <= high)


def _validate_param(name: str, key: str, value: Any) -> None:
    """FdlError unless ``value`` is valid for parameter ``key`` of behaviour ``name``."""
    where = f"eye behaviour {name!r}"
    if key not in PARAM_KEYS:
        raise FdlError(f"{where}: unknown parameter {key!r}" + _suggest(key, PARAM_KEYS))
    if value is None and key not in ("engine", "mode"):
        return  # None: the mode's own value (or the head-eye rule's, the mode's blink state)
    if key == "blink_state" and value not in BLINK_STATES:
        raise FdlError(f"{where}: blink_state {value!r:.40}"
                       + _suggest(str(value), BLINK_STATES))
    if key in _NUMERIC and not _in_limits(key, value):
        low, high = _limits()[key]
        raise FdlError(f"{where}: {key} must be a number in [{low:g}, {high:g}], got "
                       f"{value!r:.40}")
    if key == "engine" and value not in ENGINES:
        raise FdlError(f"{where}: engine {value!r:.40}" + _suggest(str(value), ENGINES))
    if key == "mode" and value not in (*GAZE_MODES, "auto"):
        raise FdlError(f"{where}: mode {value!r:.40}"
                       + _suggest(str(value), (*GAZE_MODES, "auto")))
    sequence = isinstance(value, Sequence) and not isinstance(value, str)
    if key == "direction_percent" and (
        not sequence or len(value) != 8
        or not all(_in_limits(key, p) for p in value) or sum(value) <= 0
    ):
        raise FdlError(f"{where}: direction_percent must be 8 numbers in [0, 1e6] with a "
                       f"positive sum, got {value!r:.80}")
    if key in _PAIRS and (not sequence or len(value) != 2
                          or not all(_in_limits(key, v) for v in value)):
        raise FdlError(f"{where}: {key} must be [left, up] degrees in [-90, 90], got "
                       f"{value!r:.80}")


def _check_shape(name: str, spec: Mapping[str, Any]) -> None:
    """FdlError unless ``params`` is a mapping, ``args`` a list of argument tables and
    ``base`` and ``description`` texts (a storyboard may give any value for each)."""
    where = f"eye behaviour {name!r}"
    if "params" in spec and not isinstance(spec["params"], Mapping):
        raise FdlError(f"{where}: params must be a table of parameter = value, got "
                       f"{spec['params']!r:.60}")
    args = spec.get("args", [])
    if (isinstance(args, str) or not isinstance(args, Sequence)
            or not all(isinstance(a, Mapping) for a in args)):
        raise FdlError(f"{where}: args must be a list of argument tables ({{ name = ..., "
                       f"kind = ..., sets = ... }}), got {args!r:.60}")
    for i, arg in enumerate(args):
        if not isinstance(arg.get("name"), str):
            raise FdlError(f"{where}: argument {i + 1} needs a name text, got "
                           f"{arg.get('name')!r:.40}")
        for bound in ("min", "max"):
            if bound in arg and not (isinstance(arg[bound], (int, float))
                                     and not isinstance(arg[bound], bool)):
                raise FdlError(f"{where}: argument {arg['name']!r} {bound} must be a number")
        if arg.get("kind") == "choice" and not (
            isinstance(arg.get("choices"), Sequence)
            and all(isinstance(c, str) for c in arg["choices"])
        ):
            raise FdlError(f"{where}: argument {arg['name']!r} needs choices, a list of texts")
    for key in ("base", "description"):
        if key in spec and not isinstance(spec[key], str):
            raise FdlError(f"{where}: {key} must be a text, got {spec[key]!r:.40}")


@dataclass(frozen=True, slots=True)
class BoundBehaviour:
    """An eye behaviour with its script arguments applied, ready to generate.

    engine: ``"statistical"``, ``"look"`` or ``"pursuit"``.
    mode: talking/listening/thinking, or ``"auto"`` (from where the character speaks).
    direction_percent: (8,) bin weights or None (the mode's table).
    magnitude_scale, magnitude_max_deg (None = mode's), p_mutual (None = mode's),
    interval_scale, lid_closure, blink_scale: see the data file. head_coupling,
    head_threshold_deg: the slope and onset of the head's share of a gaze shift (None = the
    rule of ``alive/head_eye.json``). blink_state: the blink state (None = the mode's).
    gaze_offset_deg, head_offset_deg: (left, up) degrees.
    intensity: blend factor toward ``default`` already applied to the numbers above.
    target_deg: (left, up) of a look/pursuit target relative to the current gaze origin;
    head: True if a look/pursuit moves the head.
    """

    name: str
    engine: str
    mode: str
    direction_percent: tuple[float, ...] | None
    magnitude_scale: float
    magnitude_max_deg: float | None
    p_mutual: float | None
    interval_scale: float
    gaze_offset_deg: tuple[float, float]
    head_offset_deg: tuple[float, float]
    lid_closure: float
    blink_scale: float
    head_coupling: float | None
    head_threshold_deg: float | None
    blink_state: str | None = None
    target_deg: tuple[float, float] = (0.0, 0.0)
    head: bool = False


def _bind_arg(name: str, arg: Mapping[str, Any], value: Any, where: dict[str, Any]) -> Any:
    kind, label = arg["kind"], arg["name"]
    if kind == "number":
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
        ):
            raise FdlError(f"{name}: {label} must be a number, got {value!r}", **where)
        lo, hi = arg.get("min", -math.inf), arg.get("max", math.inf)
        if not lo <= value <= hi:
            raise FdlError(f"{name}: {label} {value!r} is outside [{lo}, {hi}]", **where)
        return float(value)
    if not isinstance(value, (str, int, float)) or isinstance(value, bool):
        raise FdlError(f"{name}: {label} has the wrong type: {value!r}", **where)
    if kind == "direction":
        if isinstance(value, (int, float)):
            return float(value) % 360.0
        key = value.lower().replace("-", "").replace("_", "").replace(" ", "")
        names = _direction_names()
        if key not in names:
            raise FdlError(
                f"{name}: unknown direction {value!r}" + _suggest(key, list(names)), **where
            )
        return names[key]
    text = str(value)
    if kind == "yesno":
        if text.lower() not in ("yes", "no"):
            raise FdlError(f'{name}: {label} must be "yes" or "no", got {value!r}', **where)
        return text.lower() == "yes"
    choices = arg["choices"]
    if text not in choices:
        raise FdlError(f"{name}: {label} {value!r} is not valid" + _suggest(text, choices), **where)
    return text


def bind_behaviour(
    name: str,
    args: Sequence[Any],
    *,
    library: Mapping[str, Mapping[str, Any]],
    origin: tuple[str, int] | None = None,
) -> BoundBehaviour:
    """Apply an eye-script tuple's values to behaviour ``name`` of ``library``.

    Raises :class:`FdlError` (with ``origin``'s file and line) for an unknown behaviour,
    too many values, or a value of the wrong kind or range.
    """
    where: dict[str, Any] = {"path": origin[0], "line": origin[1]} if origin else {}
    if name not in library:
        raise FdlError(f"unknown eye behaviour {name!r}" + _suggest(name, sorted(library)), **where)
    spec = library[name]
    arg_specs = spec.get("args", [])
    if len(args) > len(arg_specs):
        names = ", ".join(a["name"] for a in arg_specs) or "none"
        raise FdlError(
            f"{name} takes at most {len(arg_specs)} values before the duration ({names}), "
            f"got {len(args)}: {tuple(args)!r}",
            **where,
        )
    slots: dict[str, Any] = {}
    for i, arg in enumerate(arg_specs):
        value = args[i] if i < len(args) else arg.get("default")
        slots[arg["sets"]] = None if value is None else _bind_arg(name, arg, value, where)
    return _bound(name, _params(library, spec, slots), slots)


def _params(
    library: Mapping[str, Mapping[str, Any]], spec: Mapping[str, Any], slots: Mapping[str, Any]
) -> dict[str, Any]:
    """The behaviour's parameters over the default behaviour's, with the script's values
    (``slots``) set and the rest blended toward the default by ``slots["intensity"]``."""
    defaults = dict(library["default"]["params"])
    params = {**defaults, **spec.get("params", {})}
    for key in PARAM_KEYS:
        if key in slots:
            params[key] = slots[key]
    if "p_away" in slots:
        params["p_mutual"] = 1.0 - slots["p_away"]
    intensity = float(slots.get("intensity", 1.0))
    if intensity != 1.0:
        blended = _blend(defaults, params, intensity, params["mode"])
        # Values given directly by the script are not scaled by the intensity.
        direct = {k for k in PARAM_KEYS if k in slots} | (
            {"p_mutual"} if "p_away" in slots else set()
        )
        params = {k: params[k] if k in direct else blended[k] for k in params}
    return params


def _optional_float(value: Any) -> float | None:
    return None if value is None else float(value)


def _bound(name: str, params: Mapping[str, Any], slots: Mapping[str, Any]) -> BoundBehaviour:
    direction = slots.get("direction")
    angle = float(slots.get("angle", 0.0) or 0.0)
    if direction is None:
        target = (0.0, 0.0)
    else:
        rad = math.radians(direction)
        target = (angle * math.cos(rad), angle * math.sin(rad))
    percent = params["direction_percent"]
    gaze_offset, head_offset = params["gaze_offset_deg"], params["head_offset_deg"]
    return BoundBehaviour(
        name=name,
        engine=params.get("engine", "statistical"),
        mode=params["mode"],
        direction_percent=None if percent is None else tuple(map(float, percent)),
        magnitude_scale=float(params["magnitude_scale"]),
        magnitude_max_deg=_optional_float(params["magnitude_max_deg"]),
        p_mutual=_optional_float(params["p_mutual"]),
        interval_scale=max(float(params["interval_scale"]), 1e-3),
        gaze_offset_deg=(float(gaze_offset[0]), float(gaze_offset[1])),
        head_offset_deg=(float(head_offset[0]), float(head_offset[1])),
        lid_closure=float(params["lid_closure"]),
        blink_scale=float(params["blink_scale"]),
        head_coupling=_optional_float(params["head_coupling"]),
        head_threshold_deg=_optional_float(params["head_threshold_deg"]),
        blink_state=params.get("blink_state"),
        target_deg=target,
        head=bool(slots.get("head", False)),
    )


def _blend(
    defaults: Mapping[str, Any], params: Mapping[str, Any], t: float, mode: str
) -> dict[str, Any]:
    """Numbers of ``params`` moved a fraction ``t`` of the way from ``defaults``; a None
    (the mode's value) is resolved against ``mode`` first so it can be blended."""
    stats = mode_stats("talking" if mode == "auto" else mode)
    resolved_none: dict[str, Any] = {
        "p_mutual": stats.p_mutual,
        "magnitude_max_deg": stats.magnitude_max_deg,
        "direction_percent": list(stats.direction_percent),
        "head_coupling": head_eye_rule().slope,
        "head_threshold_deg": head_eye_rule().onset_deg,
    }
    out = dict(params)
    for key in (*_NUMERIC, "direction_percent", *_PAIRS):
        a: Any = defaults.get(key)
        b: Any = params.get(key)
        if a == b:
            continue
        a = resolved_none.get(key, a) if a is None else a
        b = resolved_none.get(key, b) if b is None else b
        if isinstance(a, list | tuple):
            out[key] = [x + t * (y - x) for x, y in zip(a, b, strict=True)]
        else:
            out[key] = a + t * (b - a)
    return out
