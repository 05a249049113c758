"""Animate a storyboard from Python in five lines: run it, write the .fap, render a video."""

import facelib

animation = facelib.run_fdl("examples/hello/hello.fdl")
facelib.write_fap(animation.faps, "out/hello_api.fap")
facelib.render(animation, out="out/hello_api.mp4")
print(animation.faps, "->", "out/hello_api.mp4")
