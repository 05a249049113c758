"""``facelib serve``: the live WebSocket server (:mod:`facelib.live.server`)."""

from __future__ import annotations

import argparse
import asyncio
import os
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON


def add(commands: Any) -> None:
    serve = commands.add_parser("serve", help="serve live sessions over WebSocket",
                                parents=[COMMON])
    serve.add_argument("--host", default="127.0.0.1",
                       help="address to listen on (default 127.0.0.1; any other needs a token)")
    serve.add_argument("--port", type=int, default=8765, help="port (default 8765)")
    serve.add_argument("--token-env", default="FACELIB_TOKEN",
                       help="environment variable holding the token clients must send "
                            "(default FACELIB_TOKEN)")
    serve.add_argument("--max-sessions", type=int, default=16,
                       help="sessions at once (default 16)")
    serve.add_argument("--livelink", metavar="HOST:PORT",
                       help="also send every session's frames as Live Link Face UDP packets "
                            "(Unreal's Live Link; port 11111 if left out)")
    serve.add_argument("--vmc", metavar="HOST:PORT",
                       help="also send every session's frames as VMC protocol OSC bundles "
                            "(VSeeFace, VNyan; port 39539 if left out)")
    serve.set_defaults(run=_serve)


def _serve(args: argparse.Namespace, console: Console) -> int:
    from facelib.live.server import ServerOptions, serve

    options = ServerOptions(host=args.host, port=args.port,
                            token=os.environ.get(args.token_env) or None,
                            max_sessions=args.max_sessions, livelink=args.livelink,
                            vmc=args.vmc)
    print(f"facelib serve: ws://{options.host}:{options.port}"
          f"{' (token required)' if options.token else ''}", flush=True)
    asyncio.run(serve(options))
    return EXIT_OK
