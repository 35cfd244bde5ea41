"""Parameter sweeps: many runs of one DEM with different parameters, in parallel worker
processes or on a dask.distributed cluster.

Each member is a full :class:`erodem.Simulation` run in its own process, writing its own
``.h5`` result file; the sweep returns one pandas DataFrame row per member with its
parameters, summary metrics and output path. A member that fails (an unstable run, a bad
value) has its error in its row; the others go on.
"""

from __future__ import annotations

import concurrent.futures
import itertools
import multiprocessing
import os
import tempfile
import time
import traceback
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

#: The metric columns of a sweep's table, with their units.
METRICS = {
    "eroded_volume": "m^3: sum of max(initial bed - bed, 0) * cell area over active cells",
    "deposited_volume": "m^3: sum of max(bed - initial bed, 0) * cell area",
    "outflow_volume": "m^3: net water out through the boundary (ledger boundary_out)",
    "max_depth": "m: the largest max_depth over all steps",
    "closure_error": "1: the water ledger's closure error at the end, relative to the water moved",
    "material_closure_error": "1: the material ledger's closure error at the end, relative to "
    "the material moved",
    "wall_time": "s: wall time of the member (building the simulation and running it)",
}


def _members(
    grid: Optional[Mapping[str, Sequence[Any]]], params: Optional[Iterable[Mapping[str, Any]]]
) -> List[Dict[str, Any]]:
    """The parameter sets of a sweep: the Cartesian product of ``grid`` (in key order, the
    last key varying fastest), or the dicts of ``params``, with keys made dotted."""
    from ._params import _flatten

    if (grid is None) == (params is None):
        raise ValueError("sweep: give exactly one of 'grid' (dict of lists) or 'params' (list)")
    if grid is not None:
        flat = _flatten(grid)
        for k, v in flat.items():
            if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
                raise ValueError("sweep: grid '%s': expected a list of values, got %r" % (k, v))
        keys = list(flat)
        values = [list(flat[k]) for k in keys]
        for k, v in zip(keys, values):
            if not v:
                raise ValueError("sweep: grid '%s': the list of values is empty" % k)
        return [dict(zip(keys, combo)) for combo in itertools.product(*values)]
    members = [_flatten(p) for p in params]
    if not members:
        raise ValueError("sweep: 'params' is empty")
    return members


def run_member(spec: Dict[str, Any]) -> Dict[str, Any]:
    """Runs one sweep member and returns its table row. Never raises for a failing run:
    the error (type and message) goes into the row's ``error`` column.

    ``spec`` holds: ``index``, ``dem`` (a :class:`erodem.DEM`, pickled as its settings),
    ``config``, ``backend``, ``fixed`` and ``params`` (dotted keys), ``output``,
    ``overwrite``, ``threads``. This function is what worker processes and dask workers
    run: ``from erodem.sweep import run_member`` (the name ``erodem.sweep`` is the function).
    """
    import erodem

    row: Dict[str, Any] = {"member": spec["index"]}
    row.update(spec["params"])
    row.update({k: float("nan") for k in METRICS})
    row.update({"steps": 0, "time": float("nan"), "output": spec["output"], "error": ""})
    start = time.perf_counter()
    try:
        settings = dict(spec["fixed"])
        settings.update(spec["params"])
        if spec.get("threads"):
            settings["numerics.threads"] = spec["threads"]
        sim = erodem.Simulation(spec["dem"], spec["backend"], config=spec["config"], **_kw(settings))
        sim.run(output=spec["output"], overwrite=spec["overwrite"])
        eroded, deposited = sim.erosion_volumes()
        ledger = sim.ledger
        row.update(
            eroded_volume=eroded,
            deposited_volume=deposited,
            outflow_volume=ledger["boundary_out"],
            max_depth=sim.peak_depth,
            closure_error=ledger["relative_closure_error"],
            material_closure_error=ledger["relative_material_closure_error"],
            steps=sim.steps_done,
            time=sim.time,
        )
    except Exception as e:  # a failed member is reported in its row
        row["error"] = "%s: %s" % (type(e).__name__, e)
        if not isinstance(e, (ValueError, OSError, RuntimeError)):
            row["error"] += "\n" + traceback.format_exc(limit=3)
        if not os.path.exists(spec["output"]):
            row["output"] = ""
    row["wall_time"] = time.perf_counter() - start
    return row


def _kw(settings: Mapping[str, Any]) -> Dict[str, Any]:
    """Dotted keys as Simulation keywords."""
    return {k.replace(".", "__"): v for k, v in settings.items()}


def _worker_init(threads: int) -> None:
    """Worker process start: OpenMP threads for this worker's share of the cores (0: leave
    the environment as it is)."""
    if threads > 0:
        os.environ["OMP_NUM_THREADS"] = str(threads)


def sweep(
    dem,
    grid: Optional[Mapping[str, Sequence[Any]]] = None,
    params: Optional[Iterable[Mapping[str, Any]]] = None,
    *,
    steps: Optional[int] = None,
    duration: Union[None, float, str] = None,
    backend: str = "cpu",
    workers: Optional[int] = None,
    output_dir: Union[str, os.PathLike, None] = None,
    client=None,
    config: Union[Mapping[str, Any], str, os.PathLike, None] = None,
    every: Union[None, int, float, str] = None,
    overwrite: bool = False,
    threads: Optional[int] = None,
    **fixed: Any,
):
    """Runs one simulation per parameter set over one DEM, in parallel.

    Parameters
    ----------
    dem : erodem.DEM or str
        The terrain every member runs on (:func:`erodem.read_dem`'s result or a path).
    grid : dict, optional
        ``{"erosion.sediment_capacity": [0.01, 0.1], "rain.rate": ["10 mm/h", "40 mm/h"]}``:
        every combination is a member (keys dotted, ``__`` or nested dicts).
    params : list of dict, optional
        Explicit parameter sets instead of ``grid``.
    steps, duration : optional
        The length of every run (``time.steps`` or ``time.duration``; a duration takes a
        unit string). Otherwise the config's.
    backend : {"cpu", "opencl", "auto"}, default "cpu"
    workers : int, optional
        Worker processes (``spawn`` context), default the number of cores; each gets
        ``cores // workers`` OpenMP threads (``numerics.threads``). ``1`` runs the members
        one after another in this process. Ignored with ``client``.
    output_dir : str or path-like, optional
        Folder for the members' ``member_NNN.h5`` files (created if missing); default a
        new temporary folder (``erodem-sweep-*``), reported in the ``output`` column.
    client : dask.distributed.Client, optional
        Run the members on this cluster (``client.map`` of :func:`run_member`) instead of
        local processes: the way a sweep outgrows one machine. The workers need erodem
        installed and the DEM and ``output_dir`` at the same paths (a shared file system).
    config : dict or str, optional
        Base configuration (TOML file or dict), as for :class:`erodem.Simulation`.
    every : int or float or str, optional
        Snapshot interval of the result files (steps, or simulated time).
    overwrite : bool, default False
        Replace existing member files.
    threads : int, optional
        OpenMP threads of each member (``numerics.threads``): default ``cores // workers``
        for local workers (all cores for ``workers=1``), 1 on a dask cluster (one member per
        dask worker thread; size the cluster's workers and threads to match). A
        ``numerics.threads`` in ``config`` or ``fixed`` is used instead when given. Results
        are bit-identical for any thread count.
    **fixed
        Parameters shared by every member (keyword form, ``erosion__enabled=True``).

    Returns
    -------
    pandas.DataFrame
        One row per member, in member order: ``member``, the swept parameters (dotted
        names), the metrics ``eroded_volume``, ``deposited_volume``, ``outflow_volume``
        (m^3), ``max_depth`` (m), ``closure_error`` (1), ``wall_time`` (s), and ``steps``,
        ``time`` (s), ``output`` (path of the ``.h5``), ``error`` ('' when the member ran;
        else the exception type and message, with NaN metrics).

    Raises
    ------
    ValueError
        Bad sweep arguments (``grid``/``params``, ``workers``). Bad parameter values of a
        member are reported in its row.
    """
    import pandas as pd

    from ._params import _flatten
    from .dem import DEM, read_dem

    if not isinstance(dem, DEM):
        dem = read_dem(dem)
    members = _members(grid, params)
    base = _flatten(fixed)
    if steps is not None and duration is not None:
        raise ValueError("sweep: give 'steps' or 'duration', not both")
    if steps is not None:
        base["time.steps"] = int(steps)
    if duration is not None:
        base["time.duration"] = duration
    if every is not None:
        if isinstance(every, int) and not isinstance(every, bool):
            base["output.every"] = every
        else:
            base["output.interval"] = every
    if output_dir is None:
        output_dir = tempfile.mkdtemp(prefix="erodem-sweep-")
    output_dir = os.path.abspath(os.fspath(output_dir))
    os.makedirs(output_dir, exist_ok=True)
    if config is not None and not isinstance(config, Mapping):
        config = os.path.abspath(os.fspath(config))
    cores = os.cpu_count() or 1
    if client is None:
        workers = cores if workers is None else int(workers)
        if workers < 1:
            raise ValueError("sweep: 'workers' must be >= 1, got %d" % workers)
    if threads is None:
        threads = 1 if client is not None else max(1, cores // min(workers, len(members)))
    elif int(threads) < 1:
        raise ValueError("sweep: 'threads' must be >= 1, got %r" % (threads,))
    if "numerics.threads" in base or (
        isinstance(config, Mapping) and "numerics.threads" in _flatten(config)
    ):
        threads = 0  # the caller's numerics.threads
    specs = [
        {
            "index": i,
            "dem": dem,
            "config": config,
            "backend": backend,
            "fixed": base,
            "params": m,
            "output": os.path.join(output_dir, "member_%03d.h5" % i),
            "overwrite": overwrite,
            "threads": threads,
        }
        for i, m in enumerate(members)
    ]
    if client is not None:
        futures = client.map(run_member, specs, pure=False)
        rows = client.gather(futures)
    elif workers == 1:
        rows = [run_member(s) for s in specs]
    else:
        ctx = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(
            max_workers=min(workers, len(specs)),
            mp_context=ctx,
            initializer=_worker_init,
            initargs=(threads,),
        ) as pool:
            rows = list(pool.map(run_member, specs))
    table = pd.DataFrame(rows)
    return table.sort_values("member").reset_index(drop=True)
