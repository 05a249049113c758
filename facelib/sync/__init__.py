"""The synchronizer: conflict resolution between expressions, visemes and gaze, and idle
head motion."""

from facelib.sync.combine import add_head_noise, blend, close_lids, combine, to_stream
from facelib.sync.noise import perlin1d
from facelib.sync.rules import HeadNoise, SyncRules

__all__ = [
    "HeadNoise",
    "SyncRules",
    "add_head_noise",
    "blend",
    "close_lids",
    "combine",
    "perlin1d",
    "to_stream",
]
