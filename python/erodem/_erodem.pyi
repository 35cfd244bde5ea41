"""Type stubs of the extension module erodem._erodem (the C++ core). Use the package
``erodem``; these are its building blocks."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

Settings = Sequence[Tuple[str, str]]

class UnstableError(RuntimeError):
    """The simulation went unstable (NaN, negative depth or CFL violated); the message names
    the step, time and cell. ``exit_code`` is 75."""

    exit_code: int

def parameter_keys() -> List[str]:
    """All dotted parameter keys, in schema order."""

def field_names() -> List[str]:
    """The names of every field, in the order of the C++ field table (fields.cpp)."""

def parameter_info(key: str) -> Dict[str, str]:
    """key, type, unit, accepted, default, doc of one parameter; ValueError if unknown."""

def quoted_string(s: str) -> str:
    """``s`` as a TOML basic string: in double quotes, with ``"``, ``\\`` and control
    characters escaped, as the C++ schema writes strings (``--dump-config``)."""

def duration_seconds(key: str, text: str) -> float:
    """A duration ("10 min", "600") in seconds; ValueError naming ``key`` otherwise."""

def resolve_config(config_path: str, settings: Settings) -> str:
    """The fully resolved configuration (TOML text) of a config file ("" for none) with
    ``settings`` (dotted key, TOML value text) applied and validated."""

def release_opencl_runtimes() -> int:
    """Releases the OpenCL contexts and programs kept for later simulations; returns how many
    are still held by live simulations. Registered with ``atexit`` when the module loads."""

class Terrain:
    """A DEM on its grid, read with its dem.* settings."""

    def __init__(self, settings: Settings) -> None: ...
    @staticmethod
    def from_array(
        z: npt.ArrayLike,
        transform: Sequence[float],
        has_transform: bool,
        cell_size: float,
        crs: str,
        source: str,
        sha256: str,
    ) -> "Terrain":
        """A terrain from elevations in memory (see erodem.DEM.from_array)."""
    @property
    def in_memory(self) -> bool: ...
    @property
    def elevation(self) -> npt.NDArray[np.float32]:
        """Bed elevation (m), (ny, nx), NaN at nodata. A copy."""
    @property
    def mask(self) -> npt.NDArray[np.bool_]:
        """Active cells, (ny, nx). A copy."""
    @property
    def transform(self) -> Tuple[float, float, float, float, float, float]: ...
    @property
    def has_transform(self) -> bool: ...
    @property
    def crs(self) -> str: ...
    @property
    def is_geographic(self) -> bool: ...
    @property
    def dx(self) -> List[float]:
        """East-west cell size per row (m)."""
    @property
    def dy(self) -> List[float]:
        """North-south cell size per row (m)."""
    @property
    def area(self) -> List[float]:
        """Cell area per row (m^2)."""
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def source(self) -> str: ...
    @property
    def sha256(self) -> str: ...

class Simulation:
    """The C++ simulation behind erodem.Simulation."""

    def __init__(
        self,
        config_path: str,
        settings: Settings,
        terrain: Optional[Terrain],
        backend: str,
        restart: str,
        config_from_restart: bool,
        command_line: str,
    ) -> None:
        """An io::RunSession (the run driver of ``erodem run``) without a result file;
        ``restart`` ("FILE[:TIME]" or "") continues a stored run, with its stored config as
        the base when ``config_from_restart``."""
    def advance(
        self,
        max_steps: int,
        to_end: bool,
        until_time: float,
        chunk_seconds: float,
        once: bool,
    ) -> int:
        """Runs up to ``max_steps`` steps (stopping at the configured end when ``to_end``, and
        once the time reaches ``until_time`` s) with the GIL released, in chunks of
        ``chunk_seconds`` wall time; checks signals between chunks (KeyboardInterrupt); with
        ``once`` returns after one chunk. An open result file records every step. Returns
        the steps run."""
    def open_output(self, settings: Settings, overwrite: bool) -> None:
        """Opens a result file (output.* ``settings``) with a first snapshot of the state now."""
    def finish_output(self) -> None:
        """The last snapshot, the .xmf sidecar, the rename into place."""
    def abandon_output(self) -> None:
        """A snapshot of this step (unless it has one); the file stays at its partial name."""
    def close_output(self) -> None:
        """Closes the file as it is, at its partial name."""
    @property
    def output_open(self) -> bool: ...
    @property
    def output_path(self) -> str: ...
    @property
    def output_partial(self) -> str: ...
    @property
    def restart_from(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    def field(self, name: str) -> np.ndarray:
        """A view (CPU) or read-only copy (OpenCL, erosion) of field ``name``."""
    def set_field(self, name: str, values: npt.ArrayLike) -> None: ...
    def erosion_volumes(self) -> Tuple[float, float]:
        """(eroded, deposited) volume (m^3)."""
    @property
    def peak_depth(self) -> float: ...
    @property
    def finished(self) -> bool: ...
    @property
    def progress(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def steps_done(self) -> int: ...
    @property
    def next_dt(self) -> float: ...
    @property
    def ledger(self) -> Dict[str, float]: ...
    @property
    def ledger_text(self) -> str: ...
    @property
    def diagnostics(self) -> Dict[str, float]: ...
    @property
    def sections(self) -> Dict[str, Dict[str, Any]]: ...
    @property
    def backend(self) -> str: ...
    @property
    def device(self) -> str: ...
    @property
    def config_toml(self) -> str: ...
    @property
    def configured_steps(self) -> int: ...
    @property
    def configured_duration(self) -> float: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def area(self) -> List[float]: ...
    @property
    def active(self) -> npt.NDArray[np.bool_]:
        """Active cells (ny, nx), False at nodata. A copy."""
