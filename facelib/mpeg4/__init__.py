"""The MPEG-4 facial animation vocabulary: FAP and feature-point tables, FAPU, streams and
``.fap`` files."""

from facelib.mpeg4.fapfile import (
    DIALECTS,
    FapFile,
    format_fap,
    read_fap,
    read_fap_file,
    write_fap,
    write_fap_complete,
)
from facelib.mpeg4.stream import EXPRESSION_FIELDS, VISEME_FIELDS, FapStream
from facelib.mpeg4.tables import (
    ANGLE_UNIT,
    FAPU_NAMES,
    FAPU_SCALE,
    N_FAPS,
    N_STANDARD_FAPS,
    Fap,
    FeaturePoint,
    fap,
    fap_groups,
    fap_table,
    feature_point,
    feature_point_table,
)
from facelib.mpeg4.track import FapTrack

__all__ = [
    "ANGLE_UNIT",
    "DIALECTS",
    "EXPRESSION_FIELDS",
    "FAPU_NAMES",
    "FAPU_SCALE",
    "N_FAPS",
    "N_STANDARD_FAPS",
    "VISEME_FIELDS",
    "Fap",
    "FapFile",
    "FapStream",
    "FapTrack",
    "FeaturePoint",
    "fap",
    "fap_groups",
    "fap_table",
    "feature_point",
    "feature_point_table",
    "format_fap",
    "read_fap",
    "read_fap_file",
    "write_fap",
    "write_fap_complete",
]
