"""Where a live session's Live Link and VMC packets go: a UDP address named ``HOST:PORT``,
loopback unless the server's operator names another host."""

from __future__ import annotations

import ipaddress
import socket
from dataclasses import dataclass, field

from facelib.errors import ParameterError

__all__ = ["UdpTarget", "is_loopback", "parse_target"]


def is_loopback(host: str) -> bool:
    """Whether ``host`` is ``localhost`` or a loopback address."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def parse_target(text: str, *, default_port: int, loopback_only: bool = False,
                 ) -> tuple[str, int]:
    """``(host, port)`` of ``"HOST:PORT"``, ``"HOST"`` or ``":PORT"`` (host 127.0.0.1,
    port ``default_port`` when left out). ``loopback_only``: refuse other hosts."""
    if not isinstance(text, str) or not 0 < len(text) <= 255:
        raise ParameterError(f"a UDP target is HOST:PORT, got {text!r}")
    host, _, port_text = text.rpartition(":") if ":" in text else (text, "", "")
    host = host.strip("[]") or "127.0.0.1"
    try:
        port = int(port_text) if port_text else default_port
    except ValueError:
        raise ParameterError(f"a UDP target is HOST:PORT, got {text!r}") from None
    if not 0 < port <= 65535:
        raise ParameterError(f"UDP port must be 1-65535, got {port}")
    if loopback_only and not is_loopback(host):
        raise ParameterError(f"a session may send UDP to loopback only, not {host!r} (the "
                             "server's --livelink/--vmc name other hosts)")
    return host, port


@dataclass
class UdpTarget:
    """A non-blocking UDP sender to ``(host, port)``; a packet that cannot go is counted in
    ``failed`` (no listener, a full buffer), never raised."""

    host: str
    port: int
    sent: int = 0
    failed: int = 0
    _socket: socket.socket | None = field(default=None, repr=False)

    def send(self, packet: bytes) -> None:
        if self._socket is None:
            family = socket.AF_INET6 if ":" in self.host else socket.AF_INET
            self._socket = socket.socket(family, socket.SOCK_DGRAM)
            self._socket.settimeout(0.0)
        try:
            self._socket.sendto(packet, (self.host, self.port))
            self.sent += 1
        except OSError:
            self.failed += 1

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close()
            self._socket = None
