"""The VRM 1.0 expression presets as morph targets of any face: each preset's FAP recipe
(``facelib/data/export/vrm.json``) and the face deformed by it.

A recipe is one FAP frame (84 values, FAP units): a viseme's FAPs at full intensity
(``visemes/viseme_faps.json``), a library expression's (its action units composed by
:mod:`facelib.mpeg4.action_units`, as the expression library does), FAPs given in the file
(the blinks) or an eye turn in degrees (the looks). The export layer may not import the
viseme package, so its data file is read here through :mod:`facelib.data`.
"""

from __future__ import annotations

import numpy as np

from facelib import data
from facelib.engine import Face
from facelib.errors import DataError, ParameterError
from facelib.mpeg4.action_units import compose, recipes
from facelib.mpeg4.tables import N_FAPS, fap

__all__ = ["preset_names", "preset_recipes", "preset_targets"]

_FILE = "export/vrm.json"


def preset_names() -> tuple[str, ...]:
    """The preset names in file order (``aa``, ``ih``, ... ``lookRight``)."""
    return tuple(data.json_data(_FILE)["presets"])


def _expression_faps(name: str) -> dict[str, float]:
    library = recipes()
    if name not in library:
        raise DataError(f"{_FILE}: no expression {name!r} in expressions/expressions.csv",
                        path=str(data.path(_FILE)))
    values, mask = compose(library[name].parts)
    return {fap(int(k) + 1).name: float(values[k]) for k in np.flatnonzero(mask)}


def _viseme_faps(name: str) -> dict[str, float]:
    visemes = data.json_data("visemes/viseme_faps.json")["visemes"]
    if name not in visemes:
        raise DataError(f"{_FILE}: no viseme {name!r} in viseme_faps.json",
                        path=str(data.path(_FILE)))
    return {k: float(v) for k, v in visemes[name]["faps"].items()}


def _eye_faps(turn: dict[str, float], au: float) -> dict[str, float]:
    """Both eyes turned by ``yaw`` (> 0 toward +x, the model's left) and ``pitch`` (> 0
    down) degrees, as FAPs 23-26 in angle units ``au`` (radians per unit)."""
    yaw, pitch = (np.radians(float(turn.get(k, 0.0))) / au for k in ("yaw", "pitch"))
    return {"yaw_l_eyeball": yaw, "yaw_r_eyeball": yaw,
            "pitch_l_eyeball": pitch, "pitch_r_eyeball": pitch}


def preset_recipes(*, au: float = 1e-5) -> np.ndarray:
    """``(P, 84) float32``: each preset's FAP frame, rows in :func:`preset_names` order;
    ``au``: the face's angle unit in radians (1e-5 by the MPEG-4 definition)."""
    presets = data.json_data(_FILE)["presets"]
    out = np.zeros((len(presets), N_FAPS), np.float32)
    for k, (name, spec) in enumerate(presets.items()):
        if "viseme" in spec:
            faps = _viseme_faps(spec["viseme"])
        elif "expression" in spec:
            faps = _expression_faps(spec["expression"])
        elif "eyes_deg" in spec:
            faps = _eye_faps(spec["eyes_deg"], au)
        else:
            faps = {k2: float(v) for k2, v in spec["faps"].items()}
        for key, value in faps.items():
            try:
                out[k, fap(key).index] = value
            except ParameterError as exc:
                raise DataError(f"preset {name!r}: {exc.message}",
                                path=str(data.path(_FILE))) from exc
    return out


def preset_targets(face: Face) -> np.ndarray:
    """``(P, V, 3) float32`` displacements (the face's unit): ``face`` deformed by each
    recipe, minus its rest positions. Rotations inside a recipe (eyes, lids, the jaw's teeth)
    are taken at weight 1; a morph target follows them along the chord at lower weights."""
    recipes = preset_recipes(au=float(face.fapu["AU"]))
    rest = face.vertices.astype(np.float32)
    return np.stack([face.deform_frame(r) - rest for r in recipes]).astype(np.float32)
