"""Cross-sections and outlets from Python: Simulation.sections, the result file's
``sections`` group as a pandas DataFrame (erodem.read_sections) and as xarray."""

import numpy as np

from test_api import WINDOW, small_config


def test_sections_from_python(erodem, tujunga, tmp_path):
    dem = erodem.read_dem(tujunga, window=WINDOW)
    x0, dx, _, y0, _, dy = dem.transform
    ny, nx = dem.elevation.shape
    xm = x0 + dx * nx / 2  # a north-south line across the middle
    cfg = small_config(tujunga, steps=40)
    cfg["section"] = [{"name": "middle", "line": [[xm, y0 + dy * 2], [xm, y0 + dy * (ny - 2)]]}]
    cfg["outlet"] = [{"name": "east", "edge": "east"}, {"name": "south", "edge": "south"}]
    sim = erodem.Simulation(dem, backend="cpu", config=cfg)
    out = tmp_path / "s.h5"
    sim.run(output=out, every=20)
    live = sim.sections
    assert list(live) == ["middle", "east", "south"]
    assert live["east"]["outlet"] and not live["middle"]["outlet"]

    df = erodem.read_sections(out)
    print(df.tail(3))
    assert len(df) == 40
    assert list(df["step"]) == list(range(1, 41))
    # the last row is the simulation's state; the outlets (the only open edges) let out what
    # the ledger counts as boundary_out, to float32 rounding
    for name in live:
        assert df[name]["volume"].iloc[-1] == live[name]["volume"]
        assert df[name]["discharge"].iloc[-1] == live[name]["discharge"]
    out_volume = df["east"]["volume"].iloc[-1] + df["south"]["volume"].iloc[-1]
    boundary_out = sim.ledger["boundary_out"]
    print("outlets %.6g m^3, ledger boundary_out %.6g m^3" % (out_volume, boundary_out))
    assert boundary_out > 0
    assert abs(out_volume / boundary_out - 1) < 1e-5
    # the cumulative volume is the discharge times the steps
    dt = np.diff(np.concatenate([[0.0], df.index.to_numpy()]))
    assert np.allclose(np.cumsum(df["east"]["discharge"].to_numpy() * dt), df["east"]["volume"])

    ds = erodem.open_run(out, group="sections")
    assert ds["discharge"].dims == ("step", "section")
    assert ds.attrs["section_names"] == "middle,east,south"
    ds.close()
    empty = tmp_path / "none.h5"
    erodem.Simulation(dem, backend="cpu", config=small_config(tujunga, steps=2)).run(output=empty)
    assert erodem.read_sections(empty).empty
