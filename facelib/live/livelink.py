"""The Live Link Face UDP packet: what the iPhone app sends and Unreal's Live Link
(``AppleARKitFaceSupport``) receives, so a live session can drive a MetaHuman or any
ARKit-rigged character in Unreal.

Layout (network byte order, big-endian): version ``uint8`` (6); device id and subject name,
each an ``int32`` byte length then UTF-8 bytes; the frame time as ``int32`` frame number,
``float32`` sub-frame, ``int32`` rate numerator and ``int32`` rate denominator; the curve
count ``uint8`` (61); then 61 ``float32``: the 52 ARKit weights in Unreal's
``EARFaceBlendShape`` order (:func:`facelib.export.arkit.arkit_names`) and head yaw, pitch,
roll, left eye yaw, pitch, roll, right eye yaw, pitch, roll
(:data:`facelib.export.arkit.ANGLE_NAMES`, radians).
"""

from __future__ import annotations

import math
import struct

import numpy as np

from facelib.errors import ParameterError

__all__ = ["DEFAULT_PORT", "PACKET_VERSION", "packet"]

PACKET_VERSION = 6
DEFAULT_PORT = 11111
"""The port Unreal's Live Link Face source listens on by default."""
_N_CURVES = 61
_MAX_NAME_BYTES = 255


def _name(text: str, what: str) -> bytes:
    raw = text.encode("utf-8")
    if not 0 < len(raw) <= _MAX_NAME_BYTES:
        raise ParameterError(f"{what} must be 1-{_MAX_NAME_BYTES} bytes of UTF-8, got {text!r}")
    return struct.pack(">i", len(raw)) + raw


def packet(weights: np.ndarray, angles: np.ndarray, *, frame: int, fps: float,
           subject: str = "facelib", device: str = "facelib") -> bytes:
    """One frame's packet: ``weights`` ``(52,)`` in [0, 1] (facelib's ARKit order, which is
    the packet's), ``angles`` ``(9,)`` radians, ``frame`` the frame number at ``fps``
    (a whole rate, or a ratio of whole numbers to the millionth)."""
    w = np.asarray(weights, np.float32).reshape(-1)
    a = np.asarray(angles, np.float32).reshape(-1)
    if w.size != 52 or a.size != 9 or not (np.isfinite(w).all() and np.isfinite(a).all()):
        raise ParameterError(f"a Live Link packet takes 52 finite weights and 9 angles, got "
                             f"{w.size} and {a.size}")
    numerator, denominator = _rate(fps)
    head = (struct.pack(">B", PACKET_VERSION) + _name(device, "device") + _name(subject, "subject")
            + struct.pack(">ifiiB", int(frame), 0.0, numerator, denominator, _N_CURVES))
    return head + np.concatenate([w, a]).astype(">f4").tobytes()


def _rate(fps: float) -> tuple[int, int]:
    if not math.isfinite(fps) or fps <= 0:
        raise ParameterError(f"fps must be positive, got {fps!r}")
    if float(fps).is_integer():
        return int(fps), 1
    from fractions import Fraction

    ratio = Fraction(fps).limit_denominator(1_000_000)
    return ratio.numerator, ratio.denominator
