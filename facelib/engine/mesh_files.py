"""Files a head mesh refers to, confined to the mesh's folder.

A mesh file can name other files: a glTF's buffers and images, an OBJ's material library
(``mtllib``) and the textures it names (``map_Kd``), a PLY's texture. Each one must be a
relative path that stays inside the mesh's folder (also through ``..`` and symbolic links),
name a regular file and be at most :data:`MAX_REFERENCE_BYTES`; everything else is refused.
:class:`ConfinedFiles` is the only way the mesh reader (trimesh) reaches another file: it
answers each request after these checks and records every refusal, so that the reader
cannot drop one silently (trimesh skips a material library it cannot load).
"""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path
from typing import NoReturn

from facelib.errors import FaceModelError

__all__ = [
    "MAX_MESH_BYTES",
    "MAX_REFERENCES",
    "MAX_REFERENCE_BYTES",
    "ConfinedFiles",
    "check_mesh_file",
]

MAX_MESH_BYTES = 2 * 1024**3
"""Largest head mesh file read (2 GiB: ten million triangles as text)."""
MAX_REFERENCE_BYTES = 512 * 1024**2
"""Largest file a mesh may refer to (512 MiB: a 16k x 16k texture, or a large buffer)."""
MAX_REFERENCES = 256
"""Most files one mesh may refer to."""

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def check_mesh_file(path: Path) -> None:
    """Refuse a mesh ``path`` that is missing, not a regular file or over
    :data:`MAX_MESH_BYTES` (FaceModelError naming the path)."""
    try:
        info = path.stat()
    except OSError as exc:
        raise FaceModelError(f"cannot read the mesh: {exc.strerror}", path=path) from None
    if not stat.S_ISREG(info.st_mode):
        raise FaceModelError("the mesh is not a regular file", path=path)
    if info.st_size > MAX_MESH_BYTES:
        raise FaceModelError(f"the mesh is larger than {MAX_MESH_BYTES} bytes "
                             f"({info.st_size})", path=path)


class ConfinedFiles:
    """A trimesh resolver that serves only files inside one folder.

    mesh: the mesh file whose references are served; they resolve against its folder.
    refusals: the message of every request refused so far, in order (the first one is the
    error to report even when trimesh swallowed the exception).
    """

    def __init__(self, mesh: Path):
        self.mesh = mesh
        self.folder = mesh.resolve().parent
        self.parent = str(self.folder)  # trimesh reads this attribute for file names
        self.file_name = mesh.name
        self.refusals: list[str] = []
        self._served = 0

    def locate(self, name: object) -> Path:
        """The file inside the folder that ``name`` refers to; FaceModelError otherwise."""
        if not isinstance(name, str) or not name.strip():
            self._refuse(f"refers to a file by {name!r}, which is not a file name")
        text = name.strip()
        if "\0" in text:
            self._refuse(f"refers to {text!r}, which contains a NUL character")
        if _SCHEME.match(text) and not re.match(r"^[A-Za-z]:[\\/]", text):
            self._refuse(f"refers to {text!r}: a URI scheme is not allowed; name a file "
                         "beside the mesh")
        relative = Path(text)
        if relative.is_absolute() or text.startswith(("\\", "/")) or re.match(r"^[A-Za-z]:",
                                                                               text):
            self._refuse(f"refers to the absolute path {text!r}; references must be relative "
                         "to the mesh's folder")
        full = (self.folder / relative).resolve()
        if not full.is_relative_to(self.folder):
            self._refuse(f"refers to {text!r}, which leaves the mesh's folder "
                         f"{str(self.folder)!r}")
        try:
            info = full.stat()
        except OSError as exc:
            self._refuse(f"refers to {text!r}, which cannot be read: {exc.strerror}")
        if not stat.S_ISREG(info.st_mode):
            self._refuse(f"refers to {text!r}, which is not a regular file")
        if info.st_size > MAX_REFERENCE_BYTES:
            self._refuse(f"refers to {text!r}, which is larger than {MAX_REFERENCE_BYTES} "
                         f"bytes ({info.st_size})")
        return full

    def get(self, name: str) -> bytes:
        """The bytes of the file ``name`` refers to (trimesh's resolver interface)."""
        full = self.locate(name)
        self._served += 1
        if self._served > MAX_REFERENCES:
            self._refuse(f"refers to more than {MAX_REFERENCES} files")
        try:
            fd = os.open(full, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0)
                         | getattr(os, "O_NONBLOCK", 0))
            with os.fdopen(fd, "rb") as handle:
                if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                    self._refuse(f"refers to {name.strip()!r}, which is not a regular file")
                data = handle.read(MAX_REFERENCE_BYTES + 1)
        except OSError as exc:
            self._refuse(f"refers to {name.strip()!r}, which cannot be read: {exc.strerror}")
        if len(data) > MAX_REFERENCE_BYTES:
            self._refuse(f"refers to {name.strip()!r}, which is larger than "
                         f"{MAX_REFERENCE_BYTES} bytes")
        return data

    def __getitem__(self, name: str) -> bytes:
        return self.get(name)

    def __contains__(self, name: str) -> bool:
        try:
            self.locate(name)
        except FaceModelError:
            self.refusals.pop()
            return False
        return True

    def keys(self) -> list[str]:
        """No listing: a mesh gets only the files it names."""
        return []

    def namespaced(self, namespace: str) -> ConfinedFiles:
        """This resolver again: sub-folders are reached by relative names."""
        self._refuse(f"refers to the folder {namespace!r}; name files instead")

    def write(self, name: str, data: bytes) -> None:
        """Reading a mesh writes nothing."""
        self._refuse(f"asked to write {name!r} while reading")

    def _refuse(self, message: str) -> NoReturn:
        self.refusals.append(message)
        raise FaceModelError(message, path=self.mesh)

    def check(self) -> None:
        """Raise the first refusal, if trimesh swallowed it."""
        if self.refusals:
            raise FaceModelError(self.refusals[0], path=self.mesh)
