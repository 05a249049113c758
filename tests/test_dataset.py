"""Synthetic datasets: seeded draws, the documented layout, a real Dask cluster giving the
same bytes as the local pool, and a killed run resumed."""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from facelib import run_fdl
from facelib.dataset import DatasetSpec, draw_clip, generate, load_spec
from facelib.errors import FacelibError
from facelib.mpeg4 import read_fap

ROOT = Path(__file__).resolve().parents[1]
HAS_RENDER = importlib.util.find_spec("pyrender") is not None

SPEC = """\
clips = 6
seed = 5
seconds = 0.24
width = 48
height = 48
media = "png"

[expressions]
per_clip = [1, 2]
intensity = [0.6, 1.0]

[gaze]
behaviours = ["default", "distress"]

[speech]
texts = ["Hello there.", "Good morning."]
probability = 0.5

[head]
yaw_deg = [-20, 20]

[camera]
zoom = [0.9, 1.3]
"""


def tree(folder: Path) -> dict[str, str]:
    """relative path -> sha256 of every file under ``folder``."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture
def spec_file(tmp_path: Path) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(SPEC)
    return path


def test_draws_are_seeded_per_clip_and_within_the_ranges(spec_file):
    spec = load_spec(spec_file)
    assert draw_clip(spec, 3) == draw_clip(spec, 3)
    draws = [draw_clip(spec, i) for i in range(50)]
    assert len({d.seed for d in draws}) == 50
    assert all(-20 <= d.head_deg[1] <= 20 and 0.9 <= d.zoom <= 1.3 for d in draws)
    assert {d.behaviour for d in draws} == {"default", "distress"}
    assert 10 < sum(d.text is not None for d in draws) < 40
    assert all(1 <= len(d.expressions) <= 2 for d in draws)
    other = DatasetSpec(**{**spec.__dict__, "seed": 6})
    assert draw_clip(other, 3) != draw_clip(spec, 3)


def test_spec_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("clips = 3\nclip_seconds = 2\n")
    with pytest.raises(FacelibError, match=r"bad.toml: unknown setting 'clip_seconds'"):
        load_spec(bad)
    bad.write_text("clips = 3\n[camera]\nzoom = [2, 1]\n")
    with pytest.raises(FacelibError, match=r"bad.toml: camera.zoom must be a range"):
        load_spec(bad)


@pytest.mark.render
@pytest.mark.slow
@pytest.mark.skipif(not HAS_RENDER, reason="needs the render extra")
def test_layout_labels_and_landmarks(tmp_path, spec_file):
    spec = load_spec(spec_file)
    spec = DatasetSpec(**{**spec.__dict__, "clips": 1, "source": ""})
    report = generate(spec, tmp_path / "one", jobs=1)
    assert (report.written, report.skipped, report.failed) == (1, 0, ())
    clip = tmp_path / "one" / "clip_000000"
    assert sorted(p.name for p in clip.iterdir()) == [
        "clip.fap", "clip.fdl", "frames", "frames.jsonl", "meta.json"]
    rows = [json.loads(line) for line in (clip / "frames.jsonl").read_text().splitlines()]
    stream = read_fap(clip / "clip.fap")
    assert len(rows) == stream.n_frames == len(list((clip / "frames").glob("*.png"))) == 6
    draw = draw_clip(spec, 0)
    # the labels' head yaw (degrees) is the storyboard's own head motion plus the drawn
    # offset, as written into FAP 49 (1e-5 rad)
    own = run_fdl(clip / "clip.fdl").faps.values[:6, 48] / (np.pi / 180 * 1e5)
    labelled = np.array([r["head_deg"][1] for r in rows])
    assert np.allclose(labelled, own + draw.head_deg[1], atol=2e-3)
    assert np.array_equal(stream.values, np.rint(stream.values))  # frames show clip.fap
    assert np.allclose(stream.values[:, 48], np.round((own + draw.head_deg[1])
                                                      * np.pi / 180 * 1e5), atol=1)
    assert rows[0]["behaviour"] == draw.behaviour
    name, start, duration, intensity = draw.expressions[0]
    inside = [r for r in rows if start <= r["time_s"] < start + duration]
    assert inside and all(r["expressions"].get(name) == intensity for r in inside)
    xy = np.array([rows[0]["landmarks"][fp] for fp in ("3.5", "3.6", "9.3", "2.1")])
    assert ((xy >= 0) & (xy <= 48)).all()  # eyes, nose tip and chin project into the image
    # the face's left eye (3.5) appears right of its right eye (3.6) in the picture
    assert xy[0, 0] > xy[1, 0]
    # rows: eyes above the nose tip above the chin
    assert max(xy[0, 1], xy[1, 1]) < xy[2, 1] < xy[3, 1]


@pytest.mark.render
@pytest.mark.slow
@pytest.mark.cluster
@pytest.mark.skipif(not HAS_RENDER, reason="needs the render extra")
def test_a_dask_cluster_writes_the_same_bytes_and_a_killed_run_resumes(
        tmp_path, spec_file, monkeypatch):
    distributed = pytest.importorskip("distributed")
    # llvmpipe (OSMesa's default rasterizer) is not bit-reproducible between OpenGL
    # contexts (now and then one pixel differs by one level); softpipe is. Every worker,
    # local or Dask, renders with it here, as docs/batch.md says to for identical frames.
    monkeypatch.setenv("GALLIUM_DRIVER", "softpipe")
    spec = load_spec(spec_file)
    local = generate(spec, tmp_path / "local", jobs=2)
    assert (local.written, local.failed) == (6, ())
    expected = tree(tmp_path / "local")
    assert len([k for k in expected if k.endswith("meta.json")]) == 6

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None,
                                  env={"GALLIUM_DRIVER": "softpipe"}) as cluster:
        remote = generate(spec, tmp_path / "cluster", scheduler=cluster.scheduler_address)
    assert (remote.written, remote.failed) == (6, ())
    assert tree(tmp_path / "cluster") == expected

    # kill a run after its first clip, then run again: finished clips are kept as they were
    out = tmp_path / "resumed"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONWARNINGS": "ignore"}
    proc = subprocess.Popen([sys.executable, "-m", "facelib.cli", "dataset", str(spec_file),
                             "-o", str(out), "-j", "1", "-q"], env=env,
                            start_new_session=True)
    deadline = time.monotonic() + 120
    while not (out / "clip_000000").is_dir() and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)  # the command and its worker, as a crash would
    proc.wait(timeout=30)
    time.sleep(0.5)
    finished = sorted(p.name for p in out.glob("clip_*"))
    assert finished and len(finished) < 6
    kept = {name: (out / name / "meta.json").stat().st_mtime_ns for name in finished}
    again = generate(load_spec(spec_file), out, jobs=2)
    assert again.skipped == len(finished) and again.written == 6 - len(finished)
    assert {name: (out / name / "meta.json").stat().st_mtime_ns for name in finished} == kept
    assert tree(out) == expected
    assert not list(out.glob(".clip_*"))  # the killed run's half clip was cleared


def test_a_folder_of_another_spec_is_refused(tmp_path, spec_file):
    spec = load_spec(spec_file)
    out = tmp_path / "ds"
    out.mkdir()
    (out / "spec.json").write_text("{}\n")
    with pytest.raises(FacelibError, match="another spec"):
        generate(spec, out, jobs=1)
