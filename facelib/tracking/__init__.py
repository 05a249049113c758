"""Performance-driven animation: a video of a face, or tracked landmarks, to a FapStream.

The first seed's section 4.3 (user FAPU eq. 4.12-4.15, displacements eq. 4.16, FAP
relationships eq. 4.17) with a rigid head fit, lids, gaze and One Euro smoothing on top.
Markerless tracking uses MediaPipe's face mesh (the ``track`` extra); landmark files from
other trackers need only numpy.

Submodules: :mod:`~facelib.tracking.layouts` (tracker points -> feature points),
:mod:`~facelib.tracking.mediapipe` (478 landmarks in RGB images),
:mod:`~facelib.tracking.faps` (landmarks -> FapStream: ``measure_faps``,
``landmarks_to_faps``), :mod:`~facelib.tracking.headframe` (landmarks in the neutral
head's frame), :mod:`~facelib.tracking.userfapu` (eq. 4.12-4.15),
:mod:`~facelib.tracking.pose` (head pose), :mod:`~facelib.tracking.observation` (the
learned landmarks-to-FAPs model), :mod:`~facelib.tracking.rigfit` (the avatar's
rig fitted to the landmark motion), :mod:`~facelib.tracking.embedding` (landmarks on a
mesh), :mod:`~facelib.tracking.relations` (eq. 4.17), :mod:`~facelib.tracking.smoothing`
(One Euro), :mod:`~facelib.tracking.video` (video in), :mod:`~facelib.tracking.files`
(other trackers' files), :mod:`~facelib.tracking.mirror` (the Virtual Mirror),
:mod:`~facelib.tracking.closedloop` (render, track, compare). See
``docs/performance-driven.md``.
"""
