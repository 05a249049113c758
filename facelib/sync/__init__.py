"""The synchronizer: conflict resolution between expressions, visemes and gaze, idle head
motion, and a face alive between cues (breathing, listening, micro-movements)."""

from facelib.sync.alive import AliveRules, Liveliness
from facelib.sync.combine import add_head_noise, blend, close_lids, combine, to_stream
from facelib.sync.noise import perlin1d
from facelib.sync.rules import HeadNoise, SyncRules

__all__ = [
    "AliveRules",
    "HeadNoise",
    "Liveliness",
    "SyncRules",
    "add_head_noise",
    "blend",
    "close_lids",
    "combine",
    "perlin1d",
    "to_stream",
]
