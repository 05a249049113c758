"""A storyboard with characters animates each of them as a storyboard of one face: the
speaker's mouth moves, the listener's stays near rest but it blinks, breathes and looks at
the speaker; both voices are on one soundtrack; each one's .fap is its stream."""

import numpy as np
import pytest

from facelib import animate, animate_scene, fap, fdl, read_fap
from facelib.cli import main
from facelib.errors import ParameterError

pytestmark = pytest.mark.speech  # the characters' speech is synthesized
pytest.importorskip("espeakng_loader")

DIALOGUE = '''characters {
  ada = { hair = "long" },
  ben = { hair = "short" },
}
say { who = "ada", "Good morning, Ben. Did you sleep well?", at = 0.2 }
say { who = "ben", "Not at all, Ada. The neighbours had a party.", at = 2.8 }
camera { who = "ben", at = 2.7 }
camera { "two_shot", at = 5.6 }
'''

MOUTH = ("open_jaw", "lower_t_midlip", "raise_b_midlip", "stretch_l_cornerlip",
         "stretch_r_cornerlip", "lower_t_lip_lm", "raise_b_lip_lm")


@pytest.fixture(scope="module")
def scene():
    return animate_scene(fdl.loads(DIALOGUE, name="dialogue.fdl"))


def _speaking(animation):
    frames = np.zeros(animation.faps.n_frames, bool)
    for span in animation.visemes:
        if span.name != "sil":
            frames[int(span.start_ms * 25 / 1000):int(span.end_ms * 25 / 1000)] = True
    return frames


def test_every_character_has_a_stream_over_the_same_frames(scene):
    ada, ben = scene.parts["ada"], scene.parts["ben"]
    assert list(scene.parts) == ["ada", "ben"]
    assert ada.faps.n_frames == ben.faps.n_frames == scene.n_frames
    assert ben.visemes[-1].end_ms <= scene.n_frames * 40 + 40  # the longer part sets it


@pytest.mark.parametrize(("speaker", "listener"), [("ada", "ben"), ("ben", "ada")])
def test_only_the_speaker_moves_its_lips(scene, speaker, listener):
    talk = _speaking(scene.parts[speaker])
    assert talk.sum() > 25
    for name in MOUTH:
        k = fap(name).index
        said = np.abs(scene.parts[speaker].faps.values[talk, k]).max()
        heard = np.abs(scene.parts[listener].faps.values[talk, k]).max()
        if name == "open_jaw":
            assert said > 300
        assert heard <= max(0.1 * said, 40.0), (name, said, heard)


def test_the_listener_stays_alive_and_they_look_at_each_other(scene):
    yaw = fap("head_yaw").index
    for name, side in (("ada", 1.0), ("ben", -1.0)):
        anim = scene.parts[name]
        blinks = [e for e in anim.gaze_events if type(e).__name__ == "Blink"]
        assert len(blinks) >= 1, name
        head = anim.faps.values[:, yaw]
        assert side * np.median(head) > 0.15 * 1e5  # ada (left) turns to her left: to ben
        assert np.ptp(head) > 500  # and keeps moving (idle motion, listening nods)
    ada_pitch = scene.parts["ada"].faps.values[:, fap("head_pitch").index]
    assert np.std(np.diff(ada_pitch)) > 0  # breathing / idle motion never stops


def test_both_voices_are_on_one_soundtrack(scene):
    audio = scene.speech_audio
    rate = audio.sample_rate
    ada, ben = scene.parts["ada"], scene.parts["ben"]
    assert audio.samples.size >= round(2.8 * rate) + ben.speech_audio.samples.size - 1
    for part in (ada, ben):
        start = round(part.audio_offset * rate)
        own = part.speech_audio.samples
        np.testing.assert_allclose(audio.samples[start:start + own.size], own, atol=1e-6)
    assert np.abs(audio.samples[: round(0.2 * rate)]).max() == 0.0


def test_a_storyboard_of_one_face_is_refused_by_animate_scene_and_the_other_way_round():
    with pytest.raises(ParameterError, match="names no characters"):
        animate_scene(fdl.loads('show { "joy", dur = 1 }'))
    with pytest.raises(ParameterError, match=r"names characters \(ada, ben\)"):
        animate(fdl.loads(DIALOGUE))


def test_run_writes_one_fap_per_character_that_reads_back_as_its_stream(scene, tmp_path):
    story = tmp_path / "dialogue.fdl"
    story.write_text(DIALOGUE)
    assert main(["run", str(story), "-o", str(tmp_path / "out.fap")]) == 0
    for name, anim in scene.parts.items():
        back = read_fap(tmp_path / f"out.{name}.fap")
        assert back.n_frames == anim.faps.n_frames
        standard = slice(0, 68)
        np.testing.assert_allclose(back.values[:, standard], anim.faps.values[:, standard],
                                   atol=0.51)
    jaw = fap("open_jaw").index
    ada, ben = (read_fap(tmp_path / f"out.{n}.fap").values[:, jaw] for n in ("ada", "ben"))
    first_turn = _speaking(scene.parts["ada"])
    assert ada[first_turn].max() > 300 and np.abs(ben[first_turn]).max() < 40


def test_the_scene_is_the_same_for_the_same_seed_and_differs_for_another():
    one = animate_scene(fdl.loads(DIALOGUE), seed=3)
    two = animate_scene(fdl.loads(DIALOGUE), seed=3)
    other = animate_scene(fdl.loads(DIALOGUE), seed=4)
    for name in ("ada", "ben"):
        assert one.parts[name].faps == two.parts[name].faps
        assert one.parts[name].faps != other.parts[name].faps


def test_commands_that_play_one_face_refuse_characters_clearly(tmp_path, capsys):
    story = tmp_path / "dialogue.fdl"
    story.write_text(DIALOGUE)
    assert main(["plot", str(story), "-o", str(tmp_path / "x.png")]) != 0
    assert "names characters (ada, ben)" in capsys.readouterr().err
    assert main(["run", str(story), "-o", "-"]) != 0
    assert "one .fap per character" in capsys.readouterr().err


def test_a_character_speaks_several_turns_on_one_stream_and_soundtrack():
    scene = animate_scene(fdl.loads(DIALOGUE + 'say { who = "ada", "Coffee, then?", at = 6 }'))
    ada, ben = scene.parts["ada"], scene.parts["ben"]
    jaw = fap("open_jaw").index
    starts = [s.start_ms for s in ada.visemes if s.name != "sil"]
    assert min(starts) < 1000 and max(starts) > 6000  # both of her turns
    times = np.arange(scene.n_frames) * 40
    second = (times > 6100) & (times < 7000)
    assert ada.faps.values[second, jaw].max() > 300
    assert np.abs(ben.faps.values[second, jaw]).max() < 40
    # her two turns are one voice from her first turn on, both on the soundtrack
    assert ada.audio is None and ada.audio_offset == pytest.approx(0.2)
    rate = scene.speech_audio.sample_rate
    late = scene.speech_audio.samples[round(6.1 * rate):round(7.0 * rate)]
    assert np.sqrt(np.mean(late ** 2)) > 0.02
