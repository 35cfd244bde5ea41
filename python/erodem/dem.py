"""DEMs: :class:`DEM` (a terrain on its grid, with the settings it was read with) and
:func:`read_dem`."""

from __future__ import annotations

import os
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _erodem
from ._params import _settings


class DEM:
    """A DEM on its grid, as :func:`read_dem` returns it.

    It carries the settings it was read with (path, window, resample, z_scale, cell_size,
    crs, nodata_value), so a :class:`Simulation` built on it runs on exactly this terrain,
    and it pickles as those settings (a worker process reads the file again).

    Attributes
    ----------
    elevation : numpy.ndarray
        Bed elevation (m), float32 ``(ny, nx)``, row 0 north, NaN at nodata cells.
    mask : numpy.ndarray
        bool ``(ny, nx)``: True for active cells, False for nodata.
    transform : tuple of 6 float
        GDAL geotransform of the top-left corner (CRS units: metres, or degrees when
        geographic).
    crs : str
        The CRS as WKT ('' when unknown).
    is_geographic : bool
        True for lat/lon grids (cell sizes vary by row).
    dx, dy, area : numpy.ndarray
        Per-row cell sizes (m) and cell areas (m^2), shape ``(ny,)``.
    shape : tuple of int
        ``(ny, nx)``.
    path : str
        The DEM file; ``sha256`` its checksum.
    settings : dict
        The ``dem.*`` settings (dotted keys) it was read with.
    """

    def __init__(self, settings: Mapping[str, Any]):
        self.settings = dict(settings)
        self._terrain = _erodem.Terrain(_settings(self.settings))

    @property
    def elevation(self) -> np.ndarray:
        """Bed elevation (m), float32 ``(ny, nx)``, row 0 north, NaN at nodata cells (a copy)."""
        return self._terrain.elevation

    @property
    def mask(self) -> np.ndarray:
        """Active cells: bool ``(ny, nx)``, False where the DEM is nodata (a copy)."""
        return self._terrain.mask

    @property
    def transform(self) -> Tuple[float, ...]:
        """GDAL geotransform ``(x0, pixel width, 0, y0, 0, pixel height)`` of the top-left
        corner, in the CRS's units (metres, or degrees when geographic)."""
        return tuple(self._terrain.transform)

    @property
    def crs(self) -> str:
        """The CRS as WKT ('' when unknown)."""
        return self._terrain.crs

    @property
    def is_geographic(self) -> bool:
        """True for lat/lon grids, whose cell sizes vary by row."""
        return self._terrain.is_geographic

    @property
    def dx(self) -> np.ndarray:
        """East-west cell size of each row (m), shape ``(ny,)``."""
        return np.asarray(self._terrain.dx)

    @property
    def dy(self) -> np.ndarray:
        """North-south cell size of each row (m), shape ``(ny,)``."""
        return np.asarray(self._terrain.dy)

    @property
    def area(self) -> np.ndarray:
        """Cell area of each row (m^2), shape ``(ny,)``."""
        return np.asarray(self._terrain.area)

    @property
    def shape(self) -> Tuple[int, int]:
        """``(ny, nx)``."""
        return tuple(self._terrain.shape)

    @property
    def path(self) -> str:
        """The DEM file (absolute path)."""
        return self._terrain.source

    @property
    def sha256(self) -> str:
        """SHA-256 of the DEM file's bytes (lower-case hex)."""
        return self._terrain.sha256

    def __reduce__(self):
        return (DEM, (self.settings,))

    def __repr__(self) -> str:
        ny, nx = self.shape
        return "<erodem.DEM %s: %d x %d cells, dx %.4g m>" % (
            self.path,
            nx,
            ny,
            min(self.dx.min(), self.dy.min()),
        )


def read_dem(
    path: Union[str, os.PathLike],
    window: Optional[Sequence[int]] = None,
    resample: Union[None, int, float, str] = None,
    z_scale: float = 1.0,
    cell_size: Union[None, float, str] = None,
    crs: Optional[str] = None,
    nodata_value: Optional[float] = None,
) -> DEM:
    """Reads a DEM (any raster GDAL reads) as the simulation will see it.

    Parameters
    ----------
    path : str or path-like
        The raster file.
    window : sequence of 4 int, optional
        ``(col, row, width, height)`` in pixels: read only that part.
    resample : int or float or str, optional
        Coarser cells by block averaging: an integer factor (``4``), or a cell size in
        metres (``320.0`` or ``"320 m"``, a whole multiple of the file's).
    z_scale : float, default 1.0
        Multiplier of the stored values (e.g. 0.1 for Puget Sound's 0.1 m units).
    cell_size : float or str, optional
        Cell size (m) for files without georeferencing.
    crs : str, optional
        CRS (``"EPSG:32610"``, WKT) for files without one.
    nodata_value : float, optional
        A stored value to treat as nodata (before ``z_scale``).

    Returns
    -------
    DEM

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    ValueError
        Bad settings (naming the ``dem.*`` parameter), or a file GDAL cannot read.
    """
    s: Dict[str, Any] = {"dem.path": os.path.abspath(os.fspath(path))}
    if window is not None:
        s["dem.window"] = [int(v) for v in window]
    if resample is not None:
        if isinstance(resample, (int, np.integer)) and not isinstance(resample, bool):
            s["dem.resample_factor"] = int(resample)
        else:
            s["dem.resample"] = resample
    if z_scale != 1.0:
        s["dem.z_scale"] = z_scale
    if cell_size is not None:
        s["dem.cell_size"] = cell_size
    if crs is not None:
        s["dem.crs"] = crs
    if nodata_value is not None:
        s["dem.nodata_value"] = nodata_value
    return DEM(s)
