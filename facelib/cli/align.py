"""``facelib align AUDIO``: speech audio aligned to visemes, as JSON, TSV or an FDL
sentence."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON
from facelib.cli.outputs import STDOUT, check_suffix, emit_text
from facelib.errors import FileError

METHODS = ("auto", "acoustic", "words", "phones")
"""``--recognize``'s choices: :data:`facelib.speech.recognize.METHODS`."""


def add(commands: Any) -> None:
    align = commands.add_parser("align", help="align speech audio to visemes",
                                parents=[COMMON])
    align.add_argument("audio", help="speech audio (any format soundfile reads)")
    align.add_argument("--text", help="the transcript (omit it to recognise the speech: see "
                                      "--recognize)")
    align.add_argument("--text-file", help="a file holding the transcript")
    align.add_argument("-o", "--output", required=True,
                       help="OUT.json, OUT.tsv or OUT.sb; - writes --format to stdout")
    align.add_argument("--format", choices=("json", "tsv", "sb"), default="json",
                       help="the format written to stdout by -o - (default json)")
    align.add_argument("--fps", type=float, default=25.0, help="frame rate of a .sb script")
    align.add_argument("--lang", default="en",
                       help="language of the speech (with --text, en: pocketsphinx, others: "
                            "DTW against espeak-ng; without it, see --recognize)")
    align.add_argument("--recognize", "--method", choices=METHODS, default="auto",
                       help="without --text: auto (the best measured path for --lang: "
                            "English words decoded then aligned, the phone loop where no word "
                            "is heard; any other language the acoustic model), acoustic (the "
                            "acoustic viseme model, any language), words (no fallback) or "
                            "phones (the phone loop alone)")
    align.set_defaults(run=_align)


def _align(args: argparse.Namespace, console: Console) -> int:
    import json

    from facelib.speech.recognize import recognize
    from facelib.visemes import align, align_dtw, with_visemes
    from facelib.visemes.scripts import (
        timeline_to_json,
        timeline_to_sentence,
        timeline_to_tsv,
    )

    check_suffix(args.output, (".json", ".tsv", ".sb", ".lua", ".fdl"), "align")
    kind = args.format if args.output == STDOUT else Path(args.output).suffix[1:].lower()
    kind = "sb" if kind in ("lua", "fdl") else kind
    text = args.text
    if args.text_file is not None:
        try:
            text = Path(args.text_file).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise FileError(f"cannot read the transcript: {exc}", path=args.text_file) from exc
    if text is None:
        timeline = with_visemes(recognize(args.audio, language=args.lang,
                                          method=args.recognize))
    elif args.lang.lower().startswith("en"):
        timeline = align(args.audio, text)
    else:
        timeline = align_dtw(args.audio, text, lang=args.lang)
    formatted = {
        "json": lambda: json.dumps(timeline_to_json(timeline), indent=1) + "\n",
        "tsv": lambda: timeline_to_tsv(timeline),
        "sb": lambda: timeline_to_sentence(timeline, fps=args.fps),
    }[kind]()
    emit_text(formatted, args.output, console, "")
    return EXIT_OK

