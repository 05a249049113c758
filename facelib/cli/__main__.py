"""``python -m facelib.cli``: the ``facelib`` command."""

import sys

from facelib.cli.dispatch import main

sys.exit(main())
