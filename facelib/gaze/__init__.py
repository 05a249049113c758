"""Eye behaviour: statistical saccades (Eyes Alive), expressive gaze behaviours, blinks,
smooth pursuit, lid-eye and head-eye coordination (thesis 4.2.1).

``animate`` turns eye-behaviour cues into a FapTrack on FAPs 19-26 and 48-50 plus an event
log; ``simulate`` runs one behaviour for checking; ``pursue`` follows a moving target.
"""

from facelib.gaze.animate import GAZE_FAPS, GazeAnimation, animate, pursue, simulate
from facelib.gaze.behaviours import BoundBehaviour, behaviour_library, bind_behaviour
from facelib.gaze.events import Blink, GazeEvent, HeadMove, Saccade

__all__ = [
    "GAZE_FAPS",
    "Blink",
    "BoundBehaviour",
    "GazeAnimation",
    "GazeEvent",
    "HeadMove",
    "Saccade",
    "animate",
    "behaviour_library",
    "bind_behaviour",
    "pursue",
    "simulate",
]
