"""Type stubs of the public erodem API (docs/python.md)."""

import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._erodem import UnstableError as UnstableError

__version__: str
FIELDS: Tuple[str, ...]

_Path = Union[str, os.PathLike]
_Quantity = Union[int, float, str]

def parameter_keys() -> List[str]: ...
def parameter_info(key: str) -> Dict[str, str]: ...

class DEM:
    settings: Dict[str, Any]
    def __init__(self, settings: Mapping[str, Any]) -> None: ...
    @classmethod
    def from_array(
        cls,
        z: Any,
        cell_size: Optional[float] = ...,
        crs: Any = ...,
        transform: Any = ...,
        nodata: Optional[float] = ...,
    ) -> "DEM": ...
    @property
    def in_memory(self) -> bool: ...
    @property
    def elevation(self) -> npt.NDArray[np.float32]: ...
    @property
    def mask(self) -> npt.NDArray[np.bool_]: ...
    @property
    def transform(self) -> Tuple[float, ...]: ...
    @property
    def crs(self) -> str: ...
    @property
    def is_geographic(self) -> bool: ...
    @property
    def dx(self) -> npt.NDArray[np.float64]: ...
    @property
    def dy(self) -> npt.NDArray[np.float64]: ...
    @property
    def area(self) -> npt.NDArray[np.float64]: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def path(self) -> str: ...
    @property
    def sha256(self) -> str: ...

def read_dem(
    path: _Path,
    window: Optional[Sequence[int]] = ...,
    resample: Union[None, int, float, str] = ...,
    z_scale: float = ...,
    cell_size: Union[None, float, str] = ...,
    crs: Optional[str] = ...,
    nodata_value: Optional[float] = ...,
) -> DEM: ...

class Simulation:
    chunk_seconds: float
    def __init__(
        self,
        dem: Union[DEM, _Path, None] = ...,
        backend: str = ...,
        *,
        config: Union[Mapping[str, Any], _Path, None] = ...,
        restart: Union[_Path, Tuple[_Path, Union[float, str, None]], None] = ...,
        **params: Any,
    ) -> None: ...
    def step(self, n: int = ...) -> None: ...
    def run(
        self,
        steps: Optional[int] = ...,
        duration: Optional[_Quantity] = ...,
        output: Optional[_Path] = ...,
        every: Optional[_Quantity] = ...,
        progress: bool = ...,
        overwrite: bool = ...,
    ) -> Dict[str, float]: ...
    def field(self, name: str) -> np.ndarray: ...
    def set_field(
        self, name: str, values: npt.ArrayLike, *, reset_erosion: bool = ...
    ) -> None: ...
    bed: np.ndarray
    water_depth: np.ndarray
    sediment: np.ndarray
    velocity_x: np.ndarray
    velocity_y: np.ndarray
    @property
    def erosion(self) -> np.ndarray: ...
    @property
    def ledger(self) -> Dict[str, float]: ...
    @property
    def diagnostics(self) -> Dict[str, float]: ...
    @property
    def sections(self) -> Dict[str, Dict[str, float]]: ...
    def erosion_volumes(self) -> Tuple[float, float]: ...
    @property
    def peak_depth(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def steps_done(self) -> int: ...
    @property
    def restart_from(self) -> str: ...
    @property
    def finished(self) -> bool: ...
    @property
    def backend(self) -> str: ...
    @property
    def device(self) -> str: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def config_toml(self) -> str: ...

def open_run(path: _Path, group: Optional[str] = ...) -> Any:
    """An xarray.Dataset of the result file."""

def read_sections(path: _Path) -> Any:
    """A pandas.DataFrame of the result file's cross-sections and outlets."""

def sweep(
    dem: Union[DEM, _Path],
    grid: Optional[Mapping[str, Sequence[Any]]] = ...,
    params: Optional[Iterable[Mapping[str, Any]]] = ...,
    *,
    steps: Optional[int] = ...,
    duration: Optional[_Quantity] = ...,
    backend: str = ...,
    workers: Optional[int] = ...,
    output_dir: Optional[_Path] = ...,
    client: Any = ...,
    config: Union[Mapping[str, Any], _Path, None] = ...,
    every: Optional[_Quantity] = ...,
    overwrite: bool = ...,
    resume: bool = ...,
    progress: bool = ...,
    threads: Optional[int] = ...,
    **fixed: Any,
) -> Any:
    """A pandas.DataFrame, one row per member."""

class SweepInterrupted(KeyboardInterrupt):
    table: Any
    output_dir: str
