"""VMC protocol messages (OSC over UDP, the ``live`` extra's ``python-osc``): what VSeeFace,
VNyan, Warudo and three-vrm bridges read to move a VRM avatar.

Each frame is one OSC bundle of ``/VMC/Ext/Blend/Val`` (clip name, value) for the VRM
vowel and blink presets (``A I U E O Blink_L Blink_R``) and the 52 ARKit names as Apple
spells them (``eyeBlinkLeft`` ... ``tongueOut``: the "perfect sync" clips), then
``/VMC/Ext/Blend/Apply``, ``/VMC/Ext/Bone/Pos`` for ``Head`` (local position 0, rotation as
a Unity quaternion x, y, z, w from the head's yaw, pitch and roll) and ``/VMC/Ext/OK`` 1 with
``/VMC/Ext/T`` (session seconds).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from facelib.errors import ParameterError
from facelib.optional import require

__all__ = ["DEFAULT_PORT", "VOWELS", "bundle", "clip_values", "head_quaternion"]

DEFAULT_PORT = 39539
"""The port VMC receivers (VSeeFace, VNyan) listen on by default."""
VOWELS = {10: "A", 11: "E", 12: "I", 13: "O", 14: "U"}
"""The VRM vowel clip of each MPEG-4 vowel viseme id."""
_PRESETS = ("A", "I", "U", "E", "O", "Blink_L", "Blink_R")


def _osc() -> Any:
    return require("osc_bundle"), require("osc_message")


def clip_values(weights: np.ndarray, viseme: int) -> list[tuple[str, float]]:
    """``(clip, value)`` of one frame: the vowel presets (the shown vowel viseme at twice
    ``JawOpen``, capped at 1; the others 0), the blinks (``EyeBlinkLeft/Right``), then the
    52 ARKit weights under Apple's names. ``weights``: ``(52,)`` in facelib's order."""
    from facelib.export.arkit import arkit_names

    names = arkit_names()
    w = np.asarray(weights, np.float64).reshape(-1)
    if w.size != len(names):
        raise ParameterError(f"VMC clips take {len(names)} ARKit weights, got {w.size}")
    by_name = dict(zip(names, w.tolist(), strict=True))
    opening = min(1.0, 2.0 * by_name["JawOpen"])
    preset = dict.fromkeys(_PRESETS, 0.0)
    if viseme in VOWELS:
        preset[VOWELS[viseme]] = opening
    preset["Blink_L"], preset["Blink_R"] = by_name["EyeBlinkLeft"], by_name["EyeBlinkRight"]
    arkit = [(n[0].lower() + n[1:], v) for n, v in by_name.items()]
    return [*preset.items(), *arkit]


def head_quaternion(yaw: float, pitch: float, roll: float) -> tuple[float, float, float, float]:
    """Unity's ``Quaternion.Euler(pitch, yaw, roll)`` (radians in; x, y, z, w out): roll
    about z, then pitch about x, then yaw about y."""
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cx, sx = math.cos(pitch / 2), math.sin(pitch / 2)
    cz, sz = math.cos(roll / 2), math.sin(roll / 2)
    # q = q_yaw(y) * q_pitch(x) * q_roll(z)
    x = cy * sx * cz + sy * cx * sz
    y = sy * cx * cz - cy * sx * sz
    z = cy * cx * sz - sy * sx * cz
    w = cy * cx * cz + sy * sx * sz
    return x, y, z, w


def bundle(weights: np.ndarray, angles: np.ndarray, *, viseme: int, time_s: float) -> bytes:
    """The OSC bundle of one frame (see the module's docstring); ``angles`` ``(9,)``
    radians in :data:`facelib.export.arkit.ANGLE_NAMES` order."""
    bundles, messages = _osc()
    a = np.asarray(angles, np.float64).reshape(-1)
    if a.size != 9 or not np.isfinite(a).all():
        raise ParameterError(f"VMC takes 9 finite angles, got {a.size}")
    out = bundles.OscBundleBuilder(bundles.IMMEDIATELY)

    def add(address: str, *args: Any) -> None:
        message = messages.OscMessageBuilder(address=address)
        for arg in args:
            message.add_arg(arg, "s" if isinstance(arg, str) else (
                "i" if isinstance(arg, int) else "f"))
        out.add_content(message.build())

    for name, value in clip_values(weights, viseme):
        add("/VMC/Ext/Blend/Val", name, float(value))
    add("/VMC/Ext/Blend/Apply")
    add("/VMC/Ext/Bone/Pos", "Head", 0.0, 0.0, 0.0, *head_quaternion(a[0], a[1], a[2]))
    add("/VMC/Ext/OK", 1)
    add("/VMC/Ext/T", float(time_s))
    return bytes(out.build().dgram)
