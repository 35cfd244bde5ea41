"""Parameter sweeps: many runs of one DEM with different parameters, in parallel worker
processes or on a dask.distributed cluster.

Each member is a full :class:`erodem.Simulation` run in its own process, writing its own
``.h5`` result file; the sweep returns one pandas DataFrame row per member with its
parameters, summary metrics and output path. A member that fails (an unstable run, a bad
value) has its error in its row; the others go on.

Local worker processes run ``python -m erodem._sweep_worker`` and receive plain data, so a
sweep runs the same from a script with or without an ``if __name__ == "__main__":`` guard,
from stdin (``python - <<EOF``) and from a notebook: nothing of the caller's ``__main__`` is
imported in a worker.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
import traceback
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

#: The metric columns of a sweep's table (numbers in SI, the unit in the column name).
METRICS = {
    "eroded_volume [m^3]": "sum of max(initial bed - bed, 0) * cell area over active cells",
    "deposited_volume [m^3]": "sum of max(bed - initial bed, 0) * cell area",
    "outflow_volume [m^3]": "net water out through the boundary (ledger boundary_out)",
    "max_depth [m]": "the largest max_depth over all steps",
    "closure_error": "the water ledger's closure error at the end, relative to the water moved",
    "material_closure_error": "the material ledger's closure error at the end, relative to "
    "the material moved",
    "wall_time [s]": "wall time of the member (building the simulation and running it)",
}

#: The sweep table's file names in ``output_dir`` (the CSV always, Parquet with pyarrow).
TABLE_CSV = "sweep.csv"
TABLE_PARQUET = "sweep.parquet"


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`sweep`: the workers are stopped at once; ``table`` holds the
    rows of the members that finished (also written to ``output_dir``), and running the
    same sweep into the same ``output_dir`` again resumes it (finished members are
    skipped)."""

    def __init__(self, message: str, table: Any, output_dir: str):
        super().__init__(message)
        self.table = table
        self.output_dir = output_dir


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


def _remove_stale_partials(output: str) -> None:
    """Removes the partial files of ``output`` (``.<name>.<host>-<pid>.partial``, and the
    ``.<name>.partial`` of erodem before 2026-11-27) that no running process on this host
    writes: those of this host whose process has ended. Those of other hosts stay."""
    import socket

    folder, name = os.path.split(output)
    host = "".join(c if c.isalnum() or c in "._-" else "_" for c in socket.gethostname())
    prefix = "." + name + "." + host + "-"
    legacy = os.path.join(folder, "." + name + ".partial")
    if os.path.exists(legacy):
        os.remove(legacy)
    for entry in os.listdir(folder or "."):
        pid = entry[len(prefix):-len(".partial")]
        if not (entry.startswith(prefix) and entry.endswith(".partial") and pid.isdigit()):
            continue
        try:
            os.kill(int(pid), 0)
            continue  # still running
        except ProcessLookupError:
            pass
        except PermissionError:
            continue  # another user's live process
        os.remove(os.path.join(folder, entry))


def run_member(spec: Dict[str, Any]) -> Dict[str, Any]:
    """Runs one sweep member and returns its table row. Never raises for a failing run:
    the error (type and message) goes into the row's ``error`` column.

    ``spec`` holds: ``index``, ``dem`` (a :class:`erodem.DEM`, pickled as its settings or
    values), ``config``, ``backend``, ``fixed`` and ``params`` (dotted keys), ``output``,
    ``overwrite``, ``threads``, ``config_hash``. This function is what worker processes and
    dask workers run: ``from erodem.sweep import run_member`` (the name ``erodem.sweep`` is
    the function).
    """
    import erodem

    row: Dict[str, Any] = {"member": spec["index"]}
    row.update({k: float("nan") for k in METRICS})
    row.update({"steps": 0, "time [s]": float("nan"), "output": spec["output"], "error": ""})
    start = time.perf_counter()
    try:
        settings = dict(spec["fixed"])
        settings.update(spec["params"])
        if spec.get("threads"):
            settings["numerics.threads"] = spec["threads"]
        if not os.path.exists(spec["output"]):
            _remove_stale_partials(spec["output"])  # unfinished files of an interrupted sweep
        row_file = spec["output"][:-3] + ".json"
        if spec.get("config_hash"):
            # claims the member's files for this configuration before the result file exists:
            # a sweep resumed after the result file was completed but before its row was
            # written here runs the member again (its file is known to be this member's)
            _write_json(row_file, {"member": spec["index"], "config_hash": spec["config_hash"],
                                   "finished": False})
        sim = erodem.Simulation(spec["dem"], spec["backend"], config=spec["config"], **_kw(settings))
        sim.run(output=spec["output"], overwrite=spec["overwrite"])
        eroded, deposited = sim.erosion_volumes()
        ledger = sim.ledger
        row.update({
            "eroded_volume [m^3]": eroded,
            "deposited_volume [m^3]": deposited,
            "outflow_volume [m^3]": ledger["boundary_out"],
            "max_depth [m]": sim.peak_depth,
            "closure_error": ledger["relative_closure_error"],
            "material_closure_error": ledger["relative_material_closure_error"],
            "steps": sim.steps_done,
            "time [s]": sim.time,
        })
    except Exception as e:  # a failed member is reported in its row
        row["error"] = "%s: %s" % (type(e).__name__, e)
        if not isinstance(e, (ValueError, OSError, RuntimeError)):
            row["error"] += "\n" + traceback.format_exc(limit=3)
        if not os.path.exists(spec["output"]):
            row["output"] = ""
    row["wall_time [s]"] = time.perf_counter() - start
    if spec.get("config_hash"):
        _write_json(spec["output"][:-3] + ".json",
                    dict(row, config_hash=spec["config_hash"], finished=True))
    return row


def _write_json(path: str, data: Dict[str, Any]) -> None:
    """Writes ``data`` to ``path`` whole or not at all (a temporary file renamed)."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


def _kw(settings: Mapping[str, Any]) -> Dict[str, Any]:
    """Dotted keys as Simulation keywords."""
    return {k.replace(".", "__"): v for k, v in settings.items()}


def _resolved(dem, config, settings: Mapping[str, Any]) -> Optional[Dict[str, Any]]:
    """The fully resolved configuration of a member (SI values) as a dict with its TOML
    text under ``""``; None when its parameters do not validate (the run reports why)."""
    from . import _erodem
    from ._params import _flatten, _settings

    s = []
    if isinstance(config, Mapping):
        s += [kv for kv in _settings(config) if not kv[0].startswith("dem.")]
    s += _settings(settings)
    dem_settings = dict(dem.settings) if dem.settings else {"dem.path": dem.path}
    s += _settings(dem_settings)
    try:
        text = _erodem.resolve_config(config if isinstance(config, str) else "", s)
    except (ValueError, OSError):
        return None
    try:
        import tomllib
    except ImportError:  # Python < 3.11: hash only, no SI values
        return {"": text}
    values = _flatten(tomllib.loads(text))
    values[""] = text
    return values


def _config_hash(resolved: Optional[Dict[str, Any]], dem, backend: str,
                 settings: Mapping[str, Any]) -> str:
    """16 hex digits of SHA-256 over what decides a member's result: its resolved config
    (or, when it does not validate, its settings), the DEM's checksum and the backend."""
    h = hashlib.sha256()
    h.update((resolved[""] if resolved else repr(sorted(settings.items()))).encode())
    h.update(dem.sha256.encode())
    h.update(backend.encode())
    return h.hexdigest()[:16]


def _column_values(members: List[Dict[str, Any]], resolved: List[Optional[Dict[str, Any]]]):
    """The swept parameters as table columns: a parameter with a unit as numbers in SI under
    ``"key [unit]"`` (strings such as ``"40 mm/h"`` converted), others as given."""
    from ._params import parameter_info

    keys: List[str] = []
    for m in members:
        keys += [k for k in m if k not in keys]
    columns: Dict[str, List[Any]] = {}
    for k in keys:
        try:
            info = parameter_info(k)
        except ValueError:
            info = {"unit": "", "type": ""}
        unit = info["unit"]
        if unit in ("", "1") or not info["type"].startswith("number"):
            columns[k] = [m.get(k) for m in members]
            continue
        col = []
        for m, r in zip(members, resolved):
            v = r.get(k) if r else None
            if not isinstance(v, (int, float)) or isinstance(v, bool):
                raw = m.get(k)
                v = float(raw) if isinstance(raw, (int, float)) and not isinstance(raw, bool) \
                    else float("nan")
            col.append(float(v))
        columns["%s [%s]" % (k, unit)] = col
    return columns


class _Progress:
    """Members done and failed with an ETA: a tqdm bar when tqdm is installed, else a line
    on stderr rewritten in place (a new line each time when stderr is not a terminal)."""

    def __init__(self, total: int, skipped: int, enabled: bool):
        self.total, self.done, self.failed = total, 0, 0
        self.start = time.perf_counter()
        self.bar = None
        if enabled and skipped:
            print("sweep: %d member(s) already finished in output_dir, skipped" % skipped,
                  file=sys.stderr, flush=True)
        self.enabled = enabled and total > 0
        if not self.enabled:
            return
        try:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, unit="member", desc="sweep", dynamic_ncols=True)
        except ImportError:
            self._line()

    def update(self, failed: bool) -> None:
        self.done += 1
        self.failed += int(failed)
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(1)
        else:
            self._line()

    def _line(self) -> None:
        eta = "?"
        if self.done:
            left = (time.perf_counter() - self.start) / self.done * (self.total - self.done)
            eta = "%d:%02d" % divmod(int(round(left)), 60)
        end = "\n" if self.done == self.total or not sys.stderr.isatty() else ""
        print("\rsweep: %d/%d members done, %d failed, ETA %s"
              % (self.done, self.total, self.failed, eta), end=end, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.enabled and self.done < self.total:
            print(file=sys.stderr)


def _worker_env(threads: int) -> Dict[str, str]:
    """The environment of a worker process: this erodem importable first, and OpenMP
    threads for its share of the cores (0: as it is)."""
    import erodem

    env = dict(os.environ)
    here = os.path.dirname(os.path.dirname(os.path.abspath(erodem.__file__)))
    env["PYTHONPATH"] = os.pathsep.join(
        [here] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    )
    if threads > 0:
        env["OMP_NUM_THREADS"] = str(threads)
    return env


class _Worker:
    """One ``python -m erodem._sweep_worker`` process and its two pipes."""

    def __init__(self, env: Dict[str, str]):
        from multiprocessing.connection import Connection

        req_r, req_w = os.pipe()
        res_r, res_w = os.pipe()
        try:
            # its own session: a terminal's Ctrl-C reaches only the parent, which ends it
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "erodem._sweep_worker", str(req_r), str(res_w)],
                pass_fds=(req_r, res_w), stdin=subprocess.DEVNULL, env=env,
                start_new_session=True,
            )
        finally:
            os.close(req_r)
            os.close(res_w)
        self.requests = Connection(req_w, readable=False)
        self.results = Connection(res_r, writable=False)
        self.spec: Optional[Dict[str, Any]] = None

    def send(self, spec: Optional[Dict[str, Any]]) -> None:
        self.spec = spec
        self.requests.send(spec)

    def stop(self, kill: bool) -> None:
        if kill:
            self.proc.kill()
        else:
            try:
                self.requests.send(None)
            except OSError:
                pass
        self.requests.close()
        self.results.close()
        self.proc.wait()


def _run_local(specs, workers: int, threads: int, on_row) -> None:
    """Runs ``specs`` on ``workers`` worker processes, calling ``on_row(row)`` for each
    result in the order they finish. A worker that dies fails its member (its row says
    so) and is replaced. Ctrl-C kills the workers at once."""
    from multiprocessing.connection import wait

    env = _worker_env(threads)
    todo = list(specs)
    pool: List[_Worker] = []
    try:
        for _ in range(min(workers, len(todo))):
            w = _Worker(env)
            pool.append(w)
            w.send(todo.pop(0))
        while any(w.spec is not None for w in pool):
            busy = {w.results: w for w in pool if w.spec is not None}
            for conn in wait(list(busy)):
                w = busy[conn]
                try:
                    row = conn.recv()
                except (EOFError, OSError):
                    code = w.proc.wait()
                    row = _failed_row(w.spec, "worker process died (exit code %s)" % code)
                    pool.remove(w)
                    w.stop(kill=True)
                    w = _Worker(env)
                    pool.append(w)
                w.spec = None
                on_row(row)
                if todo:
                    w.send(todo.pop(0))
        for w in pool:
            w.stop(kill=False)
        pool = []
    finally:
        for w in pool:
            w.stop(kill=True)


def _failed_row(spec: Dict[str, Any], error: str) -> Dict[str, Any]:
    row: Dict[str, Any] = {"member": spec["index"]}
    row.update({k: float("nan") for k in METRICS})
    row.update({"steps": 0, "time [s]": float("nan"), "output": "", "error": error})
    return row


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
    resume: bool = True,
    progress: bool = True,
    threads: Optional[int] = None,
    **fixed: Any,
):
    """Runs one simulation per parameter set over one DEM, in parallel.

    Parameters
    ----------
    dem : erodem.DEM or str
        The terrain every member runs on (:func:`erodem.read_dem`'s or
        :meth:`erodem.DEM.from_array`'s result, or a path).
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
        Worker processes, default the number of cores; each gets ``cores // workers``
        OpenMP threads (``numerics.threads``). ``1`` runs the members one after another in
        this process. Ignored with ``client``. Workers run ``python -m
        erodem._sweep_worker`` and import only erodem: no ``if __name__ == "__main__":``
        guard is needed, and sweeps run from stdin and notebooks.
    output_dir : str or path-like, optional
        Folder for the members' ``member_NNN.h5`` files (created if missing), their rows
        (``member_NNN.json``) and the sweep table (``sweep.csv``, and ``sweep.parquet``
        when pyarrow is installed); default a new temporary folder (``erodem-sweep-*``).
    client : dask.distributed.Client, optional
        Run the members on this cluster (``client.map`` of :func:`run_member`) instead of
        local processes: the way a sweep outgrows one machine. The workers need erodem
        installed and the DEM and ``output_dir`` at the same paths (a shared file system).
    config : dict or str, optional
        Base configuration (TOML file or dict), as for :class:`erodem.Simulation`.
    every : int or float or str, optional
        Snapshot interval of the result files (steps, or simulated time).
    overwrite : bool, default False
        Run every member again, replacing its files.
    resume : bool, default True
        Skip the members whose result file in ``output_dir`` is complete and was written
        with the same configuration (the same ``config_hash``; their rows are read back).
        A result file of another configuration, or one without its row file, stops the
        sweep before anything runs (pass ``overwrite=True`` or another ``output_dir``).
        ``resume=False`` with existing member files is refused the same way.
    progress : bool, default True
        Show members done and failed with an ETA (tqdm when installed, else a line on
        stderr).
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
        One row per member, in member order: ``member``, ``config_hash`` (16 hex digits of
        SHA-256 over the member's resolved configuration, the DEM's checksum and the
        backend), the swept parameters (dotted names; those with a unit as numbers in SI
        named ``"key [unit]"``, e.g. ``"rain.rate [m/s]"``), the metrics
        ``eroded_volume [m^3]``, ``deposited_volume [m^3]``, ``outflow_volume [m^3]``,
        ``max_depth [m]``, ``closure_error``, ``material_closure_error`` (1),
        ``wall_time [s]``, and ``steps``, ``time [s]``, ``output`` (path of the ``.h5``),
        ``error`` ('' when the member ran; else the exception type and message, with NaN
        metrics). The same table is written to ``output_dir``.

    Raises
    ------
    ValueError
        Bad sweep arguments (``grid``/``params``, ``workers``), or member files in
        ``output_dir`` that resuming cannot use. Bad parameter values of a member are
        reported in its row.
    SweepInterrupted
        (a KeyboardInterrupt) on Ctrl-C: the workers are stopped at once, the finished rows
        are in its ``table`` and in ``output_dir``; run the same call again to resume.
    """
    import pandas as pd

    from ._params import _flatten
    from .dem import DEM, _is_dataarray, read_dem

    if _is_dataarray(dem):
        dem = DEM.from_array(dem)
    elif not isinstance(dem, DEM):
        dem = read_dem(dem)
    members = _members(grid, params)
    base = _flatten(fixed)
    for k in list(base) + [k for m in members for k in m]:
        if k.startswith("dem."):
            raise ValueError(
                "sweep: parameter '%s': the DEM object gives the dem.* settings; pass it to "
                "read_dem() (one DEM per sweep)" % k
            )
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
    resolved = []
    specs = []
    for i, m in enumerate(members):
        settings = dict(base)
        settings.update(m)
        r = _resolved(dem, config, settings)
        resolved.append(r)
        specs.append({
            "index": i,
            "dem": dem,
            "config": config,
            "backend": backend,
            "fixed": base,
            "params": m,
            "output": os.path.join(output_dir, "member_%03d.h5" % i),
            "overwrite": overwrite,
            "threads": threads,
            "config_hash": _config_hash(r, dem, backend, settings),
        })
    rows: Dict[int, Dict[str, Any]] = {}
    if not overwrite:
        rows = _finished_rows(specs, resume)
    todo = [s for s in specs if s["index"] not in rows]
    columns = _column_values(members, resolved)

    def table():
        t = pd.DataFrame([rows[i] for i in sorted(rows)])
        if t.empty:
            return t
        front = {"member": t["member"],
                 "config_hash": [specs[i]["config_hash"] for i in t["member"]]}
        front.update({k: [v[i] for i in t["member"]] for k, v in columns.items()})
        out = pd.concat([pd.DataFrame(front), t.drop(columns=["member"])], axis=1)
        return out.reset_index(drop=True)

    bar = _Progress(len(todo), len(specs) - len(todo), progress)

    def on_row(row: Dict[str, Any]) -> None:
        rows[row["member"]] = dict(row)
        bar.update(bool(row["error"]))

    try:
        if client is not None:
            from distributed import as_completed

            futures = client.map(run_member, todo, pure=False)
            try:
                for fut in as_completed(futures):
                    on_row(fut.result())
            except KeyboardInterrupt:
                client.cancel(futures)
                raise
        elif workers == 1:
            for s in todo:
                on_row(run_member(s))
        else:
            _run_local(todo, workers, threads, on_row)
    except KeyboardInterrupt:
        bar.close()
        for s in specs:  # members a worker finished before its row reached this process
            if s["index"] not in rows:
                row = _row_on_disk(s)
                if row is not None:
                    rows[s["index"]] = row
        t = table()
        _write_table(t, output_dir)
        message = (
            "sweep interrupted: %d of %d members finished (their rows are in %s and in this "
            "exception's .table); to resume, run the same sweep again with output_dir=%r: "
            "finished members are skipped" % (len(rows), len(specs),
                                              os.path.join(output_dir, TABLE_CSV), output_dir)
        )
        print(message, file=sys.stderr)
        raise SweepInterrupted(message, t, output_dir) from None
    bar.close()
    t = table()
    _write_table(t, output_dir)
    return t


def _finished_rows(specs, resume: bool) -> Dict[int, Dict[str, Any]]:
    """The rows of members whose result file is complete and of the same configuration
    (``resume``); ValueError for member files that cannot be used, before anything runs."""
    rows: Dict[int, Dict[str, Any]] = {}
    for s in specs:
        path = s["output"]
        if not os.path.exists(path):
            continue
        if not resume:
            raise ValueError(
                "sweep: %s exists; pass resume=True to skip the finished members, "
                "overwrite=True to run them again, or another output_dir" % path
            )
        row_file = path[:-3] + ".json"
        try:
            with open(row_file) as f:
                row = json.load(f)
        except (OSError, ValueError):
            raise ValueError(
                "sweep: %s exists without its row file %s, so it cannot be checked against "
                "member %d's parameters; pass overwrite=True to run it again, or another "
                "output_dir" % (path, os.path.basename(row_file), s["index"])
            ) from None
        if row.get("config_hash") != s["config_hash"]:
            raise ValueError(
                "sweep: %s was written with another configuration (config_hash %s, member %d "
                "now has %s); pass overwrite=True to replace it, or another output_dir"
                % (path, row.get("config_hash"), s["index"], s["config_hash"])
            )
        if not row.get("finished"):
            s["overwrite"] = True  # this member's own file, its row lost to Ctrl-C: run again
            continue
        rows[s["index"]] = _table_row(row)
    return rows


def _table_row(row: Dict[str, Any]) -> Dict[str, Any]:
    """A row as its row file holds it, as a table row."""
    row = {k: v for k, v in row.items() if k not in ("config_hash", "finished")}
    return {k: (float("nan") if v is None else v) for k, v in row.items()}


def _row_on_disk(spec: Dict[str, Any]) -> Optional[Dict[str, Any]]:
    """The row of a member whose result file is complete and whose row file says finished
    with its configuration; else None."""
    try:
        with open(spec["output"][:-3] + ".json") as f:
            row = json.load(f)
    except (OSError, ValueError):
        return None
    if (os.path.exists(spec["output"]) and row.get("finished")
            and row.get("config_hash") == spec["config_hash"]):
        return _table_row(row)
    return None


def _write_table(table, output_dir: str) -> None:
    """``sweep.csv`` (and ``sweep.parquet`` with pyarrow) in ``output_dir``."""
    if table.empty:
        return
    table.to_csv(os.path.join(output_dir, TABLE_CSV), index=False)
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return
    table.to_parquet(os.path.join(output_dir, TABLE_PARQUET), index=False)
