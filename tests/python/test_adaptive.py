"""The adaptive time step sees a depth written from Python between two steps (model.md
section 5): through the CPU backend's numpy view in place, or by assignment (an upload on
OpenCL)."""

import math

import numpy as np
import pytest

# A 64 x 64 crop of Big Tujunga (SRTM 30 m, UTM 11N), dry.
WINDOW = [300, 200, 64, 64]
G = 9.81


@pytest.mark.parametrize("backend", ["cpu", "opencl"])
def test_depth_written_between_steps_sets_the_next_adaptive_dt(
    erodem, tujunga, backend, opencl_available
):
    if backend == "opencl" and not opencl_available:
        pytest.skip("no OpenCL device")
    dem = erodem.read_dem(tujunga, window=WINDOW)
    sim = erodem.Simulation(dem, backend=backend, time__adaptive=True, time__duration=3600)
    sim.step(2)
    dt_dry = sim.diagnostics["dt"]
    # 20 m of water on every cell, written between two steps.
    if backend == "cpu":
        view = sim.water_depth
        assert view.flags.writeable
        view[...] = 20.0  # in place: no call tells the simulation
    else:
        sim.water_depth = np.full(dem.shape, 20.0)
    sim.step(1)  # raised UnstableError (CFL 2.4 > 1) while the step kept dt_max
    dt = sim.diagnostics["dt"]
    # The bound the step must keep: time.cfl dx_min / sqrt(g d_max), with d_max the 20 m
    # written (within float32 rounding of the depth; the step cannot see more water than that).
    dx_min = float(min(dem.dx.min(), dem.dy.min()))
    bound = 0.7 * dx_min / math.sqrt(G * 20.0)
    courant = dt * math.sqrt(G * sim.diagnostics["max_depth"]) / dx_min
    print(
        "%s: dt %.4f s on the dry DEM; after writing 20 m: dt %.4f s (bound %.4f s = 0.7 dx_min "
        "/ sqrt(g 20 m)), Courant %.3f after the step (bound 1)"
        % (backend, dt_dry, dt, bound, courant)
    )
    assert dt_dry == 5.0  # dry: time.dt_max
    assert dt <= bound * (1 + 1e-6)
    # After the step the water has run into the valleys (d_max grows from 20 m to 37 m), so the
    # Courant number of the step's end exceeds 0.7; the stability stop's bound is 1.
    assert courant <= 1.0
