"""Cheaper uniform setting for pyrender's shader programs, with the same pixels.

pyrender sets every uniform of every primitive on every frame, each through
``glGetUniformLocation`` (and a Python exception for each name the shader does not use).
:func:`install_uniform_cache` gives one shader program a cache of uniform locations and of
the values last set: a uniform keeps its value in its program, so setting the same value
again is skipped (exact).

Measured in ``benchmarks/render_speed.py`` (docs/rendering.md, "Speed").
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["install_uniform_cache"]

_UNSET = object()


def install_uniform_cache(program: Any) -> None:
    """Make ``program`` (a ``pyrender.shader_program.ShaderProgram``) set a uniform only
    when its value changed, looking each name's location up once.

    The values and conversions are pyrender's (``ShaderProgram.set_uniform``): 1-D arrays
    as vectors of unsigned, signed or float components, 2-D arrays as transposed matrices,
    Python floats, ints and bools as scalars; anything else goes to pyrender's own method.
    """
    from OpenGL import GL

    served = program.set_uniform
    locations: dict[str, int] = {}
    last: dict[str, Any] = {}

    def set_uniform(name: str, value: Any, unsigned: bool = False) -> None:
        if isinstance(value, np.ndarray) and value.ndim in (1, 2):
            key: Any = (value.dtype.str, value.shape, unsigned, value.tobytes())
        elif isinstance(value, (float, int)):  # bool is an int
            key = (type(value), value, unsigned)
        else:
            served(name, value, unsigned)
            last.pop(name, None)
            return
        if last.get(name, _UNSET) == key:
            return
        loc = locations.get(name)
        if loc is None:
            loc = locations[name] = int(GL.glGetUniformLocation(program._program_id, name))
        last[name] = key
        if loc == -1:  # not in the shader (pyrender ignores it too)
            return
        _write(program, loc, value, unsigned)

    program.set_uniform = set_uniform


def _write(program: Any, loc: int, value: Any, unsigned: bool) -> None:
    """Set the uniform at ``loc`` of the bound ``program`` as pyrender's ``set_uniform``
    does."""
    from OpenGL import GL

    if isinstance(value, np.ndarray):
        if value.ndim == 1:
            if np.issubdtype(value.dtype, np.unsignedinteger) or unsigned:
                kind, value = "u", value.astype(np.uint32)
            elif np.issubdtype(value.dtype, np.integer):
                kind, value = "i", value.astype(np.int32)
            else:
                kind, value = "f", value.astype(np.float32)
            program._FUNC_MAP[(value.shape[0], kind)](loc, 1, value)
        else:
            program._FUNC_MAP[value.shape](loc, 1, GL.GL_TRUE, value)
    elif isinstance(value, float):
        GL.glUniform1f(loc, value)
    elif unsigned:
        GL.glUniform1ui(loc, int(value))
    else:
        GL.glUniform1i(loc, int(value))
