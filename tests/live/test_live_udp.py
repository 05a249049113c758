"""Live Link Face and VMC packets on a real loopback UDP socket, decoded by decoders
written here from the public descriptions (the Live Link Face app's packet as Unreal's
``AppleARKitLiveLinkSource`` reads it; OSC 1.0 messages and bundles; the VMC protocol's
addresses), not by facelib's encoders: the values must be the frames' own."""

from __future__ import annotations

import math
import socket
import struct

import numpy as np
import pytest

from facelib.errors import ParameterError
from facelib.export.arkit import arkit_names
from facelib.live.session import SyncSession
from facelib.live.udp import parse_target

pytestmark = pytest.mark.speech


def _receiver() -> tuple[socket.socket, str]:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.settimeout(5)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    return sock, f"127.0.0.1:{sock.getsockname()[1]}"


def _drain(sock: socket.socket, n: int) -> list[bytes]:
    return [sock.recv(65536) for _ in range(n)]


# -- Live Link Face: big-endian; u8 version; i32-length strings (device, subject);
#    i32 frame, f32 sub-frame, i32 rate numerator, i32 denominator; u8 count; count f32
def _live_link(packet: bytes) -> dict:
    at = 0

    def take(fmt: str) -> tuple:
        nonlocal at
        values = struct.unpack_from(fmt, packet, at)
        at += struct.calcsize(fmt)
        return values

    def string() -> str:
        nonlocal at
        (n,) = take(">i")
        at += n
        return packet[at - n:at].decode("utf-8")

    (version,) = take(">B")
    device, subject = string(), string()
    frame, sub, num, den = take(">ifii")
    (count,) = take(">B")
    curves = take(f">{count}f")
    assert at == len(packet)
    return {"version": version, "device": device, "subject": subject, "frame": frame,
            "sub": sub, "rate": (num, den), "curves": curves}


def _session_frames(**targets: str) -> list:
    with SyncSession(clock="manual", fps=30, seed=5, arkit=True, **targets) as s:
        s.say("Hello, how are you?")
        s.cue('show { "joy", dur = 1 }')
        s.stop()
        return list(s.frames())


def test_live_link_packets_carry_the_frames_weights_and_angles() -> None:
    sock, target = _receiver()
    with sock:
        frames = _session_frames(livelink=target)
        packets = _drain(sock, len(frames))
    assert len(frames) > 40
    for out, raw in zip(frames, packets, strict=True):
        got = _live_link(raw)
        assert got["version"] == 6 and got["subject"] == "facelib"
        assert got["frame"] == out.frame.index and got["rate"] == (30, 1)
        curves = np.array(got["curves"], np.float32)
        assert curves.size == 61
        assert np.array_equal(curves[:52], out.arkit)  # float32 both ways: exact
        assert np.array_equal(curves[52:], out.angles)
    jaw = arkit_names().index("JawOpen")
    assert max(_live_link(p)["curves"][jaw] for p in packets) > 0.1  # the mouth moves


# -- OSC 1.0: strings NUL-terminated and padded to 4 bytes; ",types"; big-endian i32/f32;
#    a bundle is "#bundle", an 8-byte time tag, then (i32 size, element) pairs
def _osc_string(data: bytes, at: int) -> tuple[str, int]:
    end = data.index(b"\0", at)
    return data[at:end].decode("utf-8"), (end // 4 + 1) * 4


def _osc_message(data: bytes) -> tuple[str, list]:
    address, at = _osc_string(data, 0)
    tags, at = _osc_string(data, at)
    assert tags.startswith(",")
    args: list = []
    for tag in tags[1:]:
        if tag == "s":
            text, at = _osc_string(data, at)
            args.append(text)
        else:
            args.append(struct.unpack_from(">i" if tag == "i" else ">f", data, at)[0])
            at += 4
    return address, args


def _osc_bundle(data: bytes) -> list[tuple[str, list]]:
    assert data[:8] == b"#bundle\0"
    at, out = 16, []
    while at < len(data):
        (size,) = struct.unpack_from(">i", data, at)
        out.append(_osc_message(data[at + 4:at + 4 + size]))
        at += 4 + size
    return out


def test_vmc_bundles_carry_the_clips_and_the_head() -> None:
    sock, target = _receiver()
    with sock:
        frames = _session_frames(vmc=target)
        bundles = [_osc_bundle(raw) for raw in _drain(sock, len(frames))]
    apple = [n[0].lower() + n[1:] for n in arkit_names()]
    vowels = {10: "A", 11: "E", 12: "I", 13: "O", 14: "U"}
    for out, messages in zip(frames, bundles, strict=True):
        values = {args[0]: args[1] for address, args in messages
                  if address == "/VMC/Ext/Blend/Val"}
        assert np.allclose([values[n] for n in apple], out.arkit, atol=1e-6)
        assert values["Blink_L"] == pytest.approx(float(out.arkit[0]), abs=1e-6)
        shown = vowels.get(out.frame.viseme)
        for clip in vowels.values():
            assert (values[clip] > 0) <= (clip == shown)
        addresses = [a for a, _ in messages]
        assert addresses.index("/VMC/Ext/Blend/Apply") > max(
            i for i, a in enumerate(addresses) if a == "/VMC/Ext/Blend/Val")
        (bone,) = [args for address, args in messages if address == "/VMC/Ext/Bone/Pos"]
        assert bone[0] == "Head" and bone[1:4] == [0.0, 0.0, 0.0]
        x, y, z, w = bone[4:]
        assert math.isclose(x * x + y * y + z * z + w * w, 1.0, abs_tol=1e-5)
        yaw, pitch, roll = (float(a) for a in out.angles[:3])
        # an independent check of the rotation: the quaternion's own yaw about Unity's y
        # (rotating the forward axis z) matches the head's yaw when pitch and roll are small
        forward_x = 2 * (x * z + w * y)
        forward_z = 1 - 2 * (x * x + y * y)
        assert math.atan2(forward_x, forward_z) == pytest.approx(yaw, abs=abs(pitch) + abs(
            roll) + 1e-4)
    spoken = [m for m in bundles if any(a[0] in vowels.values() and a[1] > 0
                                        for addr, a in m if addr == "/VMC/Ext/Blend/Val")]
    assert spoken  # some frame shows a vowel


def test_targets_are_checked_and_clients_name_loopback_only() -> None:
    assert parse_target(":9000", default_port=1) == ("127.0.0.1", 9000)
    assert parse_target("localhost", default_port=11111) == ("localhost", 11111)
    for bad in ("host:x", "h:70000", ""):
        with pytest.raises(ParameterError):
            parse_target(bad, default_port=1)
    with pytest.raises(ParameterError):
        parse_target("10.0.0.5:11111", default_port=1, loopback_only=True)


def test_a_start_message_may_not_aim_udp_at_another_host() -> None:
    from facelib.live.server import ServerOptions, _session_from

    with pytest.raises(ParameterError):
        _session_from({"type": "start", "livelink": "192.168.1.20:11111"}, ServerOptions())
    session, _ = _session_from({"type": "start", "vmc": "127.0.0.1:39539"}, ServerOptions())
    assert set(session.udp) == {"vmc"}
    session, _ = _session_from({"type": "start"}, ServerOptions(livelink="10.1.2.3:11111"))
    assert session.udp["livelink"].host == "10.1.2.3"  # the operator's target for all
