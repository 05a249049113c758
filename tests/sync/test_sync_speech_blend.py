"""Per-FAP mouth weights and fades (issue 14, items 6 and 7), on real storyboards."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib import engine, fap, run_fdl
from facelib.sync import SyncRules, blend

ROOT = Path(__file__).parent.parent.parent
CORNERS = [fap(n).index for n in ("raise_l_cornerlip", "raise_r_cornerlip")]
JAW = fap("open_jaw").index


@pytest.fixture(scope="module")
def hello():
    return run_fdl(ROOT / "examples" / "hello" / "hello.fdl")


def test_per_fap_weights_come_from_the_data_file():
    rules = SyncRules.load()
    e, v = rules.mouth_weights()
    assert e.shape == v.shape == (84,)
    assert e[CORNERS[0]] / (e[CORNERS[0]] + v[CORNERS[0]]) >= 0.75  # the smile leans on E
    assert v[JAW] / (e[JAW] + v[JAW]) >= 0.9  # the opening leans on the viseme
    untouched = fap("tongue_roll").index
    assert (e[untouched], v[untouched]) == rules.mouth


@pytest.mark.speech  # the demo's speech is force-aligned
def test_smile_keeps_most_of_its_corner_lift_while_speaking(hello):
    """Joy 'with the word' (2.7-4.2 s, full between its ramps) while the mouth talks."""
    e, v, out = hello.tracks["expressions"], hello.tracks["visemes"], hello.faps
    n = min(e.n_frames, v.n_frames)
    t = np.arange(n) / out.fps
    both = (t > 3.0) & (t < 3.8) & (v.weight[:n, JAW] > 0.99) & (e.weight[:n, CORNERS[0]] > 0.99)
    assert both.sum() >= 10
    kept = out.values[:n][both][:, CORNERS].mean() / e.values[:n][both][:, CORNERS].mean()
    assert kept >= 0.7


@pytest.mark.speech  # the demo's speech is force-aligned
def test_every_bilabial_of_the_demo_closes_the_lips(hello):
    face = engine.load_face(None)
    fp = face.feature_points
    rest = face.deform_frame(np.zeros(84, np.float32))
    rest_gap = rest[fp["2.2"], 1] - rest[fp["2.3"], 1]  # inner upper minus inner lower lip
    bilabials = [s for s in hello.visemes if s.name == "PP"]
    assert len(bilabials) >= 2
    for span in bilabials:
        k = round((span.start_ms + span.end_ms) / 2 * hello.faps.fps / 1000)
        moved = face.deform_frame(hello.faps.values[k])
        gap = moved[fp["2.2"], 1] - moved[fp["2.3"], 1]
        assert gap <= rest_gap + 0.5e-3, (span, gap)  # metres: within half a millimetre


def test_a_lone_viseme_fades_out_instead_of_popping():
    """Speech that ends on an open vowel with nothing else driving the jaw: the jaw must
    ease back to neutral with the envelope (it used to hold its value while the weight was
    above 0 and then drop to 0 in one frame)."""
    from facelib.cues import SpeechSpec, VisemeCue
    from facelib.mpeg4.track import FapTrack
    from facelib.sync import combine
    from facelib.visemes import animate

    cues = (VisemeCue("silence", 0, 200), VisemeCue("A", 200, 240), VisemeCue("Q", 440, 40),
            VisemeCue("A", 480, 300))
    speech = animate(SpeechSpec(visemes=cues), fps=25)
    n = speech.track.n_frames + 10
    track = FapTrack(25, np.pad(speech.track.values, ((0, 10), (0, 0))),
                     np.pad(speech.track.weight, ((0, 10), (0, 0))))
    empty = FapTrack.empty(n, fps=25)
    out = combine(expressions=empty, visemes=track, gaze=empty,
                  rules=SyncRules(head_noise=None))
    jaw = out.values[:, JAW]
    assert jaw.max() > 300
    assert np.abs(np.diff(jaw)).max() < 0.5 * jaw.max()  # a pop is the whole value
    assert jaw[-1] == pytest.approx(0.0, abs=1e-3)


def test_per_fap_blend_is_eq_4_11_where_the_table_says_1_3():
    from facelib import FapTrack

    values = np.zeros((1, 84), np.float32)
    values[0, [JAW, CORNERS[0]]] = (100, 100)
    ones = np.ones((1, 84), np.float32)
    e = FapTrack(25, values, ones)
    v = FapTrack(25, values * 3, ones)
    we, wv = np.full(84, 1.0), np.full(84, 3.0)
    we[CORNERS[0]], wv[CORNERS[0]] = 4.0, 1.0
    out = blend(e, v, weight_a=we, weight_b=wv)
    assert out.values[0, JAW] == pytest.approx((100 + 3 * 300) / 4)
    assert out.values[0, CORNERS[0]] == pytest.approx((4 * 100 + 300) / 5)


@pytest.mark.speech  # the demo's speech is force-aligned
def test_speech_nods_on_stressed_syllables_are_seeded_and_sized(hello):
    """Issue 14 item 8: nods of 2-5 degrees on the jaw-opening peaks while speaking."""
    import dataclasses

    from facelib import animate
    from facelib.mpeg4.tables import ANGLE_UNIT
    from facelib.sync.nods import Nods, accents

    rules = SyncRules.load()
    assert rules.speech_nods is not None
    still = animate(hello.storyboard, rules=dataclasses.replace(rules, speech_nods=None))
    again = animate(hello.storyboard)
    assert again.faps == hello.faps  # deterministic
    pitch = fap("head_pitch").index
    nod = np.rad2deg((hello.faps.values[:, pitch] - still.faps.values[:, pitch]) * ANGLE_UNIT)
    assert 2.0 <= nod.max() <= 5.0
    strength = accents(hello.tracks["visemes"], nods=Nods())
    beats = np.flatnonzero(strength)
    assert len(beats) >= 4
    # every accent has its nod around it (unless gaze turns the head then), and the nods lie
    # around accents
    gaze_head = hello.tracks["gaze"].weight[:, pitch]
    for i in beats[gaze_head[beats] == 0]:
        assert nod[max(i - 3, 0): i + 4].max() > 0.5 * strength[i] * Nods().pitch_deg
    quiet = np.ones(nod.size, bool)
    for i in beats:
        quiet[max(i - 6, 0): i + 7] = False
    assert np.abs(nod[quiet]).max() < 0.05
