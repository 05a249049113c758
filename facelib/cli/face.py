"""``facelib face setup MESH``: make your own head mesh animatable (landmarks given or
found automatically, the default face definition transferred onto it)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console, UsageError
from facelib.cli.options import COMMON


def add(commands: Any) -> None:
    face = commands.add_parser("face", help="make your own head mesh animatable",
                               parents=[COMMON])
    face_commands = face.add_subparsers(dest="face_command", metavar="ACTION", required=True)
    setup = face_commands.add_parser(
        "setup", help="transfer the default face definition onto a head mesh",
        parents=[COMMON])
    setup.add_argument("mesh", help="head mesh: .obj, .ply, .glb/.gltf, .off or .stl")
    setup.add_argument("--landmarks", help="JSON of feature point -> vertex index or [x, y, z]")
    setup.add_argument("--auto", action="store_true",
                       help="find the landmarks automatically (MediaPipe on a front view of "
                            "the mesh; needs the track and render extras)")
    setup.add_argument("-o", "--output", required=True, help="folder for face.json + face.npz")
    setup.add_argument("--unit", choices=("m", "dm", "cm", "mm", "in"),
                       help="the mesh's length unit (default: guessed from the landmarks)")
    for axis, default in (("up", "+y"), ("forward", "+z")):
        setup.add_argument(f"--{axis}", choices=("+x", "-x", "+y", "-y", "+z", "-z"),
                           help=f"the mesh's {axis} axis (default: guessed from the "
                                f"landmarks; {default} for --auto)")
    setup.add_argument("--part", action="append", default=[], metavar="PART=OBJECT",
                       help="name the file's object for a part (eye_l, eye_r, teeth_upper, "
                            "teeth_lower, tongue), e.g. --part eye_l=LeftEye")
    setup.set_defaults(run=_face_setup)


def _write_found(found: Any, folder: Path, console: Console) -> None:
    """The automatic landmarks as an editable JSON and a picture of where they are."""
    import json

    from facelib.atomic import write_text_atomic
    from facelib.rendering.video import save_png
    from facelib.tracking.head_landmarks import draw_landmarks

    write_text_atomic(folder / "landmarks.json",
                      json.dumps({"landmarks": found.as_json()}, indent=1) + "\n")
    save_png(draw_landmarks(found), folder / "landmarks.png")
    console.status(f"found:     {len(found.points)} feature points (see "
                   f"{folder / 'landmarks.png'}; edit {folder / 'landmarks.json'} and rerun "
                   "with --landmarks to correct them)")


def _face_setup(args: argparse.Namespace, console: Console) -> int:
    from facelib.engine.setup import setup_face
    from facelib.engine.setup.headmesh import load_head_mesh
    from facelib.engine.writer import write_face

    if (args.landmarks is None) == (not args.auto):
        raise UsageError("give either --landmarks L.json or --auto (see docs/own-head.md)")
    bad = [item for item in args.part if "=" not in item]
    if bad:
        raise UsageError(f"--part {bad[0]!r} must be PART=OBJECT, e.g. eye_l=LeftEye")
    started = time.perf_counter()
    parts = dict(item.split("=", 1) for item in args.part)
    mesh = load_head_mesh(args.mesh, parts=parts)
    landmarks: Any = args.landmarks
    found = None
    if args.auto:
        from facelib.tracking.head_landmarks import detect_head_landmarks

        found = detect_head_landmarks(mesh, up=args.up, forward=args.forward)
        landmarks = found.as_json()
    result = setup_face(mesh, landmarks=landmarks, unit=args.unit, up=args.up,
                        forward=args.forward, report=True)
    out = write_face(result.face, Path(args.output) / "face.json", name=Path(args.mesh).stem,
                     source=f"facelib face setup {Path(args.mesh).name}")
    if found is not None:
        _write_found(found, Path(args.output), console)
    _report_setup(args.mesh, mesh, result, console)
    console.status(f"wrote {out} in {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def _report_setup(name: str, mesh: Any, result: Any, console: Console) -> None:
    import numpy as np

    from facelib.mpeg4.tables import FAPU_SCALE

    face = result.face
    console.status(f"mesh:      {name} ({len(mesh.vertices)} vertices, unit {result.unit})")
    if mesh.repairs:
        console.status(f"repaired:  {'; '.join(mesh.repairs)}")
    if not np.allclose(result.rotation, np.eye(3)):
        console.status("oriented:  turned upright (+y up, looking along +z)")
    console.status(f"landmarks: {len(result.landmarks)}, off the surface by at most "
                   f"{result.residual.max() * 1000:.2f} mm")
    own = [p for p in face.parts if p not in result.carried]
    console.status(f"parts:     {', '.join(own)} from the mesh"
                   + (f"; {', '.join(result.carried)} warped into place from the default head"
                      if result.carried else ""))
    console.status("FAPU0 (mm): " + "  ".join(f"{k} {v * FAPU_SCALE * 1000:.2f}"
                                             for k, v in face.fapu.items() if k != "AU"))

