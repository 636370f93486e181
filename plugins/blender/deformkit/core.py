"""The compiled `deformkit` module, shipped inside the add-on (its file is named deformkit.*.so, so Python
finds its init function as this package's submodule `deformkit`)."""

from . import deformkit as dk  # noqa: F401  (re-exported)
