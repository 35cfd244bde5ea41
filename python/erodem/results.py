"""Result files: :func:`open_run` (an ``.h5`` result file as an ``xarray.Dataset``) and
:func:`read_sections` (its cross-sections and outlets as a ``pandas.DataFrame``)."""

from __future__ import annotations

import os
from typing import Optional, Union


def open_run(path: Union[str, os.PathLike], group: Optional[str] = None):
    """Opens a result file (``.h5``, also a partial one) as an ``xarray.Dataset``.

    Parameters
    ----------
    path : str or path-like
        The result file.
    group : {None, "diagnostics", "gauges", "sections"}, optional
        None: the fields over ``(time, y, x)`` with coordinates, CRS and root attributes
        (``config_toml``, ``backend``, ...). ``"diagnostics"``: the per-step series over
        ``step``. ``"gauges"``: the gauge series. ``"sections"``: the cross-section and
        outlet series over ``(step, section)`` (names in the group attribute
        ``section_names``; :func:`read_sections` gives them as a DataFrame).

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

    return xr.open_dataset(_existing(path), engine="h5netcdf", group=group)


def _existing(path: Union[str, os.PathLike]) -> str:
    """The path as a string; FileNotFoundError when there is no such file."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError("%s: no such result file" % p)
    return p


SECTION_SERIES = ("discharge", "sediment_flux", "volume", "sediment_volume")


def read_sections(path: Union[str, os.PathLike]):
    """The cross-sections and outlets of a result file, one row per step.

    Parameters
    ----------
    path : str or path-like
        The result file (also a partial one).

    Returns
    -------
    pandas.DataFrame
        Indexed by ``time`` (s, the end of each step), with a ``step`` column and, for every
        section or outlet (by its name) and series, a column ``(name, series)``:
        ``discharge`` (m^3/s) and ``sediment_flux`` (m^3/s of solid) in the step,
        ``volume`` and ``sediment_volume`` (m^3, cumulative). ``df["bridge"]["discharge"]``
        is one section's hydrograph. Sections count positive from the left to the right
        of their line (walking from the first vertex), outlets out of the grid. A run
        without sections gives an empty DataFrame.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    """
    import h5py
    import pandas as pd

    with h5py.File(_existing(path), "r") as f:
        if "sections" not in f:
            return pd.DataFrame()
        g = f["sections"]
        raw = g.attrs["section_names"]
        names = (raw.decode() if isinstance(raw, bytes) else str(raw)).split(",")
        time = g["time"][:]
        columns = {("step", ""): g["step"][:]}
        for k, name in enumerate(names):
            for series in SECTION_SERIES:
                columns[(name, series)] = g[series][:, k]
    df = pd.DataFrame(columns, index=pd.Index(time, name="time"))
    df.columns = pd.MultiIndex.from_tuples(df.columns)
    return df
