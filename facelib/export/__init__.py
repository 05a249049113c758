"""Exports into other tools: glTF 2.0 with morph targets and a skin, ARKit-52 blendshape
curves (and their import), and a static web player.

Loaded on first use (``facelib.export_gltf`` ...); the container needs the ``export`` extra.
"""

from facelib.export.gltf import GltfExport, export_gltf

__all__ = ["GltfExport", "export_gltf"]
