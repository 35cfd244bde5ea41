"""Issue 19, the Python user's day: DEM.from_array (numpy and xarray), checked field setters
and step counts, sweeps run from stdin and unguarded scripts, resume, the sweep table and
the console entry point."""

import os
import pickle

import numpy as np
import pytest

from test_api import WINDOW, small_config


def cone(n=48, cell=10.0, height=60.0):
    """A cone-shaped hill on an n x n grid of `cell` m, its top in the middle."""
    y, x = np.mgrid[0:n, 0:n]
    r = np.hypot(x - (n - 1) / 2, y - (n - 1) / 2) * cell
    return height - r * height / (n * cell / 2)


# ---- DEM.from_array -----------------------------------------------------------------------


def test_from_array_builds_a_simulation(erodem, tmp_path):
    z = cone()
    z[0, 0] = np.nan  # nodata
    dem = erodem.DEM.from_array(z, cell_size=10.0, crs="EPSG:32611")
    assert dem.shape == (48, 48) and dem.in_memory and not dem.is_geographic
    assert np.allclose(dem.dx, 10.0) and np.allclose(dem.area, 100.0)
    assert "UTM zone 11N" in dem.crs and dem.path.startswith("<array 48 x 48")
    assert not dem.mask[0, 0] and dem.mask.sum() == 48 * 48 - 1
    assert np.array_equal(dem.elevation[1:], z[1:].astype(np.float32))
    sim = erodem.Simulation(dem, "cpu", time__steps=20, rain__rate="50 mm/h",
                            numerics__threads=1)
    sim.run(output=tmp_path / "cone.h5")
    assert sim.steps_done == 20 and sim.ledger["water"] > 0
    ds = erodem.open_run(tmp_path / "cone.h5")
    assert ds.attrs["dem_sha256"] == dem.sha256 and ds.attrs["dem_path"] == dem.path
    ds.close()
    # pickles as its values (sweep workers), the same terrain again
    again = pickle.loads(pickle.dumps(dem))
    assert again.sha256 == dem.sha256
    assert np.array_equal(again.elevation, dem.elevation, equal_nan=True)
    # so a sweep's worker processes run on it
    t = erodem.sweep(dem, grid={"rain.rate": ["20 mm/h", "50 mm/h"]}, steps=10, workers=2,
                     output_dir=tmp_path / "sweep", progress=False)
    assert (t["error"] == "").all(), list(t["error"])
    assert t["max_depth [m]"][1] > t["max_depth [m]"][0]


def test_from_array_same_terrain_as_read_dem(erodem, tujunga):
    # the values, transform and CRS of a file give the terrain read_dem reads from it
    f = erodem.read_dem(tujunga, window=WINDOW)
    a = erodem.DEM.from_array(f.elevation, transform=f.transform, crs=f.crs)
    assert np.array_equal(a.elevation, f.elevation, equal_nan=True)
    assert a.transform == f.transform and a.crs == f.crs
    assert np.array_equal(a.dx, f.dx) and np.array_equal(a.area, f.area)
    # south-up rows (positive pixel height) are flipped to north-up
    x0, px, _, y0, _, py = f.transform
    s = erodem.DEM.from_array(f.elevation[::-1], transform=(x0, px, 0, y0 + 64 * py, 0, -py),
                              crs=f.crs)
    assert np.array_equal(s.elevation, f.elevation) and s.transform == f.transform


def test_from_array_geographic_true_cell_sizes(erodem):
    # a lat/lon file's terrain (ellipsoidal cell sizes by row, GeographicLib) is the one
    # from_array builds from its values, transform and CRS
    path = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "dem",
                        "dfw", "dfw_srtm3.tif")
    if not os.path.exists(path):
        pytest.skip("missing " + path)
    f = erodem.read_dem(path, window=[0, 0, 40, 30])
    assert f.is_geographic
    a = erodem.DEM.from_array(f.elevation, transform=f.transform, crs="EPSG:4326")
    assert a.is_geographic
    assert np.allclose(a.dx, f.dx, rtol=1e-12) and np.allclose(a.dy, f.dy, rtol=1e-12)
    assert np.allclose(a.area, f.area, rtol=1e-12)
    # 3 arc-seconds near 33 N: about 92.6 m north-south, 78 m east-west (not 3/3600 "m")
    assert 90 < a.dy[0] < 95 and 70 < a.dx[0] < 85
    with pytest.raises(ValueError, match="geographic"):
        erodem.DEM.from_array(f.elevation, cell_size=90.0, crs="EPSG:4326")


def test_from_dataarray(erodem):
    xr = pytest.importorskip("xarray")
    z = cone(n=30)
    x = 500000.0 + 10.0 * np.arange(30) + 5.0
    y = 3800000.0 + 10.0 * np.arange(30)[::-1] + 5.0  # north-up: y decreasing
    da = xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x},
                      attrs={"crs": "EPSG:32611"})
    dem = erodem.DEM.from_array(da)
    assert dem.transform == (500000.0, 10.0, 0.0, 3800300.0, 0.0, -10.0)
    assert "UTM zone 11N" in dem.crs and np.array_equal(dem.elevation, z.astype(np.float32))
    # y increasing (south-up storage): the same DEM
    up = da.isel(y=slice(None, None, -1))
    assert erodem.DEM.from_array(up).sha256 == dem.sha256
    # (x, y) order and a band of size 1, the CRS on a spatial_ref coordinate (CF / GDAL)
    da2 = da.transpose("x", "y").expand_dims("band").copy()
    da2.attrs = {}
    da2 = da2.assign_coords(spatial_ref=xr.DataArray(0, attrs={"crs_wkt": dem.crs}))
    assert erodem.DEM.from_array(da2).sha256 != ""  # builds
    assert erodem.DEM.from_array(da2).transform == dem.transform
    # Simulation takes the DataArray itself
    sim = erodem.Simulation(da, "cpu", time__steps=2, numerics__threads=1)
    assert sim.shape == (30, 30)
    # irregular coordinates, lat/lon without a CRS
    bad = da.assign_coords(x=x + np.r_[np.zeros(29), 3.0])
    with pytest.raises(ValueError, match="coordinate 'x' is not regularly spaced"):
        erodem.DEM.from_array(bad)
    ll = xr.DataArray(z, dims=("lat", "lon"),
                      coords={"lat": 34 - 0.001 * np.arange(30),
                              "lon": -118 + 0.001 * np.arange(30)})
    with pytest.raises(ValueError, match="EPSG:4326"):
        erodem.DEM.from_array(ll)
    g = erodem.DEM.from_array(ll, crs="EPSG:4326")
    assert g.is_geographic and 90 < g.dx[0] < 93 and 110 < g.dy[0] < 112


def test_from_dataarray_takes_the_rio_crs_and_nodata(erodem, monkeypatch):
    # with rioxarray installed, da.rio.crs and da.rio.nodata are used (a stand-in accessor
    # here: rioxarray is not a dependency)
    import sys
    import types

    xr = pytest.importorskip("xarray")

    class Crs:
        def to_wkt(self):
            return erodem.DEM.from_array(np.ones((2, 2)), cell_size=1.0, crs="EPSG:32610").crs

    class Rio:
        crs = Crs()
        nodata = -32768.0

    monkeypatch.setitem(sys.modules, "rioxarray", types.ModuleType("rioxarray"))
    monkeypatch.setattr(xr.DataArray, "rio", property(lambda self: Rio()), raising=False)
    z = cone(n=10)
    z[4, 4] = -32768.0
    da = xr.DataArray(z, dims=("y", "x"),
                      coords={"y": 100.0 - 2.0 * np.arange(10), "x": 2.0 * np.arange(10)})
    dem = erodem.DEM.from_array(da)
    assert "UTM zone 10N" in dem.crs and not dem.mask[4, 4] and dem.mask.sum() == 99
    assert dem.transform == (-1.0, 2.0, 0.0, 101.0, 0.0, -2.0)


def test_from_array_rejects_bad_input(erodem):
    z = cone(n=8)
    with pytest.raises(ValueError, match="'z' must be a 2-D array"):
        erodem.DEM.from_array(z[0], cell_size=1.0)
    with pytest.raises(ValueError, match="'z' must hold real numbers"):
        erodem.DEM.from_array(z.astype(complex), cell_size=1.0)
    inf = z.copy()
    inf[2, 3] = np.inf
    with pytest.raises(ValueError, match="infinite values .*row 2, column 3"):
        erodem.DEM.from_array(inf, cell_size=1.0)
    with pytest.raises(ValueError, match="no finite value"):
        erodem.DEM.from_array(np.full((4, 4), np.nan), cell_size=1.0)
    with pytest.raises(ValueError, match="'cell_size' must be a positive"):
        erodem.DEM.from_array(z, cell_size=-1.0)
    with pytest.raises(ValueError, match="give 'cell_size' .* or 'transform'"):
        erodem.DEM.from_array(z)
    with pytest.raises(ValueError, match="not both"):
        erodem.DEM.from_array(z, cell_size=1.0, transform=(0, 1, 0, 0, 0, -1))
    with pytest.raises(ValueError, match="'transform'.*rotated"):
        erodem.DEM.from_array(z, transform=(0, 1, 0.1, 0, 0, -1))
    with pytest.raises(ValueError, match="'crs'"):
        erodem.DEM.from_array(z, cell_size=1.0, crs="EPSG:999999")
    with pytest.raises(ValueError, match="DEM.from_array"):
        erodem.Simulation(z)
    # nodata values become nodata; the caller's array is not changed
    z9 = z.copy()
    z9[0, :] = -9999.0
    d = erodem.DEM.from_array(z9, cell_size=1.0, nodata=-9999)
    assert not d.mask[0].any() and (z9[0] == -9999.0).all()
    # parameter rasters need a file
    with pytest.raises(ValueError, match="parameter 'flow.manning_n'.*from_array"):
        erodem.Simulation(d, "cpu", flow__manning_n="n.tif")


# ---- field setters and step counts --------------------------------------------------------


def test_set_bed_resets_the_erosion_reference(erodem, tujunga):
    dem = erodem.read_dem(tujunga, window=WINDOW)
    sim = erodem.Simulation(dem, "cpu", time__steps=10, numerics__threads=1)
    bed = sim.bed.copy()
    bed[10:20, 10:20] -= 5.0  # dig a pit
    sim.bed = bed
    assert np.nanmax(np.abs(sim.erosion)) == 0.0  # the new reference, not erosion
    assert np.allclose(sim.field("initial_bed"), bed, equal_nan=True)
    # with reset_erosion=False the edit counts as erosion
    bed[30:32, 30:32] -= 2.0
    sim.set_field("bed", bed, reset_erosion=False)
    e = sim.erosion
    assert np.allclose(e[30:32, 30:32], 2.0) and np.nanmax(np.abs(e[:30])) == 0.0


def test_setters_refuse_bad_values(erodem, tujunga):
    sim = erodem.Simulation(erodem.read_dem(tujunga, window=WINDOW), "cpu", time__steps=10,
                            numerics__threads=1)
    before = sim.water_depth.copy()
    h = np.full(sim.shape, 0.1)
    h[3, 4] = -0.5
    with pytest.raises(ValueError, match=r"field 'water_depth': 1 value\(s\) at active cells "
                                         r"are negative \(the first at row 3, column 4"):
        sim.water_depth = h
    h[3, 4] = np.nan
    with pytest.raises(ValueError, match="field 'water_depth'.*NaN or infinite"):
        sim.set_field("water_depth", h)
    assert np.array_equal(sim.water_depth, before)  # nothing changed
    with pytest.raises(ValueError, match="field 'bed'.*NaN"):
        sim.bed = np.full(sim.shape, np.nan)
    with pytest.raises(ValueError, match="field 'hardness'.*above 1"):
        sim.set_field("hardness", np.full(sim.shape, 2.0))
    with pytest.raises(ValueError,
                       match=r"field 'sediment': expected an array of shape \(64, 64\)"):
        sim.sediment = np.zeros((3, 3))
    with pytest.raises(ValueError, match="field 'sediment': expected real numbers"):
        sim.sediment = np.full(sim.shape, "a")
    with pytest.raises(ValueError, match="field 'erosion' is derived"):
        sim.set_field("erosion", np.zeros(sim.shape))
    with pytest.raises(ValueError, match="unknown field 'depth'"):
        sim.set_field("depth", np.zeros(sim.shape))
    # step counts are whole numbers
    with pytest.raises(ValueError, match="step: 'n' must be a whole number of steps, got 1.5"):
        sim.step(1.5)
    with pytest.raises(ValueError, match="run: 'steps' must be a whole number"):
        sim.run(steps=2.5)
    with pytest.raises(ValueError, match="'n' must be >= 0"):
        sim.step(-1)
    assert sim.steps_done == 0
    sim.step(2.0)
    sim.step(np.int64(1))
    assert sim.steps_done == 3


def test_setters_ignore_nodata_cells(erodem):
    # NaN where the DEM has nodata is fine (those cells are not simulated); at an active cell
    # it is refused
    z = cone(n=12)
    z[0, 0] = np.nan
    sim = erodem.Simulation(erodem.DEM.from_array(z, cell_size=5.0), "cpu", time__steps=2,
                            numerics__threads=1)
    h = np.full(sim.shape, 0.1)
    h[0, 0] = np.nan
    sim.water_depth = h
    assert np.isclose(sim.water_depth[5, 5], 0.1)
    h[0, 1] = np.nan
    with pytest.raises(ValueError, match="row 0, column 1"):
        sim.water_depth = h


# ---- sweeps: scripts, stdin, resume, Ctrl-C, the table ------------------------------------

SWEEP_SCRIPT = """
import json, os, sys
import erodem
with open(os.environ["MARKER"], "a") as f:
    f.write("ran\\n")  # once per execution of this script
table = erodem.sweep(erodem.read_dem({tujunga!r}, window={window!r}),
                     grid={{"rain.rate": ["40 mm/h", "80 mm/h"]}}, steps=20, workers=2,
                     output_dir={out!r}, progress=False, initial__water_depth=0.05)
print(json.dumps({{"errors": list(table["error"]), "steps": [int(v) for v in table["steps"]]}}))
"""


def run_script(tmp_path, tujunga, how):
    import json
    import subprocess
    import sys

    out = str(tmp_path / how)
    code = SWEEP_SCRIPT.format(tujunga=tujunga, out=out, window=WINDOW)
    env = dict(os.environ, MARKER=str(tmp_path / (how + ".marker")))
    if how == "stdin":  # python - <<EOF
        r = subprocess.run([sys.executable, "-"], input=code, capture_output=True, text=True,
                           env=env, timeout=300)
    else:  # a file without the __main__ guard
        path = tmp_path / "unguarded.py"
        path.write_text(code)
        r = subprocess.run([sys.executable, str(path)], capture_output=True, text=True,
                           env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout.strip().splitlines()[-1])
    runs = (tmp_path / (how + ".marker")).read_text().count("ran")
    return result, runs


def test_sweep_from_stdin(erodem, tujunga, tmp_path):
    result, runs = run_script(tmp_path, tujunga, "stdin")
    assert result == {"errors": ["", ""], "steps": [20, 20]} and runs == 1


def test_sweep_from_unguarded_script_runs_it_once(erodem, tujunga, tmp_path):
    result, runs = run_script(tmp_path, tujunga, "unguarded")
    assert result == {"errors": ["", ""], "steps": [20, 20]}
    assert runs == 1  # the workers never import the caller's script


def small_sweep(erodem, tujunga, out, **kw):
    cfg, _ = sweep_config(tujunga)
    kw.setdefault("grid", {"rain.rate": ["40 mm/h", "120 mm/h"], "erosion.min_tilt": [0.02, 0.05]})
    return erodem.sweep(erodem.read_dem(tujunga, window=WINDOW), config=cfg,
                        output_dir=out, **kw)


def sweep_config(tujunga, steps=30):
    cfg = small_config(tujunga, steps=steps)
    del cfg["dem"], cfg["numerics"]
    return cfg, None


def test_sweep_resume_skips_finished_members(erodem, tujunga, tmp_path, capsys):
    first = small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1, progress=True)
    err = capsys.readouterr().err
    assert "4/4" in err and "failed=0" in err  # the tqdm bar: members done, failed
    assert (first["error"] == "").all()
    assert list(first.columns[:4]) == ["member", "config_hash", "rain.rate [m/s]",
                                       "erosion.min_tilt"]
    assert first["rain.rate [m/s]"].dtype == np.float64
    assert first["config_hash"].str.len().eq(16).all() and first["config_hash"].nunique() == 4
    # the table beside the member files, as CSV (and Parquet with pyarrow)
    import pandas as pd

    csv = pd.read_csv(tmp_path / "sweep.csv", keep_default_na=False)
    assert list(csv.columns) == list(first.columns)
    assert np.array_equal(csv["eroded_volume [m^3]"], first["eroded_volume [m^3]"])
    try:
        import pyarrow  # noqa: F401

        pq = pd.read_parquet(tmp_path / "sweep.parquet")
        assert pq.equals(first)
    except ImportError:
        pass
    mtimes = [os.path.getmtime(p) for p in first["output"]]
    # rerunning into the same folder: every member is skipped, the rows come back
    t0 = __import__("time").perf_counter()
    again = small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1, progress=True)
    print("resumed 4 finished members in %.2f s" % (__import__("time").perf_counter() - t0))
    assert "4 member(s) already finished" in capsys.readouterr().err
    assert [os.path.getmtime(p) for p in again["output"]] == mtimes
    pd.testing.assert_frame_equal(again, first)
    # a finished member of another configuration is never overwritten silently
    with pytest.raises(ValueError, match="member_000.h5 was written with another configuration"):
        small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1, thermal__rate=0.1)
    with pytest.raises(ValueError, match="member_000.h5 exists; pass resume=True"):
        small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1, resume=False)
    # a lost member file is run again, the others skipped
    os.remove(first["output"][2])
    part = small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1, progress=False)
    assert os.path.exists(first["output"][2])
    assert np.array_equal(part["eroded_volume [m^3]"], first["eroded_volume [m^3]"])


def test_sweep_progress_line_without_tqdm(erodem, tujunga, tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    t = small_sweep(erodem, tujunga, tmp_path, workers=1, threads=1,
                    params=[{"rain.rate": "40 mm/h"}, {"erosion.sediment_capacity": -1.0}],
                    grid=None)
    err = capsys.readouterr().err
    print(err)
    assert "sweep: 2/2 members done, 1 failed, ETA 0:00" in err
    assert t["error"][0] == "" and "erosion.sediment_capacity" in t["error"][1]


INTERRUPT_SCRIPT = """
import erodem, sys
cfg = {cfg!r}
try:
    erodem.sweep(erodem.read_dem({tujunga!r}, window={window!r}), config=cfg, workers=2,
                 threads=1, output_dir={out!r}, progress=False,
                 grid={{"rain.rate": ["40 mm/h", "60 mm/h", "80 mm/h", "100 mm/h", "120 mm/h",
                                      "140 mm/h"]}})
except erodem.SweepInterrupted as e:
    print("rows", len(e.table))
    sys.exit(130)
"""


def finished_members(out):
    """Members whose row file says finished (the worker writes it after the result file)."""
    import json

    n = 0
    for name in os.listdir(out) if os.path.isdir(out) else []:
        if name.startswith("member_") and name.endswith(".json"):
            try:
                with open(os.path.join(out, name)) as f:
                    n += bool(json.load(f).get("finished"))
            except ValueError:
                pass
    return n


def test_sweep_ctrl_c_keeps_finished_rows_and_resumes(erodem, tujunga, tmp_path):
    import signal
    import subprocess
    import sys
    import time

    cfg, _ = sweep_config(tujunga, steps=300)
    out = str(tmp_path / "run")
    code = INTERRUPT_SCRIPT.format(cfg=cfg, tujunga=tujunga, window=WINDOW, out=out)
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while not finished_members(out) and time.time() < deadline:
        time.sleep(0.05)
    t0 = time.perf_counter()
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=60)
    t_stop = time.perf_counter() - t0
    print(stderr[-600:])
    print("stopped %.2f s after Ctrl-C" % t_stop)
    assert p.returncode == 130, stderr
    assert "sweep interrupted" in stderr and "to resume, run the same sweep again" in stderr
    assert t_stop < 5.0
    done = int(stdout.split()[-1])
    assert 1 <= done < 6
    import pandas as pd

    assert len(pd.read_csv(os.path.join(out, "sweep.csv"))) == done
    # the same call again finishes the rest: the finished members are skipped
    t = erodem.sweep(erodem.read_dem(tujunga, window=WINDOW), config=cfg, workers=2, threads=1,
                     output_dir=out, progress=False,
                     grid={"rain.rate": ["40 mm/h", "60 mm/h", "80 mm/h", "100 mm/h",
                                         "120 mm/h", "140 mm/h"]})
    assert (t["error"] == "").all(), list(t["error"])
    assert (t["steps"] == 300).all() and len(t) == 6
    assert not [f for f in os.listdir(out) if f.endswith(".partial")]


# ---- the console entry point --------------------------------------------------------------


def test_console_script_runs_the_bundled_cli(erodem, cli, tmp_path):
    # pyproject.toml's console script runs erodem._cli:main; the package as `pip install .`
    # lays it out (CMake's install of the component python: the module and erodem/bin/erodem,
    # beside the package files) runs its own bundled CLI
    import shutil
    import subprocess
    import sys

    from conftest import BUILD, REPO

    with open(os.path.join(REPO, "pyproject.toml")) as f:
        assert 'erodem = "erodem._cli:main"' in f.read()
    r = subprocess.run(["cmake", "--install", BUILD, "--component", "python", "--prefix",
                        str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    pkg = tmp_path / "erodem"
    assert os.access(pkg / "bin" / "erodem", os.X_OK)
    for name in os.listdir(os.path.join(REPO, "python", "erodem")):
        if name.endswith((".py", ".pyi")):
            shutil.copy(os.path.join(REPO, "python", "erodem", name), pkg / name)
    env = dict(os.environ, PYTHONPATH=str(tmp_path))
    env.pop("ERODEM_CLI", None)
    main = "import sys; from erodem._cli import main, cli_path; print(cli_path()); sys.exit(main())"
    r = subprocess.run([sys.executable, "-c", main, "--version"], capture_output=True,
                       text=True, env=env)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().splitlines()
    print(lines)
    assert lines[0] == str(pkg / "bin" / "erodem")
    assert lines[1] == subprocess.run([cli, "--version"], capture_output=True,
                                      text=True).stdout.strip()
    # the exit status is the CLI's: a missing config is 66, with its message
    r = subprocess.run([sys.executable, "-c", main, "run", str(tmp_path / "missing.toml")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 66 and "missing.toml" in r.stderr
    # a package without a CLI says where to get one (exit 69)
    os.remove(pkg / "bin" / "erodem")
    r = subprocess.run([sys.executable, "-c", main, "--version"], capture_output=True,
                       text=True, env=env)
    assert r.returncode == 69 and "ERODEM_CLI" in r.stderr, r.stderr
