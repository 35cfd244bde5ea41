"""DEMs: :class:`DEM` (a terrain on its grid, with the settings it was read with, or built
from an array by :meth:`DEM.from_array`) and :func:`read_dem`."""

from __future__ import annotations

import hashlib
import math
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
        self._array_state: Optional[Tuple[Any, ...]] = None
        self._terrain = _erodem.Terrain(_settings(self.settings))

    @classmethod
    def from_array(
        cls,
        z: Any,
        cell_size: Optional[float] = None,
        crs: Any = None,
        transform: Any = None,
        nodata: Optional[float] = None,
    ) -> "DEM":
        """A DEM from elevations already in memory: a numpy array (a synthetic surface, a
        raster read with rasterio) or an ``xarray.DataArray`` with coordinates.

        Parameters
        ----------
        z : array-like or xarray.DataArray
            Elevations (m), 2-D ``(ny, nx)``. NaN marks nodata cells; infinite values are
            refused. A numpy array's row 0 is the north edge unless ``transform`` says
            otherwise (a positive pixel height: the rows are flipped). A DataArray's dims
            are ``(y, x)`` (or ``(lat, lon)``; ``(x, y)`` is transposed; a leading ``band``
            of size 1 is dropped); its coordinates are cell centres, regularly spaced,
            increasing or decreasing (rows and columns are put north-up, west to east).
        cell_size : float, optional
            Square cells of this size (m), for an array without ``transform`` (a projected
            or unknown CRS).
        crs : str or int or CRS object, optional
            ``"EPSG:32611"``, WKT, a PROJ string, an EPSG code, or an object with
            ``to_wkt()`` (pyproj, rasterio). For a DataArray the default is
            ``da.rio.crs`` (with rioxarray installed), else the ``crs`` / ``crs_wkt`` /
            ``spatial_ref`` attribute or the ``spatial_ref`` coordinate's ``crs_wkt``.
            With a geographic CRS the transform is in degrees and the cell sizes and areas
            are geodesic ones on the CRS's ellipsoid (GeographicLib), exactly as
            :func:`read_dem` computes them for a lat/lon file.
        transform : sequence of 6 float or affine.Affine, optional
            GDAL geotransform ``(x0, pixel width, 0, y0, 0, pixel height)`` of the top-left
            corner in the CRS's units (metres without a CRS), or a rasterio/affine
            ``Affine``. Default for a DataArray: from its coordinates.
        nodata : float, optional
            A value that marks nodata cells (besides NaN); for a DataArray the default is
            its ``rio.nodata`` / ``_FillValue`` / ``nodata`` attribute.

        Returns
        -------
        DEM
            Held in memory: ``path`` is ``"<array NX x NY, sha256 ...>"`` (recorded as
            ``dem.path`` in result files), ``sha256`` the checksum of its values and
            georeferencing, ``settings`` empty. It pickles as its values (sweep workers get
            a copy). Parameter rasters (``flow.manning_n = "n.tif"``, ``rain.grids``, ...)
            need a DEM read from a file: give uniform values instead.

        Raises
        ------
        ValueError
            Not 2-D, not real numbers, infinite values, no finite value, irregular
            coordinates, a bad ``cell_size`` / ``transform`` / ``crs``, both or neither of
            ``cell_size`` and ``transform``; the message names the argument.
        """
        if _is_dataarray(z):
            z, transform, crs, nodata = _from_dataarray(z, cell_size, crs, transform, nodata)
        a = np.asarray(z)
        if a.dtype == bool or a.dtype.kind not in "iuf":
            raise ValueError(
                "DEM.from_array: 'z' must hold real numbers (elevations in m), got dtype %s"
                % a.dtype
            )
        if a.ndim != 2 or a.shape[0] < 1 or a.shape[1] < 1:
            raise ValueError(
                "DEM.from_array: 'z' must be a 2-D array (ny, nx), got shape %s" % (a.shape,)
            )
        a = np.array(a, dtype=np.float64)  # a copy: the caller's array is never changed
        if nodata is not None:
            a[a == float(nodata)] = np.nan
        inf = np.isinf(a)
        if inf.any():
            r, c = np.argwhere(inf)[0]
            raise ValueError(
                "DEM.from_array: 'z' holds %d infinite values (the first at row %d, column %d);"
                " use NaN for nodata cells" % (inf.sum(), r, c)
            )
        if not np.isfinite(a).any():
            raise ValueError("DEM.from_array: 'z' has no finite value (every cell is NaN)")
        crs_text = _crs_text(crs)
        ny, nx = a.shape
        if transform is not None and cell_size is not None:
            raise ValueError("DEM.from_array: give 'cell_size' or 'transform', not both")
        if transform is None and cell_size is None:
            raise ValueError(
                "DEM.from_array: give 'cell_size' (m) or 'transform' (the geotransform of the "
                "top-left corner), or a DataArray with x/y coordinates"
            )
        has_transform = transform is not None
        gt = (0.0, 1.0, 0.0, 0.0, 0.0, -1.0)
        size = 0.0
        if has_transform:
            gt = _geotransform(transform)
            x0, px, _, y0, _, py = gt
            if py > 0:  # south-up: rows flipped to north-up
                a = a[::-1]
                y0, py = y0 + ny * py, -py
            if px < 0:  # east to west: columns flipped
                a = a[:, ::-1]
                x0, px = x0 + nx * px, -px
            gt = (x0, px, gt[2], y0, gt[4], py)
        else:
            try:
                size = float(cell_size)
            except (TypeError, ValueError):
                raise ValueError(
                    "DEM.from_array: 'cell_size' must be a length in m, got %r" % (cell_size,)
                ) from None
            if not (math.isfinite(size) and size > 0):
                raise ValueError(
                    "DEM.from_array: 'cell_size' must be a positive length (m), got %r"
                    % (cell_size,)
                )
        a = np.ascontiguousarray(a)
        h = hashlib.sha256(a.astype("<f8").tobytes())
        h.update(repr((a.shape, gt if has_transform else size, crs_text)).encode())
        sha = h.hexdigest()
        source = "<array %d x %d, sha256 %s>" % (nx, ny, sha[:12])
        self = cls.__new__(cls)
        self.settings = {}
        self._terrain = _erodem.Terrain.from_array(
            a, list(gt), has_transform, size, crs_text, source, sha
        )
        self._array_state = (a, gt if has_transform else None, size or None, crs_text)
        return self

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

    @property
    def in_memory(self) -> bool:
        """True for a DEM built by :meth:`from_array` (no file behind it)."""
        return self._array_state is not None

    def __reduce__(self):
        if self._array_state is not None:
            a, gt, size, crs = self._array_state
            return (_dem_from_array, (a, gt, size, crs))
        return (DEM, (self.settings,))

    def __repr__(self) -> str:
        ny, nx = self.shape
        return "<erodem.DEM %s: %d x %d cells, dx %.4g m>" % (
            self.path,
            nx,
            ny,
            min(self.dx.min(), self.dy.min()),
        )


def _dem_from_array(a, transform, cell_size, crs) -> DEM:
    """Unpickles a DEM built by :meth:`DEM.from_array` (its values travel with it)."""
    return DEM.from_array(a, cell_size=cell_size, crs=crs or None, transform=transform)


def _is_dataarray(z: Any) -> bool:
    return type(z).__name__ == "DataArray" and hasattr(z, "dims") and hasattr(z, "coords")


def _crs_text(crs: Any) -> str:
    """A CRS argument as text GDAL reads ('' for none)."""
    if crs is None:
        return ""
    if isinstance(crs, (int, np.integer)) and not isinstance(crs, bool):
        return "EPSG:%d" % crs
    if isinstance(crs, str):
        return crs.strip()
    if hasattr(crs, "to_wkt"):
        return str(crs.to_wkt())
    raise ValueError(
        "DEM.from_array: 'crs' must be a string (\"EPSG:32611\", WKT), an EPSG code or an "
        "object with to_wkt(), got %s" % type(crs).__name__
    )


def _geotransform(transform: Any) -> Tuple[float, ...]:
    """A GDAL geotransform from 6 numbers or an affine.Affine (rasterio)."""
    if hasattr(transform, "to_gdal"):
        transform = transform.to_gdal()
    try:
        gt = tuple(float(v) for v in transform)
    except (TypeError, ValueError):
        raise ValueError(
            "DEM.from_array: 'transform' must be 6 numbers (x0, pixel width, 0, y0, 0, pixel "
            "height) or an Affine, got %r" % (transform,)
        ) from None
    if len(gt) != 6 or not all(math.isfinite(v) for v in gt):
        raise ValueError(
            "DEM.from_array: 'transform' must be 6 finite numbers (x0, pixel width, 0, y0, 0, "
            "pixel height), got %r" % (transform,)
        )
    if gt[1] == 0 or gt[5] == 0:
        raise ValueError("DEM.from_array: 'transform': the pixel width and height must be "
                         "non-zero, got %r" % (gt,))
    if gt[2] != 0 or gt[4] != 0:
        raise ValueError("DEM.from_array: 'transform': rotated grids are not supported "
                         "(terms 2 and 4 must be 0), got %r" % (gt,))
    return gt


_Y_NAMES = ("y", "lat", "latitude", "northing", "rows", "row")
_X_NAMES = ("x", "lon", "long", "longitude", "easting", "cols", "col")


def _from_dataarray(da: Any, cell_size: Any, crs: Any, transform: Any, nodata: Any):
    """Values, transform, CRS and nodata of an xarray.DataArray (see DEM.from_array)."""
    if da.ndim == 3 and da.shape[0] == 1:
        da = da.isel({da.dims[0]: 0}, drop=True)  # rioxarray's band dimension
    if da.ndim != 2:
        raise ValueError(
            "DEM.from_array: the DataArray must be 2-D (y, x), got dims %s with shape %s"
            % (tuple(da.dims), tuple(da.shape))
        )
    d0, d1 = (str(d).lower() for d in da.dims)
    if d0 in _X_NAMES and d1 in _Y_NAMES:
        da = da.transpose()
        d0, d1 = d1, d0
    ydim, xdim = da.dims
    rio_crs = rio_nodata = None
    try:
        import rioxarray  # noqa: F401  (registers the .rio accessor)

        rio_crs, rio_nodata = da.rio.crs, da.rio.nodata
    except Exception:  # no rioxarray, or an array it cannot read: the attributes below
        pass
    if crs is None:
        if rio_crs is not None:
            crs = rio_crs
        else:
            for key in ("crs", "crs_wkt", "spatial_ref"):
                if isinstance(da.attrs.get(key), str) and da.attrs[key]:
                    crs = da.attrs[key]
                    break
            if crs is None:
                gm = da.attrs.get("grid_mapping", "spatial_ref")
                if gm in da.coords:
                    attrs = da.coords[gm].attrs
                    crs = attrs.get("crs_wkt") or attrs.get("spatial_ref") or None
    if nodata is None:
        nodata = rio_nodata
    if nodata is None:
        for key in ("_FillValue", "nodata", "missing_value"):
            v = da.attrs.get(key, da.encoding.get(key) if hasattr(da, "encoding") else None)
            if v is not None:
                nodata = v
                break
    if nodata is not None and isinstance(nodata, float) and math.isnan(nodata):
        nodata = None
    if transform is None and cell_size is None:
        coords = []
        for dim in (xdim, ydim):
            if dim not in da.coords:
                raise ValueError(
                    "DEM.from_array: the DataArray has no coordinate '%s': give 'cell_size' "
                    "or 'transform'" % dim
                )
            v = np.asarray(da.coords[dim].values, dtype=np.float64)
            if v.size < 2:
                raise ValueError(
                    "DEM.from_array: coordinate '%s' has %d value(s); a spacing needs 2: give "
                    "'cell_size' or 'transform'" % (dim, v.size)
                )
            step = np.diff(v)
            if not (np.all(np.isfinite(v)) and step[0] != 0
                    and np.allclose(step, step[0], rtol=1e-6, atol=0)):
                raise ValueError(
                    "DEM.from_array: coordinate '%s' is not regularly spaced (steps from %r to "
                    "%r); erodem needs a regular grid" % (dim, float(step.min()), float(step.max()))
                )
            spacing = (v[-1] - v[0]) / (v.size - 1)
            coords.append((v[0] - spacing / 2, spacing))
        (x0, px), (y0, py) = coords
        transform = (x0, px, 0.0, y0, 0.0, py)
        if crs is None and (d0 in ("lat", "latitude") or d1 in ("lon", "long", "longitude")):
            raise ValueError(
                "DEM.from_array: coordinates '%s'/'%s' look like degrees but no CRS is given: "
                "pass crs=\"EPSG:4326\" (or the DataArray's geographic CRS)" % (ydim, xdim)
            )
    return da.values, transform, crs, nodata


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
