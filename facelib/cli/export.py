"""``facelib export SOURCE``: glTF (.glb), ARKit curves (.csv/.json), a VRM avatar (.vrm), a
VRM animation (.vrma) or a web page."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console, UsageError
from facelib.cli.options import COMMON, FACE_HELP, add_hair, output_face, read_source
from facelib.cli.outputs import check_suffix


def add(commands: Any) -> None:
    export = commands.add_parser(
        "export", parents=[COMMON],
        help="export to glTF (.glb), ARKit curves (.csv/.json), VRM (.vrm, .vrma) or a web page")
    export.add_argument("source", help="STORY.fdl or FILE.fap")
    export.add_argument("-o", "--output",
                        help="OUT.glb (glTF), OUT.vrma (a VRM 1.0 animation for any VRM avatar), "
                             "or with --arkit OUT.csv (Live Link Face) / OUT.json")
    export.add_argument("--arkit", action="store_true",
                        help="write ARKit-52 blendshape curves instead of glTF")
    export.add_argument("--targets", choices=("fap", "arkit"), default="fap",
                        help="glTF morph targets: one per FAP basis vector (fap, the default) or "
                             "the 52 ARKit-named shapes of the head (arkit; also for --html, "
                             "which the live page of examples/live needs)")
    export.add_argument("--html", metavar="DIR", help="also write a web player into DIR")
    export.add_argument("--vrm", metavar="OUT.vrm",
                        help="also write a VRM 1.0 avatar of the head (expression presets aa ... "
                             "lookRight, humanoid, look-at; no animation)")
    export.add_argument("--face", help=f"{FACE_HELP} (default: the bundled head)")
    add_hair(export)
    export.add_argument("--audio", help="speech audio to put beside the .glb / in the page")
    export.add_argument("--seed", type=int)
    export.set_defaults(run=_export)

def _export(args: argparse.Namespace, console: Console) -> int:
    import numpy as np

    from facelib import export

    if args.output is None and args.html is None and args.vrm is None:
        raise UsageError("give -o OUT.glb (or OUT.vrma, or OUT.csv / OUT.json with --arkit), "
                         "--html DIR, --vrm OUT.vrm, or several")
    if args.vrm is not None:
        check_suffix(args.vrm, (".vrm",), "export --vrm")
    if args.output is not None:
        check_suffix(args.output, (".csv", ".json") if args.arkit else
                     (".glb", ".vrma", ".csv", ".json"), "export")
    face = output_face(args, None)  # exports ignore a storyboard's face, not its hair
    if face is not None and not hasattr(face, "vertices"):
        from facelib.engine import load_face

        face = load_face(face)
    source = read_source(args.source, args.seed, console)
    if args.output is not None:
        suffix = Path(args.output).suffix.lower()
        if args.arkit or suffix in (".csv", ".json"):
            curves = export.export_arkit(source, args.output, face=face)
            moving = curves.relative[curves.relative > 0]
            fit = (f"; fit residual RMS {1000 * float(curves.residual.mean()):.2f} mm, "
                   f"median relative {float(np.median(moving)):.2f}" if moving.size else "")
            console.status(f"wrote {args.output} ({curves.n_frames} frames of 52 ARKit "
                           f"weights{fit})")
        elif suffix == ".vrma":
            motion = export.export_vrma(source, args.output)
            console.status(f"wrote {motion.path} (VRM animation: {motion.n_frames} frames of "
                           f"{len(motion.presets)} expressions, head and look-at)")
        else:
            result = export.export_gltf(source, args.output, face=face, audio=args.audio,
                                        targets=args.targets)
            audio = f", audio {result.audio}" if result.audio else ""
            console.status(f"wrote {result.path} ({len(result.names)} morph targets, "
                           f"{result.n_frames} frames{audio})")
    if args.vrm is not None:
        avatar = export.export_vrm(source, args.vrm, face=face)
        console.status(f"wrote {avatar.path} (VRM 1.0: {len(avatar.presets)} expression "
                       f"presets, {len(avatar.bones)} humanoid bones)")
    if args.html is not None:
        page = export.export_html(source, args.html, face=face, audio=args.audio,
                                   targets=args.targets)
        console.status(f"wrote {page.page} (open it in a browser)")
    return EXIT_OK
