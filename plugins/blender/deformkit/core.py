"""The compiled `deformkit` module, shipped inside the add-on (its file is named deformkit.*.so, so Python
finds its init function as this package's submodule `deformkit`).

Inside Blender the library's OpenMP threads share the cores with Blender's own: waiting threads sleep
instead of spinning (OMP_WAIT_POLICY=PASSIVE, read when the module loads), unless the user set a policy."""

import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from . import deformkit as dk  # noqa: E402,F401  (re-exported)
