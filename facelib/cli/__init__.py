"""The ``facelib`` command. Every subcommand is a thin layer over the Python API.

One module per subcommand (``info``, ``check``, ``run``, ``render`` with ``play``, ``view``,
``plot``, ``align``, ``listing``, ``dataset``, ``evaluate``, ``track``, ``export``,
``import_arkit``, ``face``), each with ``add(commands)`` declaring its arguments next to the
function that does the work; :mod:`facelib.cli.dispatch` builds the parser and runs a command
(signals, a closed stdout, errors and warnings as one line each); :mod:`facelib.cli.console`,
:mod:`facelib.cli.options` and :mod:`facelib.cli.outputs` hold what the commands share.

Exit codes (also in ``docs/getting-started.md``): 0 success; 1 an input or a job failed
(the message names file, line or clip); 2 usage error; 130 interrupted (Ctrl-C); 141 the
reader of stdout went away (``| head``); 143 terminated (SIGTERM). Interrupted and
terminated runs leave no temporary files behind.
"""

from __future__ import annotations

from facelib.cli.console import (
    EXIT_ERROR,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_PIPE,
    EXIT_TERMINATED,
    EXIT_USAGE,
)
from facelib.cli.dispatch import main

__all__ = ["EXIT_ERROR", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_PIPE", "EXIT_TERMINATED",
           "EXIT_USAGE", "main"]
