"""Performance-driven animation: a video of a face, or tracked landmarks, to a FapStream.

The first seed's section 4.3 (user FAPU eq. 4.12-4.15, displacements eq. 4.16, FAP
relationships eq. 4.17) with a rigid head fit, lids, gaze and One Euro smoothing on top.
Markerless tracking uses MediaPipe's face mesh (the ``track`` extra); landmark files from
other trackers need only numpy.

Submodules: :mod:`~facelib.tracking.layouts` (tracker points -> feature points),
:mod:`~facelib.tracking.mediapipe` (478 landmarks in RGB images).
"""
