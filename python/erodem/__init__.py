"""erodem — hydrology and hydraulic erosion on real DEMs, from Python.

The package is a thin layer over the C++ core (the extension module ``erodem._erodem``):
parameters are checked by the one C++ schema (the same keys, units and ranges as the TOML
config and ``erodem run --set``), the simulation runs in C++ with the GIL released, and
result files are written by the same writer as ``erodem run``.

Public API (``docs/python.md``): :func:`read_dem`, :class:`DEM`, :class:`Simulation`,
:func:`open_run`, :func:`read_sections`, :func:`sweep` (:exc:`SweepInterrupted`),
:func:`parameter_keys`, :func:`parameter_info`,
:exc:`UnstableError`.
"""

from __future__ import annotations

from . import _erodem
from ._erodem import UnstableError
from ._params import parameter_info, parameter_keys
from .dem import DEM, read_dem
from .results import open_run, read_sections
from .simulation import Simulation

__all__ = [
    "DEM",
    "Simulation",
    "UnstableError",
    "open_run",
    "read_sections",
    "parameter_info",
    "parameter_keys",
    "read_dem",
    "sweep",
    "SweepInterrupted",
]

__version__ = "0.1.0"

#: Names of the fields a Simulation exposes (MODEL.md); all in SI units.
FIELDS = tuple(_erodem.field_names())

# Named as before the split into modules, so that pickles (a DEM pickles as erodem.DEM),
# reprs and help() read as they did.
for _obj in (DEM, Simulation, open_run, parameter_info, parameter_keys, read_dem, read_sections):
    _obj.__module__ = __name__
del _obj

from .sweep import SweepInterrupted, sweep  # noqa: E402  (needs Simulation above)
