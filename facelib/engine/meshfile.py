"""Reading a face definition's mesh file: an ``.npz`` whose headers are checked first.

``numpy.load`` allocates the shape an ``.npy`` header declares before it reads a byte, so a
200-byte ``.npz`` declaring ``(10^12, 3)`` float32 vertices asked for 2.18 TiB. Here every
member's header is read and checked against the bytes the member really holds and a limit
on the whole file before any array is made. The file a definition names must be a regular
file inside the definition's folder.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path

import numpy as np

from facelib.errors import FaceModelError

__all__ = ["MAX_MESH_BYTES", "mesh_path", "read_npz"]

MAX_MESH_BYTES = 2 * 1024**3
"""Bytes all arrays of one mesh file may declare together (2 GiB: a 20-million-vertex
face with its fields)."""


def mesh_path(definition: Path, name: str) -> Path:
    """The file ``name`` (a definition's ``mesh`` entry) beside ``definition``: a relative
    path without ``..`` that stays inside the definition's folder, also through symbolic
    links, and is a regular file; FaceModelError naming the definition otherwise."""
    relative = Path(name)
    if not name or relative.is_absolute() or ".." in relative.parts or "\0" in name:
        raise FaceModelError(f"mesh {name!r} must be a relative path inside the face "
                             "definition's folder (no absolute path, no '..')", path=definition)
    folder = definition.parent.resolve()
    target = (folder / relative).resolve()
    if not target.is_relative_to(folder):
        raise FaceModelError(f"mesh {name!r} leads outside the face definition's folder "
                             "(through a symbolic link)", path=definition)
    if not target.is_file():
        raise FaceModelError(f"mesh {name!r} does not exist or is not a regular file",
                             path=definition)
    return target


def _declared_bytes(archive: zipfile.ZipFile, info: zipfile.ZipInfo, where: Path) -> int:
    """Bytes the ``.npy`` member ``info`` declares, checked against what it holds."""
    with archive.open(info) as member:
        try:
            version = np.lib.format.read_magic(member)
            shape, _, dtype = (np.lib.format.read_array_header_1_0(member) if version == (1, 0)
                               else np.lib.format.read_array_header_2_0(member))
        except ValueError as exc:
            raise FaceModelError(f"array {info.filename!r} has a bad header: {exc}",
                                 path=where) from None
        header = member.tell()
    if dtype.hasobject:
        raise FaceModelError(f"array {info.filename!r} holds Python objects", path=where)
    declared = math.prod(shape) * dtype.itemsize
    if declared != info.file_size - header:
        raise FaceModelError(f"array {info.filename!r} declares shape {shape} "
                             f"({declared} bytes) but holds {info.file_size - header} bytes",
                             path=where)
    return declared


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` file ``path`` by name, after checking each header (no
    object arrays; the declared size equals the bytes held) and the total against
    :data:`MAX_MESH_BYTES`. FaceModelError naming the file otherwise."""
    try:
        with zipfile.ZipFile(path) as archive:
            infos = [i for i in archive.infolist() if i.filename.endswith(".npy")]
            total = sum(_declared_bytes(archive, info, path) for info in infos)
    except (OSError, zipfile.BadZipFile, EOFError) as exc:
        raise FaceModelError(f"cannot read the mesh file: {exc}", path=path) from None
    if total > MAX_MESH_BYTES:
        raise FaceModelError(f"the mesh file's arrays declare {total} bytes, more than the "
                             f"{MAX_MESH_BYTES} allowed", path=path)
    try:
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise FaceModelError(f"cannot read the mesh file: {exc}", path=path) from None
