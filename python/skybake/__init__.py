"""skybake: neural skies and baked visibility for real-time graphics.

The compiled module ``skybake._core`` binds the C++ library's public API.
Arrays are NumPy arrays of an exact dtype (float32 for geometry, colours and
radiance; uint32 for indices and visibility words), C-contiguous; anything
else raises :class:`skybake.Error` naming the argument. See docs/python.md.
"""

from ._core import *  # noqa: F401,F403
from ._core import Error, version

__version__ = version()
