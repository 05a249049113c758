"""Rendering a storyboard with characters: the two-shot side by side, close shots cut in by
camera cues, and each character's .fap showing what it does in the video."""

import numpy as np
import pytest

from facelib import animate_scene, fap, fdl, read_fap, render, render_scene
from facelib.clip import make_scene_clip
from facelib.mpeg4 import write_fap_complete

pytestmark = pytest.mark.render

W, H = 160, 120
# stored visemes: the mouth moves without speech synthesis
TALK = '{ {"sil", 0.1}, {"aa", 0.2}, {"PP", 0.12}, {"aa", 0.2}, {"oh", 0.2}, {"sil", 0.2} }'
CAST = '''characters {
  ada = { hair = "long" },
  ben = { hair = "short" },
}
'''


def _scene(body):
    return animate_scene(fdl.loads(CAST + body, name="scene.fdl"))


@pytest.fixture(scope="module")
def two_shot():
    scene = _scene(f'say {{ who = "ada", visemes = {TALK}, at = 0 }}\n'
                   'look { who = "ben", "default", dur = 1 }\n')
    return scene, render_scene(scene, width=W, height=H, progress=False)


def _mouth_box(first, stop):
    """Rows and columns around the mouth in a two-shot column (render_shots.json's two-shot
    puts the chin near mid-height)."""
    width = stop - first
    return slice(int(0.40 * H), int(0.56 * H)), slice(first + int(0.3 * width),
                                                       first + int(0.7 * width))


def test_the_two_shot_shows_both_and_only_the_speaker_moves_its_mouth(two_shot):
    scene, frames = two_shot
    assert frames.shape == (scene.n_frames, H, W, 3)
    jaw = scene.parts["ada"].faps.values[:, fap("open_jaw").index]
    rest, open_ = int(np.argmin(np.abs(jaw[:3]))), int(np.argmax(jaw))
    assert jaw[open_] > 300
    change = {}
    for name, (first, stop) in zip(("ada", "ben"), ((0, W // 2), (W // 2, W)), strict=True):
        rows, cols = _mouth_box(first, stop)
        a = frames[rest, rows, cols].astype(float)
        b = frames[open_, rows, cols].astype(float)
        change[name] = np.abs(a - b).mean()
        # somebody is in each column: skin, not background
        assert frames[rest, rows, cols].std() > 10
    assert change["ada"] > 4.0 * change["ben"], change
    assert change["ada"] > 3.0


def test_camera_cues_cut_between_shot_and_reverse_shot(tmp_path):
    scene = _scene(f'say {{ who = "ben", visemes = {TALK}, at = 0.4 }}\n'
                   'camera { who = "ben", at = 0.4 }\n'
                   'camera { who = "ada", at = 0.8 }\n'
                   'camera { "two_shot", at = 1.2 }\n')
    frames = render_scene(scene, width=W, height=H, progress=False).astype(float)

    def jump(i):
        return np.abs(frames[i] - frames[i - 1]).mean()

    cuts = [10, 20, 30]  # 0.4 s, 0.8 s, 1.2 s at 25 fps
    within = max(jump(i) for i in range(1, len(frames)) if i not in cuts)
    for i in cuts:
        assert jump(i) > 4 * within, (i, jump(i), within)
    # the two-shot's halves are the characters; ben's close shot is not ada's
    assert np.abs(frames[15] - frames[25]).mean() > 10
    assert np.abs(frames[5] - frames[35]).mean() < within * 3

    # each character's .fap, played on its face, is what the close shot shows
    clip = make_scene_clip(scene)
    for name, shot in (("ben", range(10, 20)), ("ada", range(20, 30))):
        written = write_fap_complete(scene.parts[name].faps, tmp_path / f"scene.{name}.fap")
        back = read_fap(written[-1])
        face = clip.clip_of(name).face_or_default()
        alone = render(back[shot.start:shot.stop], face=face, width=W, height=H,
                       progress=False).astype(float)
        assert np.abs(alone - frames[shot.start:shot.stop]).mean() < 1.0, name
