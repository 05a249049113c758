"""``dataset --scheduler`` against a hostile cluster (issue 38, class 2): whatever workers
send, nothing is unpickled in facelib's process; results are plain JSON text, checked;
a scheduler on another machine needs TLS or ``--trust-cluster``.

The attacks are real: a LocalCluster on loopback whose worker is changed (by a trusted
set-up client) to answer ``get_data`` with a pickle the scheduler relays, or to fail a
task with an exception whose unpickling writes a marker file named by the process id.
"""

from __future__ import annotations

import json
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import msgpack
import pytest

from facelib.cluster import TASK_FAILED, check_address, decode_message, refused
from facelib.dataset import DatasetSpec, generate, parse_clip_result
from facelib.errors import FacelibError, ParameterError

ROOT = Path(__file__).resolve().parents[1]

# Run in the worker process by the set-up client; %(mark)r is the marker folder.
_EVIL = """
import os, pickle
class Evil(BaseException):
    def __reduce__(self):
        return (exec, ("import os; open(%(mark)r + '/pwned-%%d' %% os.getpid(), 'w').close()",))
import distributed
import facelib.dataset
WORKERS = list(distributed.Worker._instances)
"""
# the clip "made" without rendering, then its result answered as a relayed pickle: the
# outer pickle builds Dask's inert Pickled wrapper on the scheduler, which sends the
# inner one on to the client as a frame to unpickle
_HOSTILE_RESULT = _EVIL + """
from distributed.core import Status
from distributed.protocol.serialize import Pickled, ToPickle
facelib.dataset.make_clip = lambda spec, index, out_dir: "written"
async def get_data(comm, keys=(), who=None, serializers=None, **kwargs):
    inner = pickle.dumps(Evil(), protocol=5)
    data = {k: ToPickle(Pickled({"pickled-obj": inner, "num-sub-frames": 0}, []))
            for k in keys}
    await comm.write({"status": "OK", "data": data})
    await comm.read()
    return Status.dont_reply
for worker in WORKERS:
    worker.handlers["get_data"] = get_data
"""
# the task fails, and the worker sends a pickle as its exception and traceback (Dask's
# own error_message would pickle a real exception: the client unpickles those bytes too)
_HOSTILE_ERROR = _EVIL + """
import distributed.core, distributed.worker
from distributed.protocol import to_serialize
def error_message(e, status="error"):
    evil = to_serialize(pickle.dumps(Evil(), protocol=5))
    return {"status": status, "exception": evil, "traceback": evil,
            "exception_text": "Evil()", "traceback_text": ""}
distributed.worker.error_message = error_message
distributed.core.error_message = error_message
def make_clip(spec, index, out_dir):
    raise BaseException("not caught by the clip task")
facelib.dataset.make_clip = make_clip
"""
# a task printing a forged line on the client and warning with a pickled category
_HOSTILE_EVENTS = _EVIL + """
def make_clip(spec, index, out_dir):
    worker = distributed.get_worker()
    worker.log_event("print", {"args": ("facelib: dataset complete, 0 failed",)})
    worker.log_event("warn", {"message": pickle.dumps(Evil()),
                              "category": pickle.dumps(Evil())})
    return "written"
facelib.dataset.make_clip = make_clip
"""

SPEC = DatasetSpec(clips=2, seed=3, seconds=0.12, width=32, height=32, media="none")


@pytest.fixture
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as local:
        yield local


def _make_hostile(cluster, code: str, mark: Path) -> None:
    """Run ``code`` in every worker process (through a trusted client of the test)."""
    import distributed

    with distributed.Client(cluster.scheduler_address, set_as_default=False) as setup:
        setup.run(exec, code % {"mark": str(mark)}, {})


def _pwned(mark: Path) -> bool:
    """Whether this process ran the payload."""
    return (mark / f"pwned-{os.getpid()}").exists()


@pytest.mark.cluster
def test_a_pickle_relayed_as_a_result_is_never_unpickled(cluster, tmp_path):
    mark = tmp_path / "mark"
    mark.mkdir()
    _make_hostile(cluster, _HOSTILE_RESULT, mark)
    with pytest.raises(FacelibError, match=r"clip [01]: the cluster sent <refused by "
                                           r"facelib: a pickle> instead of the clip's"):
        generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address)
    # a Client of the caller's is not used as it is: facelib opens its own to its scheduler
    import distributed

    with distributed.Client(cluster.scheduler_address, set_as_default=False) as theirs, \
            pytest.raises(FacelibError, match="refused by facelib: a pickle"):
        generate(SPEC, tmp_path / "ds", scheduler=theirs)
    assert not _pwned(mark)


@pytest.mark.cluster
def test_a_task_error_is_never_unpickled(cluster, tmp_path):
    mark = tmp_path / "mark"
    mark.mkdir()
    _make_hostile(cluster, _HOSTILE_ERROR, mark)
    report = generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address)
    assert report.written == 0
    assert report.failed == ((0, TASK_FAILED), (1, TASK_FAILED))
    assert not _pwned(mark)


@pytest.mark.cluster
def test_worker_events_are_ignored(cluster, tmp_path, capfd):
    mark = tmp_path / "mark"
    mark.mkdir()
    _make_hostile(cluster, _HOSTILE_EVENTS, mark)
    report = generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address)
    assert [i for i, _ in report.failed] == [0, 1]  # "written", yet no clip folder
    assert not _pwned(mark)
    assert "dataset complete" not in capfd.readouterr().out


@pytest.mark.cluster
@pytest.mark.render
@pytest.mark.slow
def test_a_trusted_cluster_makes_the_same_clips(cluster, tmp_path):
    local = generate(SPEC, tmp_path / "local", jobs=1)
    remote = generate(SPEC, tmp_path / "cluster", scheduler=cluster.scheduler_address)
    assert (remote.written, remote.failed) == (local.written, local.failed) == (2, ())
    for name in ("index.jsonl", "clip_000001/meta.json", "clip_000001/clip.fap"):
        assert (tmp_path / "cluster" / name).read_bytes() == \
            (tmp_path / "local" / name).read_bytes()
    again = generate(SPEC, tmp_path / "cluster", scheduler=cluster.scheduler_address)
    assert (again.written, again.skipped) == (0, 2)


@pytest.mark.cluster
def test_workers_that_do_not_see_the_folder_fail_the_clip(cluster, tmp_path):
    mark = tmp_path / "mark"
    mark.mkdir()
    _make_hostile(cluster, _EVIL + 'facelib.dataset.make_clip = lambda s, i, o: "written"\n',
                  mark)
    report = generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address)
    assert report.written == 0
    assert [i for i, _ in report.failed] == [0, 1]
    assert "reported as made, but" in report.failed[0][1]
    assert not (tmp_path / "ds" / "index.jsonl").read_text()


# --- the pieces, without a cluster ----------------------------------------------------

def _frames(message, *sub):
    return [msgpack.dumps(message), *sub]


@pytest.mark.parametrize(("message", "subframes", "expected"), [
    ({"op": "x", "n": 3, "keys": ["a", 1]}, (), {"op": "x", "n": 3, "keys": ("a", 1)}),
    ({"op": "x", "v": {"__Pickled__": 1}}, (b"\x80\x05.",), "a pickle"),
    ({"type": b"\x80\x05N."}, (), "bytes"),
    ({"op": "x", "v": {"__Serialized__": 1}},
     (msgpack.dumps({"serializer": "pickle", "num-sub-frames": 1}), b"x"),
     "data serialized by 'pickle'"),
    ({"op": "x", "v": {"__Serialized__": 1}},
     (msgpack.dumps({"serializer": "dask", "type-serialized": b"\x80", "num-sub-frames": 1}),
      b"x"), "data serialized by 'dask'"),
    ({"op": "x", "v": {"__Serialized__": 1}},
     (msgpack.dumps({"serializer": "msgpack", "num-sub-frames": 1, "compression": ["lz4"]}),
      b"x"), "split or compressed"),
    ({"op": "x", "v": {"__Serialized__": 9}}, (), "serialized data"),
    ({"op": "x", "v": {"__Enum__": True, "__module__": "os", "__name__": "x", "name": "y"}},
     (), "a Python enum"),
])
def test_messages_are_decoded_as_plain_data_only(message, subframes, expected):
    decoded = decode_message(_frames(message, *subframes))
    if isinstance(expected, dict):
        assert decoded == expected
    else:
        inside = decoded.get("v", decoded.get("type"))
        assert refused(inside) and expected in inside, decoded


def test_a_result_serialized_by_msgpack_is_read():
    header = {"serializer": "msgpack", "split-num-sub-frames": [1], "split-offsets": [0],
              "compression": [None], "num-sub-frames": 1}
    text = '{"clip": 0, "status": "written", "error": null}'
    frames = _frames({"status": "OK", "data": {"k": {"__Serialized__": 1}}},
                     msgpack.dumps(header), msgpack.dumps(text))
    assert decode_message(frames) == {"status": "OK", "data": {"k": text}}


def test_a_deep_or_garbled_message_is_refused():
    deep: list = []
    for _ in range(100):
        deep = [deep]
    assert "nested too deeply" in str(decode_message(_frames(deep)))
    assert refused(decode_message([b"\xc1garbage"]))
    assert refused(decode_message([]))


def test_the_stand_in_never_is_a_pickle_loads_input():
    # what Dask's handlers do with a stand-in: nothing
    with pytest.raises(TypeError):
        pickle.loads(decode_message(_frames({"type": b"x"}))["type"])


@pytest.mark.parametrize(("text", "match"), [
    ("<refused by facelib: a pickle>", "the cluster sent <refused by facelib: a pickle>"),
    ('{"clip": 1, "status": "written", "error": null}', "not a clip result"),
    ('{"clip": true, "status": "written", "error": null}', "not a clip result"),
    ('{"clip": 0, "status": "pwned", "error": null}', "not a clip result"),
    ('{"clip": 0, "status": "failed", "error": null}', "not a clip result"),
    ('{"clip": 0, "status": "written", "error": null, "x": 1}', "not a clip result"),
    ("[" * 5000, "not a clip result"),
    ("x" * 9000, "not a clip result"),
    (42, "not a clip result"),
])
def test_a_clip_result_is_checked(text, match):
    with pytest.raises(FacelibError, match=match):
        parse_clip_result(text, 0)


def test_a_clip_error_is_one_line():
    text = json.dumps({"clip": 0, "status": "failed", "error": "x\nfacelib: all fine"})
    assert parse_clip_result(text, 0) == (0, "failed", "x\\nfacelib: all fine")


@pytest.mark.parametrize(("address", "tls", "trust", "match"), [
    ("tcp://10.1.2.3:8786", False, False, "not on this machine"),
    ("scheduler.example:8786", False, False, "not on this machine"),
    ("tls://10.1.2.3:8786", False, False, "needs the cluster's certificates"),
    ("tcp://10.1.2.3:8786", True, False, "use tls://"),
    ("ucx://10.1.2.3:8786", False, False, "--trust-cluster"),
    ("", False, False, "must be a text"),
    (None, False, False, "must be a text"),
    ("tcp://[::1:8786", False, False, "not an address"),
])
def test_a_scheduler_elsewhere_needs_tls_or_trust(address, tls, trust, match):
    pytest.importorskip("distributed")
    with pytest.raises(ParameterError, match=match):
        check_address(address, tls=tls, trust=trust)


@pytest.mark.parametrize(("address", "tls", "trust", "full"), [
    ("tcp://127.0.0.1:8786", False, False, "tcp://127.0.0.1:8786"),
    ("localhost:8786", False, False, "tcp://localhost:8786"),
    ("tcp://[::1]:8786", False, False, "tcp://[::1]:8786"),
    ("tcp://10.1.2.3:8786", False, True, "tcp://10.1.2.3:8786"),
    ("tls://10.1.2.3:8786", True, False, "tls://10.1.2.3:8786"),
])
def test_loopback_tls_or_trusted_schedulers_are_used(address, tls, trust, full):
    pytest.importorskip("distributed")
    assert check_address(address, tls=tls, trust=trust) == full


def test_the_command_refuses_a_remote_scheduler_over_tcp(tmp_path):
    pytest.importorskip("distributed")
    spec = tmp_path / "spec.toml"
    spec.write_text('clips = 1\nmedia = "none"\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONWARNINGS": "ignore"}
    for extra, expected in ((["--scheduler", "tcp://10.1.2.3:8786"], "not on this machine"),
                            (["--trust-cluster"], "need --scheduler"),
                            (["--scheduler", "tls://10.1.2.3:8786", "--tls-ca", "ca.pem"],
                             "all of --tls-ca")):
        done = subprocess.run([sys.executable, "-m", "facelib.cli", "dataset", str(spec),
                               "-o", str(tmp_path / "ds"), *extra], check=False, env=env,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode != 0
        assert expected in done.stderr and "Traceback" not in done.stderr, done.stderr


def _certificates(folder: Path) -> dict[str, str]:
    """A CA and one certificate signed by it (for the cluster and the client alike)."""
    def openssl(*args: str) -> None:
        subprocess.run(["openssl", *args], check=True, capture_output=True, timeout=60)

    ca, ca_key, cert, key, request = (str(folder / n) for n in (
        "ca.pem", "ca.key", "cert.pem", "cert.key", "cert.csr"))
    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", ca_key, "-out", ca,
            "-days", "2", "-subj", "/CN=facelib test CA")
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", key, "-out", request,
            "-subj", "/CN=127.0.0.1")
    openssl("x509", "-req", "-in", request, "-CA", ca, "-CAkey", ca_key, "-CAcreateserial",
            "-out", cert, "-days", "2")
    return {"ca": ca, "cert": cert, "key": key}


@pytest.mark.cluster
@pytest.mark.skipif(not shutil.which("openssl"), reason="needs openssl to make certificates")
def test_a_tls_cluster_is_reached_with_the_plain_data_client(tmp_path):
    distributed = pytest.importorskip("distributed")
    from facelib.cluster import tls_security

    files = _certificates(tmp_path)
    security = tls_security(**files)
    roles = {f"tls_{role}_{part}": files[part] for role in ("scheduler", "worker", "client")
             for part in ("cert", "key")}
    cluster_security = distributed.Security(tls_ca_file=files["ca"], require_encryption=True,
                                            **roles)
    mark = tmp_path / "mark"
    mark.mkdir()
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None, protocol="tls://",
                                  security=cluster_security) as cluster:
        assert cluster.scheduler_address.startswith("tls://")
        with pytest.raises(ParameterError, match="needs the cluster's certificates"):
            generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address)
        with distributed.Client(cluster.scheduler_address, security=cluster_security,
                                set_as_default=False) as setup:
            setup.run(exec, _HOSTILE_RESULT % {"mark": str(mark)}, {})
        with pytest.raises(FacelibError, match="refused by facelib: a pickle"):
            generate(SPEC, tmp_path / "ds", scheduler=cluster.scheduler_address,
                     security=security)
    assert not _pwned(mark)
