"""Result files: :func:`open_run` (an ``.h5`` result file as an ``xarray.Dataset``)."""

from __future__ import annotations

import os
from typing import Optional, Union


def open_run(path: Union[str, os.PathLike], group: Optional[str] = None):
    """Opens a result file (``.h5``, also a partial one) as an ``xarray.Dataset``.

    Parameters
    ----------
    path : str or path-like
        The result file.
    group : {None, "diagnostics", "gauges"}, optional
        None: the fields over ``(time, y, x)`` with coordinates, CRS and root attributes
        (``config_toml``, ``backend``, ...). ``"diagnostics"``: the per-step series over
        ``step``. ``"gauges"``: the gauge series.

    Returns
    -------
    xarray.Dataset
        Lazily loaded (h5netcdf engine); close it, or use it in a ``with`` block.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    """
    import xarray as xr

    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError("%s: no such result file" % p)
    return xr.open_dataset(p, engine="h5netcdf", group=group)
