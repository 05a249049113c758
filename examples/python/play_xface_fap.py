"""Play a .fap file written by another MPEG-4 tool (Xface style: floats, CRLF) on the
default head, and save it again in the standard profile every player reads.

    python examples/python/play_xface_fap.py [OUT.mp4]
"""

import sys

import facelib

stream = facelib.read_fap("examples/fap/xface_smile.fap")
print(stream, "active FAPs:", stream.active_faps())
facelib.write_fap(stream, "out/xface_smile_standard.fap")
out = sys.argv[1] if len(sys.argv) > 1 else "out/xface_smile.mp4"
facelib.render(stream, out=out, width=480, height=360)
print("wrote", out)
