"""Simulations: :class:`Simulation`, a thin layer over the C++ run driver (``io::RunSession``
through ``_erodem.Simulation``): parameters from keywords, the GIL released per chunk of
steps, Ctrl-C, the tqdm bar and result files written as ``erodem run`` writes them."""

from __future__ import annotations

import math
import os
import shlex
import sys
import warnings
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np

from . import _erodem
from ._params import Settings, _settings
from .dem import DEM, _is_dataarray, read_dem


def _progress_bar(total: float, unit: str):
    from tqdm.auto import tqdm

    return tqdm(total=total, unit=unit, dynamic_ncols=True, leave=True)


class Simulation:
    """One run of the model on a DEM, on the CPU reference or the OpenCL backend.

    Parameters
    ----------
    dem : DEM or str or path-like, optional
        The terrain (:func:`read_dem`'s result, or a path read with default settings). Its
        ``dem.*`` settings replace those of ``config``. Without it, the config's ``dem.*``
        keys (or ``dem__path=...``) give the DEM.
    backend : {"auto", "cpu", "opencl"}, default "auto"
        ``auto``: an OpenCL GPU, else the CPU reference (faster than OpenCL on the CPU).
    config : dict or str or path-like, optional
        A TOML config file (relative raster paths in it resolve against its folder), or a
        dict of parameters (nested or dotted keys). Applied before ``params``.
    **params
        Parameters by their dotted config names with ``__`` for the dot
        (``erosion__sediment_capacity=0.1``), or nested dicts (``erosion={"enabled":
        True}``). Values are numbers in SI units, booleans, strings with a unit
        (``"20 mm/h"``), or lists, exactly as in TOML.

    Raises
    ------
    ValueError
        A parameter is unknown or out of range (the message names it and the accepted
        range), or the backend name is unknown or not available.
    FileNotFoundError
        The config or DEM file is missing.

    Notes
    -----
    Field properties (``bed``, ``water_depth``, ``sediment``, ``velocity_x``,
    ``velocity_y``, and :meth:`field` for the others) on the CPU backend are numpy views of
    the simulation's own memory, without copying: writing into ``sim.water_depth[...]``
    changes the state. A view is valid until the next step (processes write into a second
    buffer and swap), so take a fresh one after stepping; it keeps the simulation alive. On
    OpenCL, and for the derived field ``erosion``, they are read-only copies; assigning
    (``sim.water_depth = a``) uploads on every backend. A change made from Python is not in
    the ledger's inputs: it shows as closure error. The next adaptive step sees it (the
    statistics it is chosen from are taken again after a field is read or set).

    Not thread-safe: use one simulation from one thread at a time.
    """

    def __init__(
        self,
        dem: Union[DEM, str, os.PathLike, None] = None,
        backend: str = "auto",
        *,
        config: Union[Mapping[str, Any], str, os.PathLike, None] = None,
        restart: Union[str, os.PathLike, Tuple[Any, Any], None] = None,
        **params: Any,
    ):
        restart_arg = _restart_arg(restart)
        if _is_dataarray(dem):
            dem = DEM.from_array(dem)
        elif isinstance(dem, np.ndarray):
            raise ValueError(
                "Simulation: 'dem' is a numpy array; build the DEM with "
                "erodem.DEM.from_array(z, cell_size=...) (or transform=..., crs=...) and pass it"
            )
        elif dem is not None and not isinstance(dem, DEM):
            dem = read_dem(dem)
        config_path = ""
        settings: Settings = []
        if isinstance(config, Mapping):
            settings += _settings(config)
        elif config is not None:
            config_path = os.fspath(config)
        kw = _settings(params)
        if dem is not None:
            clash = [k for k, _ in kw if k.startswith("dem.")]
            if clash:
                raise ValueError(
                    "parameter '%s': the DEM object gives the dem.* settings; pass it to "
                    "read_dem() instead" % clash[0]
                )
        settings += kw
        self._dem = dem
        self._backend_name = backend
        self._config = config
        self._params = dict(params)
        cmd = "python: " + " ".join(shlex.quote(a) for a in (sys.argv or ["python"]))
        self._sim = _erodem.Simulation(
            config_path,
            settings,
            dem._terrain if dem is not None else None,
            backend,
            restart_arg,
            bool(restart_arg) and config is None,
            cmd,
        )
        for message in self._sim.warnings:
            warnings.warn(message, RuntimeWarning, stacklevel=2)

    # ---- stepping ----

    #: Wall time (s) of one chunk of steps run with the GIL released; Ctrl-C and progress
    #: updates are handled between chunks.
    chunk_seconds = 0.1

    def step(self, n: int = 1) -> None:
        """Runs ``n`` steps (regardless of the configured end).

        The GIL is released while stepping; Ctrl-C raises KeyboardInterrupt between two
        whole steps (within about ``chunk_seconds``), leaving a consistent state.

        Parameters
        ----------
        n : int, default 1
            Number of steps, >= 0.

        Raises
        ------
        ValueError
            ``n`` is not a whole number >= 0 (``1.5`` is refused, not rounded).
        UnstableError
            The state turned NaN or negative, or violated the CFL bound (the message names
            the step, time and cell).
        """
        n = _whole_steps("step", "n", n)
        self._sim.advance(n, False, math.inf, self.chunk_seconds, False)

    def run(
        self,
        steps: Optional[int] = None,
        duration: Union[None, float, str] = None,
        output: Union[str, os.PathLike, None] = None,
        every: Union[None, int, float, str] = None,
        progress: bool = False,
        overwrite: bool = False,
    ) -> Dict[str, float]:
        """Runs the simulation, optionally writing a result file.

        Parameters
        ----------
        steps : int, optional
            Run this many more steps.
        duration : float or str, optional
            Run until ``time`` has advanced by this much (s, or a string such as
            ``"10 min"``); the last step is not shortened to land on it (set
            ``time.duration`` for an exact end).
        output : str or path-like, optional
            Write an ``.h5`` result file as ``erodem run`` does (a snapshot now, diagnostics
            every step, snapshots per ``output.every``/``output.interval``, a final
            snapshot, the ``.xmf`` sidecar). It is written under a name unique to the
            process, ``.<name>.<host>-<pid>.partial``, and renamed when the run completes,
            never over a file another process put at ``output`` meanwhile (``OSError``,
            exit code 73; the partial file keeps the results); after Ctrl-C or an unstable
            step the partial file stays, holding the results so far.
        every : int or float or str, optional
            Snapshot interval: an int is steps (``output.every``), a float or a string
            with a unit is simulated time (``output.interval``, s).
        progress : bool, default False
            Show a tqdm progress bar.
        overwrite : bool, default False
            Replace an existing ``output``.

        With neither ``steps`` nor ``duration`` it runs to the configured end
        (``time.steps`` or ``time.duration``).

        Returns
        -------
        dict
            The ledger at the end (see :attr:`ledger`).

        Raises
        ------
        KeyboardInterrupt
            On Ctrl-C, between two steps; the result file stays at its partial name.
        UnstableError
            As for :meth:`step`; the partial result file keeps the failing step.
        ValueError, OSError
            Bad arguments; an output that exists (without ``overwrite``) or cannot be
            created.
        """
        if steps is not None and duration is not None:
            raise ValueError("run: give 'steps' or 'duration', not both")
        if steps is not None:
            steps = _whole_steps("run", "steps", steps)
        t_end = None
        if duration is not None:
            t_end = self.time + _duration_seconds(duration)
        if output is not None:
            out_settings: Dict[str, Any] = {"output.path": os.fspath(output)}
            if every is not None:
                if isinstance(every, (int, np.integer)) and not isinstance(every, bool):
                    out_settings["output.every"] = int(every)
                    out_settings["output.interval"] = 0.0
                else:
                    out_settings["output.interval"] = every
            # The first snapshot (the state now); then every step is recorded as
            # `erodem run` records it (the same C++ run driver, io::RunSession).
            self._sim.open_output(_settings(out_settings), overwrite)
        elif every is not None:
            raise ValueError("run: 'every' needs 'output'")

        bar = None
        try:
            if progress:
                if steps is not None:
                    bar = _progress_bar(int(steps), "step")
                elif t_end is not None:
                    bar = _progress_bar(t_end - self.time, "s")
                elif self._sim.configured_duration > 0:
                    bar = _progress_bar(self._sim.configured_duration, "s")
                    bar.update(self.time)
                else:
                    bar = _progress_bar(self._sim.configured_steps, "step")
                    bar.update(self.steps_done)
            big = 2**62
            while True:
                t0, n0 = self.time, self.steps_done
                if steps is not None:
                    left = int(steps)
                    if left <= 0:
                        break
                    steps = left - self._sim.advance(
                        left, False, math.inf, self.chunk_seconds, True
                    )
                elif t_end is not None:
                    if self.time >= t_end:
                        break
                    self._sim.advance(big, False, t_end, self.chunk_seconds, True)
                else:
                    if self._sim.finished:
                        break
                    self._sim.advance(big, True, math.inf, self.chunk_seconds, True)
                if bar is not None:
                    bar.update(self.time - t0 if bar.unit == "s" else self.steps_done - n0)
            if self._sim.output_open:
                self._sim.finish_output()  # last snapshot, .xmf, rename into place
        except KeyboardInterrupt:
            if self._sim.output_open:
                self._sim.abandon_output()  # a snapshot of this step; stays .partial
            raise
        finally:
            if bar is not None:
                bar.close()
            if self._sim.output_open:
                self._sim.close_output()  # an error: the partial file stays
        return self.ledger

    # ---- state ----

    def field(self, name: str) -> np.ndarray:
        """Field ``name`` (one of :data:`FIELDS`) as numpy ``(ny, nx)``, SI units.

        A writable view of the simulation's memory on the CPU backend (valid until the
        next step); a read-only copy on OpenCL and for ``erosion``.
        """
        return self._sim.field(name)

    def set_field(self, name: str, values: Any, *, reset_erosion: bool = True) -> None:
        """Replaces field ``name`` with ``values`` (array-like of shape ``(ny, nx)``, SI
        units) on any backend (an upload on OpenCL).

        Values at active cells are checked first and nothing is changed when they are bad:
        they must be finite, and at least 0 for amounts (depths, sediment, snow, soil,
        fluxes, Manning n, rain factor, ...), within [0, 1] for ``hardness``. Values at
        nodata cells are not used (NaN is fine there).

        Setting ``bed`` also sets ``initial_bed`` to the same values, so the edit is the
        new reference of :attr:`erosion` and is not reported as erosion; with
        ``reset_erosion=False`` the initial bed stays, and the edit counts as erosion or
        deposition.

        Raises
        ------
        ValueError
            Unknown field, wrong shape, values that are not real numbers, NaN or infinite
            or out of range at an active cell (the message names the field, the count and
            the first cell), or the derived fields ``erosion`` and ``shear_stress``.
        """
        a = _checked_field(name, values, self.shape, self._active())
        self._sim.set_field(name, a)
        if name == "bed" and reset_erosion:
            self._sim.set_field("initial_bed", a)

    def _active(self) -> np.ndarray:
        """Active cells (bool, ``(ny, nx)``): False at the DEM's nodata cells."""
        if getattr(self, "_mask", None) is None:
            self._mask = np.asarray(self._sim.active)
        return self._mask

    bed = property(
        lambda self: self.field("bed"),
        lambda self, v: self.set_field("bed", v),
        doc="Bed elevation (m), (ny, nx).",
    )
    water_depth = property(
        lambda self: self.field("water_depth"),
        lambda self, v: self.set_field("water_depth", v),
        doc="Water depth (m), (ny, nx).",
    )
    sediment = property(
        lambda self: self.field("sediment"),
        lambda self, v: self.set_field("sediment", v),
        doc="Suspended sediment as an equivalent bed thickness (m), (ny, nx).",
    )
    velocity_x = property(
        lambda self: self.field("velocity_x"),
        lambda self, v: self.set_field("velocity_x", v),
        doc="Eastward velocity (m/s), (ny, nx).",
    )
    velocity_y = property(
        lambda self: self.field("velocity_y"),
        lambda self, v: self.set_field("velocity_y", v),
        doc="Northward velocity (m/s), (ny, nx).",
    )

    @property
    def erosion(self) -> np.ndarray:
        """Initial bed minus bed (m), (ny, nx); negative where material was deposited. A
        read-only copy."""
        return self.field("erosion")

    @property
    def ledger(self) -> Dict[str, float]:
        """The conservation ledger (m^3, cumulative since the start): ``water_initial``,
        ``water``, ``rain``, ``inflow``, ``boundary_out``, ``evaporated``, ``clipped``,
        ``water_exchanged`` (given by cells through their faces), ``closure_error``,
        ``water_moved``, ``relative_closure_error`` (1, of ``water_moved``),
        ``material_initial``, ``material``, ``sediment_out``, ``transport_change``,
        ``eroded``, ``deposited``, ``sediment_exchanged``, ``thermal_moved``,
        ``snow_melted`` (snow to the pack's liquid water), ``snowfall`` and ``rain_on_snow``
        (taken from the depth into the pack), ``snow_runoff`` (the pack's liquid water beyond
        its retention, into the depth), ``sediment_inflow``, ``eroded_bedrock``, ``bed_bulking``,
        ``infiltrated`` and ``soil_drained`` (Green-Ampt: into the soil, and drained from its
        store as it recovers), ``material_closure_error``, ``material_moved``, ``relative_material_closure_error``
        (1, of ``material_moved``). With the physical erosion law the sediment volumes are of
        solid (times ``erosion.sediment_density`` for kg). docs/model.md section 7 defines what
        moved."""
        return dict(self._sim.ledger)

    @property
    def diagnostics(self) -> Dict[str, float]:
        """The last step's diagnostics row (as in the result file's ``diagnostics``)."""
        return dict(self._sim.diagnostics)

    @property
    def sections(self) -> Dict[str, Dict[str, float]]:
        """The cross-sections and outlets after the last step, by name (config order:
        the ``[[section]]`` tables, then the ``[[outlet]]`` tables): ``discharge`` (m^3/s)
        and ``sediment_flux`` (m^3/s of solid) in the step, the cumulative ``volume`` and
        ``sediment_volume`` (m^3), ``peak_discharge`` (m^3/s) and its ``peak_time`` (s, the
        end of its step), and ``outlet`` (bool). Sections count positive from the left to
        the right of the line (walking from its first vertex), outlets out of the grid. The
        result file's ``sections`` group holds every step (:func:`erodem.read_sections`)."""
        return {k: dict(v) for k, v in self._sim.sections.items()}

    def erosion_volumes(self) -> Tuple[float, float]:
        """``(eroded, deposited)`` volume (m^3) so far: sums of the positive and negative
        parts of :attr:`erosion` times the cell areas, over active cells."""
        return tuple(self._sim.erosion_volumes())

    @property
    def peak_depth(self) -> float:
        """The largest ``max_depth`` (m) over the steps run so far."""
        return self._sim.peak_depth

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._sim.time

    @property
    def steps_done(self) -> int:
        """Steps run so far."""
        return self._sim.steps_done

    @property
    def finished(self) -> bool:
        """Whether the configured end (``time.steps`` or ``time.duration``) is reached."""
        return self._sim.finished

    @property
    def restart_from(self) -> str:
        """``"FILE:TIME"`` of the stored state this simulation continued from (``restart``),
        recorded as ``restart_from`` in the result files it writes; ``""`` when it started
        at t = 0."""
        return self._sim.restart_from

    @property
    def backend(self) -> str:
        """``"cpu"`` or ``"opencl"``."""
        return self._sim.backend

    @property
    def device(self) -> str:
        """What runs the kernels, e.g. ``"CPU reference, float32, 2 threads, AVX-512"``."""
        return self._sim.device

    @property
    def shape(self) -> Tuple[int, int]:
        """``(ny, nx)``."""
        return tuple(self._sim.shape)

    @property
    def config_toml(self) -> str:
        """The fully resolved configuration as TOML text (``erodem run --dump-config``)."""
        return self._sim.config_toml

    def __repr__(self) -> str:
        if not hasattr(self, "_sim"):
            return "<erodem.Simulation (not built)>"
        ny, nx = self.shape
        return "<erodem.Simulation %d x %d on %s, step %d, t = %.6g s>" % (
            nx,
            ny,
            self.backend,
            self.steps_done,
            self.time,
        )


#: Fields that hold amounts (>= 0); hardness is also <= 1.
_NON_NEGATIVE = frozenset(
    (
        "water_depth", "sediment", "flux_left", "flux_right", "flux_top", "flux_bottom",
        "hardness", "wetness", "manning_n", "rain_factor", "snow", "snow_liquid",
        "snow_slide_share", "soil_thickness", "infiltrated", "infiltration_ksat",
        "infiltration_suction_deficit", "infiltration_store", "terrain_class", "talus_slope",
    )
)


def _checked_field(name: str, values: Any, shape: Tuple[int, int], active: np.ndarray):
    """``values`` for field ``name`` as float64 ``(ny, nx)``, checked at the active cells;
    ValueError naming the field and the reason otherwise."""
    if name in ("erosion", "shear_stress"):
        raise ValueError(
            "field '%s' is derived (computed from the state when read) and cannot be set%s"
            % (name, "; set bed or initial_bed" if name == "erosion" else "")
        )
    if name not in _erodem.field_names():
        raise ValueError(
            "unknown field '%s' (known: %s)" % (name, ", ".join(_erodem.field_names()))
        )
    a = np.asarray(values)
    if a.dtype == bool or a.dtype.kind not in "iuf":
        raise ValueError("field '%s': expected real numbers, got dtype %s" % (name, a.dtype))
    if a.shape != tuple(shape):
        raise ValueError(
            "field '%s': expected an array of shape %s, got %s" % (name, tuple(shape), a.shape)
        )
    a = np.array(a, dtype=np.float64)
    bad = active & ~np.isfinite(a)
    what = "NaN or infinite"
    if not bad.any() and name in _NON_NEGATIVE:
        bad = active & (a < 0)
        what = "negative"
        if not bad.any() and name == "hardness":
            bad = active & (a > 1)
            what = "above 1 (hardness is within [0, 1])"
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise ValueError(
            "field '%s': %d value(s) at active cells are %s (the first at row %d, column %d: "
            "%r); nothing was changed" % (name, int(bad.sum()), what, r, c, float(a[r, c]))
        )
    return a


def _whole_steps(where: str, arg: str, n: Any) -> int:
    """``n`` as a whole number of steps >= 0; ValueError naming ``arg`` otherwise."""
    if isinstance(n, (bool, np.bool_)):
        raise ValueError("%s: '%s' must be a whole number of steps, got %r" % (where, arg, n))
    if isinstance(n, (int, np.integer)):
        v = int(n)
    elif isinstance(n, (float, np.floating)) and math.isfinite(n) and float(n).is_integer():
        v = int(n)
    else:
        raise ValueError(
            "%s: '%s' must be a whole number of steps, got %r (steps are not split: run "
            "duration=... for a time)" % (where, arg, n)
        )
    if v < 0:
        raise ValueError("%s: '%s' must be >= 0, got %d" % (where, arg, v))
    return v


def _restart_arg(restart: Union[str, os.PathLike, Tuple[Any, Any], None]) -> str:
    """``restart`` as the C++ run driver takes it: ``"FILE"`` or ``"FILE:TIME"``."""
    if restart is None:
        return ""
    if isinstance(restart, (str, os.PathLike)):
        arg = os.fspath(restart)
    elif isinstance(restart, (tuple, list)) and len(restart) == 2:
        path, t = restart
        if not isinstance(path, (str, os.PathLike)):
            raise ValueError("restart: expected (path, time), got a path of type %s"
                             % type(path).__name__)
        arg = os.fspath(path)
        if t is not None:
            if isinstance(t, (int, float, np.integer, np.floating)) and not isinstance(t, bool):
                arg += ":" + repr(float(t))  # the shortest text of the same double
            elif isinstance(t, str):
                arg += ":" + repr(_erodem.duration_seconds("restart", t))
            else:
                raise ValueError("restart: time %r: expected seconds or a string with a unit"
                                 % (t,))
    else:
        raise ValueError(
            "restart: expected \"run.h5\", \"run.h5:TIME\" or (path, time), got %r" % (restart,)
        )
    if not arg:
        raise ValueError("restart: empty path")
    return arg


def _duration_seconds(value: Union[float, str]) -> float:
    """A duration (s, or a string with a unit such as ``"10 min"``) in seconds."""
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        v = float(value)
    else:
        v = _erodem.duration_seconds("duration", str(value))
    if not (math.isfinite(v) and v >= 0):
        raise ValueError("parameter 'duration': expected a time >= 0 (s), got %r" % (value,))
    return v
