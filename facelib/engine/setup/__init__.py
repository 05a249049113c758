"""Face set-up: a head mesh of one's own made animatable from a few landmarks.

:mod:`~facelib.engine.setup.fit` is the entry (``setup_face``, ``read_landmarks``); it reads
the mesh (:mod:`~facelib.engine.setup.headmesh`), fits the thin-plate spline
(:mod:`~facelib.engine.setup.tps`), transfers the face definition
(:mod:`~facelib.engine.setup.transfer`) and refits the upper lids
(:mod:`~facelib.engine.setup.eyelids`).
"""

from facelib.engine.setup.fit import UNITS, FaceSetup, read_landmarks, setup_face
from facelib.engine.setup.fit import set_up_face as set_up_face  # the older name, kept

__all__ = ["UNITS", "FaceSetup", "read_landmarks", "setup_face"]
