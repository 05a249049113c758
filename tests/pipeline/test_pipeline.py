"""From storyboard to stream: determinism, the thesis example, a golden stream."""

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from facelib import Animation, FapStream, animate, fap, read_fap, run_fdl, write_fap
from facelib.fdl import loads
from facelib.sync import SyncRules

HERE = Path(__file__).parent
ROOT = HERE.parent.parent
DATA = HERE.parent / "data" / "pipeline"
GOLDEN = DATA / "small.golden.fap"
# gaze, blinks, head noise and the face alive between cues (breathing's nostrils, the idle
# micro-movements of brows, lids and lip corners): the seeded parts
ALIVE = SyncRules().alive
NOISY = {*range(19, 27), 48, 49, 50, *(fap(n).id for n in ALIVE.breathing.nostril_flare),
         *(fap(n).id for group in ALIVE.micro for n in group.faps)}


def test_same_seed_same_stream_bit_for_bit():
    a = run_fdl(DATA / "small.fdl")
    b = run_fdl(DATA / "small.fdl")
    assert isinstance(a, Animation)
    assert a.faps == b.faps


def test_another_seed_changes_only_the_noisy_parts():
    a = run_fdl(DATA / "small.fdl")
    c = run_fdl(DATA / "small.fdl", seed=99)
    changed = {int(i) + 1 for i in np.flatnonzero((a.faps.values != c.faps.values).any(0))}
    assert changed
    assert changed <= NOISY


def test_stream_lasts_as_long_as_the_longest_track():
    anim = run_fdl(DATA / "small.fdl")
    assert anim.faps.duration * 1000 >= anim.storyboard.cues_end_ms
    assert anim.faps.duration * 1000 >= anim.visemes[-1].end_ms
    assert anim.tracks["visemes"].n_frames == anim.faps.n_frames


def test_golden_stream():
    """The small storyboard's stream, pinned. After an intended change of the animation,
    regenerate with: FACELIB_REGENERATE=1 pytest tests/pipeline -k golden"""
    stream = run_fdl(DATA / "small.fdl").faps
    if os.environ.get("FACELIB_REGENERATE"):
        write_fap(stream, GOLDEN, dialect="extended")
    golden = read_fap(GOLDEN, strict=True)
    assert golden.n_frames == stream.n_frames
    assert np.array_equal(golden.mask, stream.mask)
    assert np.abs(golden.values - stream.values).max() <= 0.5


def test_expressions_and_visemes_share_the_mouth_by_the_per_fap_weights():
    """Eq. 4.11 with the per-FAP weights of facelib/data/sync.json (the jaw leans on the
    viseme, the lip corners on the expression)."""
    from facelib.sync import SyncRules

    anim = run_fdl(DATA / "small.fdl")
    e, v = anim.tracks["expressions"], anim.tracks["visemes"]
    we, wv = SyncRules.load().mouth_weights()
    col = fap("open_jaw").index
    both = (e.weight[:, col] == 1) & (v.weight[:, col] == 1)
    assert both.any()
    expected = (we[col] * e.values[both, col] + wv[col] * v.values[both, col]) / (we[col] + wv[col])
    assert np.allclose(anim.faps.values[both, col], expected, atol=1e-3)


def test_expression_only_storyboard_returns_to_neutral():
    sb = loads('show { "joy", at = 0, dur = 1 }\nlook { "default", "listening", dur = 1 }')
    anim = animate(sb)
    corner = anim.faps.values[:, fap("raise_l_cornerlip").index]
    assert corner.max() > 100
    corners = next(g for g in SyncRules().alive.micro if g.name == "mouth corners")
    assert abs(corner[-1]) < 4 * corners.sd  # back to the idle micro-movement
    still = animate(sb, rules=SyncRules(alive=None)).faps.values[:, fap("raise_l_cornerlip").index]
    assert still[-1] == 0


def test_thesis_storyboard_runs_end_to_end(tmp_path):
    """The thesis's "hasta la vista" example in its own format, with real speech."""
    pytest.importorskip("pocketsphinx")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        anim = run_fdl(ROOT / "examples" / "hastalavista" / "hastalavista.fdl")
    names = [c.name for c in anim.storyboard.expressions]
    assert names[:3] == ["joy", "sadness", "surprise"]
    assert anim.faps.n_frames == 1601  # the eye script is the longest: 1600 frames at 25 fps
    assert anim.audio is not None and anim.audio.name == "hastalavista.wav"
    spoken = {span.name for span in anim.visemes}
    assert {"aa", "SS"} <= spoken
    out = write_fap(anim.faps, tmp_path / "animation.fap")
    assert read_fap(out).n_frames == 1601
    assert isinstance(anim.faps, FapStream)
