"""Exports into other tools: glTF 2.0 with morph targets and a skin, VRM 1.0 avatars and
animations, ARKit-52 blendshape curves (Live Link Face CSV, JSON) and their import, and a
static web player.

Loaded on first use (``facelib.export_gltf`` ...); the glTF container needs the ``export``
extra (pygltflib), the web player the npm build (``make web``).
"""

from facelib.export.arkit import (
    ANGLE_NAMES,
    ArkitCurves,
    arkit_names,
    from_arkit,
    live_link_names,
    to_arkit,
)
from facelib.export.arkit_roundtrip import RegionResidual, arkit_residuals
from facelib.export.gltf import GltfExport, export_gltf
from facelib.export.livelink import (
    export_arkit,
    import_arkit,
    read_arkit_json,
    read_live_link_csv,
    write_arkit_json,
    write_live_link_csv,
)
from facelib.export.vrm import VrmExport, export_vrm
from facelib.export.vrma import VrmaExport, export_vrma
from facelib.export.web import WebExport, export_html

__all__ = [
    "ANGLE_NAMES", "ArkitCurves", "GltfExport", "RegionResidual", "VrmExport", "VrmaExport",
    "WebExport",
    "arkit_names", "arkit_residuals", "export_arkit", "export_gltf", "export_html", "export_vrm",
    "export_vrma", "from_arkit", "import_arkit", "live_link_names", "read_arkit_json",
    "read_live_link_csv", "to_arkit", "write_arkit_json", "write_live_link_csv",
]

