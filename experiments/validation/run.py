#!/usr/bin/env python3
"""erodem validation report: runs every validation case on the CPU reference (float32, float64)
and on OpenCL (float32), with the full resolution ladders, and writes docs/validation.md with
one figure per case (docs/images/validation/*.png) and the table of every measured figure.

The cases are the gtest cases themselves (tests/test_analytical.cpp, test_validation.cpp,
test_runoff.cpp, test_waves.cpp, test_physics.cpp, test_sources.cpp,
test_boundaries_rasters.cpp, test_lake.cpp, test_snow.cpp, test_shallow_water.cpp,
test_precision.cpp): this script builds nothing; it runs the built test
binary with ERODEM_VALIDATION_DIR (each case appends its figures to records.jsonl and writes its
profiles as CSV, tests/validation_record.hpp) and ERODEM_VALIDATION_LADDER=full. A failing case
is recorded and shown failing; the script runs them all, writes the report, then exits 1 if any
figure failed its bound (or the test binary failed).

The full-size float32 scenarios (experiments/precision/compare.py: the Puget Sound main job, a
1 h storm over all of Big Tujunga, 0-9000 m ridged relief) run after the gtest cases, through the
CLI, unless --coarse or --no-full-size.

Usage:  python3 experiments/validation/run.py [--build build] [--coarse] [--no-full-size]
        python3 experiments/validation/run.py --full-size-only   (rerun only those)
Build first:  cmake --build build --target erodem_tests erodem
"""

from __future__ import annotations

import argparse
import collections
import csv
import datetime
import json
import math
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
# The validation cases: the set tests/validation_labels.cmake labels for ctest, read from it (one
# list): its suites `^(Cpu|OpenCl)/(A|B|...)\\.`, its single cases `Suite\\.(a|b)/` and its
# `^Precision\\.Float32` prefix, as a gtest filter.
def _filter_from_labels() -> str:
    import re

    text = (ROOT / "tests" / "validation_labels.cmake").read_text()
    patterns = re.findall(r'MATCHES\s*"([^"]*)"', text)
    parts = []
    for pat in patterns:
        pat = pat.replace("\\\\", "\\")
        m = re.fullmatch(r"\^\(Cpu\|OpenCl\)/\(([^)]*)\)\\\.", pat)
        if m:
            parts += [f"*/{suite}.*" for suite in m.group(1).split("|")]
            continue
        m = re.fullmatch(r"(\w+)\\\.\(([^)]*)\)/", pat)
        if m:
            parts += [f"*/{m.group(1)}.{case}/*" for case in m.group(2).split("|")]
            continue
        m = re.fullmatch(r"\^(\w+)\\\.(\w+)", pat)
        if m:
            parts.append(f"{m.group(1)}.{m.group(2)}*")
            continue
        sys.exit(f"run.py: tests/validation_labels.cmake: a pattern this script cannot read: {pat}")
    return ":".join(parts)


GTEST_FILTER = _filter_from_labels()

# Per case: title, set-up, reference, and what the schemes can and cannot represent.
CASES = {
    "sw_stoker": (
        "Shallow water: Stoker's dam break converging",
        "2 m onto 1 m, 1000 m channel, frictionless, 40 s, dx = 2, 1, 0.5 (0.25) m, dt = 0.08 dx.",
        "The full equations (HLLC, Chen & Noelle): first order, converging at about 0.8 to "
        "Stoker's solution (local inertial stays at 0.27).",
    ),
    "sw_ritter": (
        "Shallow water: Ritter's dry dam break converging",
        "2 m onto a dry bed, 1000 m channel, frictionless, 30 s, dx = 2, 1, 0.5 (0.25) m.",
        "First order at a dry front: orders about 0.75 for depth and discharge; the 1 mm front "
        "at 0.90 of Ritter's at 0.5 m (local inertial 0.36). Velocities at the tip unbounded.",
    ),
    "sw_radial": (
        "Shallow water: a radial dam break against a 1-D radially symmetric solution",
        "2 m deep within 10 m of the centre of a closed, flat, frictionless 64 m square basin, 1 m "
        "beyond; 4 s (the shock at 25.8 m, a 0.40 m hollow with an inward-facing secondary shock "
        "at the centre); dx = 1, 0.5, 0.25 (0.125) m, dt = 0.05 dx. Errors over all cells, by "
        "their centre radius, relative to an idle solver's; radial discharge and velocity; the "
        "shock on the east half-axis and the diagonal; the diagonal's profile against the axis's.",
        "The reference is no closed form but a fine second-order 1-D finite-volume solution of "
        "the radially symmetric equations computed in the test (3600 cells of 1 cm; a hundredth "
        "of the 2D error at 0.125 m). First order: depth errors 0.178, 0.110, 0.065, 0.037 "
        "(orders 0.70, 0.76, 0.82; discharge and velocity alike), the shock within 2 % on both "
        "rays, the diagonal within 0.015 .. 0.005 of the axis (the grid's anisotropy, "
        "shrinking), the mirror symmetries kept to rounding. Dropping the tangential momentum "
        "flux passes the 1-D dam breaks but not this case.",
    ),
    "sw_thacker": (
        "Shallow water: Thacker's planar oscillation in a paraboloid",
        "a = 1 m, h0 = 0.1 m, eta = 0.5 m in a 4 m basin, frictionless, CFL 0.5, 3 periods; "
        "100, 200, 400 cells across (49, 100, 200 wet across the disc).",
        "First order: the period's error falls at first order (+3.7, +1.9, +1.0 %), within 1 % at "
        "200 wet cells as the issue expects; the amplitude decays by numerical diffusion "
        "(0.73, 0.86, 0.93 of the first after 3 periods).",
    ),
    "sw_lake_geographic": (
        "Shallow water: a lake at rest on a lat/lon DEM (Rhine)",
        "60 x 60 cells of 30 arc-seconds filled to 80 m, 2000 steps of 5 s.",
        "The side-pressure source balances the north and south faces' different lengths: "
        "|q| stays at rounding (float64 1e-12 m^2/s).",
    ),
    "sw_macdonald": (
        "Shallow water: a smooth supercritical steady flow (MacDonald's construction), both orders",
        "1000 m channel, q = 2 m^2/s, n = 0.033, depth hc (0.75 - 0.15 exp(-36 (x/L - 1/2)^2)), "
        "the bed derived; three upstream cells held at the exact state, open outlet; 50, 100, "
        "200 (400) cells, 1000 s from q = 1.6 m^2/s.",
        "flow.order = 2 (MUSCL-minmod, Heun) converges at order 2 over 100-900 m; the first "
        "order at about 1 with a large constant on this steep bed.",
    ),
    "sw_edge_wave": (
        "Shallow water: a wave leaving through an open and a fixed-level edge",
        "1000 m channel at dx = 2 m, still water 1 m, a 1 cm Gaussian hump (20 m) at 800 m, "
        "frictionless, 150 s; the east edge open, fixed at the level 1 m, or a wall.",
        "Riemann-invariant edges: the outgoing characteristic from the cell, the incoming one "
        "from water at rest at the level, so a small wave leaves as into open water (linear "
        "theory: no reflection; a wall reflects it whole).",
    ),
    "snow_flat": (
        "Snow: a flat pack melting at the degree-day rate",
        "8 x 8 cells of 1 km, 0.1 m of snow at 4 degrees C, DDF 5 mm/d/K, t* = 5 d.",
        "Closed form S(t) = S0 - DDF (T - T_melt) t; the melt enters the depth and the ledger.",
    ),
    "snow_line": (
        "Snow: the snow line after 10 days with a lapse rate",
        "A ramp 0-1575 m, 0.2 m of snow, 10 degrees C at 0 m, -6.5 K/km, DDF 4 mm/d/K.",
        "The pack melts out below z* = 769.2 m; every cell against the closed form.",
    ),
    "snow_rain_on_snow": (
        "Snow: rain on snow adds exactly its heat term",
        "8 x 8 cells of 1 km, 0.1 m of snow at 5 degrees C, DDF 5 mm/d/K, rain 10 mm/h for 12 h, "
        "retention 0.",
        "Melt DDF T t + r t c_w T / L_f (c_w = 4186 J/kg/K, L_f = 334 kJ/kg): the heat term "
        "7.52 mm against the closed form; all rain and melt reach the depth.",
    ),
    "snow_snowfall": (
        "Snow: rain below the threshold falls on the pack; water and pack budgets close",
        "Flat 8 x 8 cells of 1 km at -3 degrees C, 0.05 m of snow, 5 mm/h for 12 h; and a ramp "
        "0-1575 m at 6 degrees C at 0 m, -6.5 K/km, 0.1 m of snow, retention 0.1, 6 h of "
        "5 mm/h with flow.",
        "S = S0 + r t and no water on the flat; the snowfall is r t times the cold area; the "
        "water closure (pack outside) and the pack's own (snowfall + rain on snow - runoff; "
        "snowfall - melt for the solid) close to rounding.",
    ),
    "snow_retention": (
        "Snow: the pack holds liquid water up to its retention fraction",
        "8 x 8 cells of 1 km, 0.1 m of snow at 4 degrees C, DDF 5 mm/d/K (20 mm/d), retention "
        "0.1.",
        "L = min(m t, theta S), depth m t - L: no water on the depth before t_w = 0.4545 d; "
        "L <= theta S at every step.",
    ),
    "snow_series": (
        "Snow: melt under a temperature series",
        "8 x 8 cells of 10 km, 0.2 m of snow, T_ref linear from -5 to 15 degrees C over 5 d, "
        "held after, DDF 4 mm/d/K, steps of 1 h.",
        "S(t) = S0 - DDF times the integral of max(0, T_ref): 24.5 mm by 3 d, 172.5 mm by 6 d "
        "(the step-midpoint values integrate the linear series exactly).",
    ),
    "snow_slide": (
        "Snow: the pack slides down slopes steeper than the slide angle",
        "8 columns of 10 m, a 60 degree slope then flat, 0.1 m of snow, slide angle 45 degrees "
        "(and 65: nothing moves), slide_rate dt 1 (5 steps) and 1/4 (1 step).",
        "The pack gathers on the first flat column (6 S0) or moves a quarter per step; its "
        "volume is kept to rounding.",
    ),
    "terrain_class_rule": (
        "Terrain classes: the rule against an independent evaluation",
        "A 12 x 10 tile of 100 m cells: flat, then a ramp of slope 1; a pack, water-wet and "
        "mud-wet rows; a snow line at 450 m and rock only above 150 m; Manning n and K_sat "
        "tables by class.",
        "The rule evaluated by the test's own code (its own slope, its own chain of "
        "thresholds); the fields against the class tables.",
    ),
    "terrain_class_infiltration": (
        "Terrain classes: each class infiltrates with its own Green-Ampt soil",
        "A flat tile ponded 0.5 m for 2 h, half mud (a clay table: K_sat 1e-7 m/s, psi 0.3 m, "
        "delta theta 0.4), half grass (the uniform loam).",
        "F - S ln(1 + F / S) = K_sat t of each class's soil (Green & Ampt 1911).",
    ),
    "terrain_class_talus": (
        "Terrain classes: each class collapses to its own talus angle",
        "A ramp of slope 2 of 1 m cells; the cells above 40 m snow (talus 20 degrees), the rest "
        "grass (45 degrees); 3000 steps of slope collapse.",
        "The largest drop out of a cell equals tan of its class's talus angle.",
    ),
    "section_steady_channel": (
        "Sections: the discharge through a cross-section at steady state",
        "A 60 x 3 sloped channel fed 15 m^3/s for 4000 s, a section across it.",
        "The inflow (steady state), and the water upstream of the section closes.",
    ),
    "temperature_grids": (
        "Gridded forcing: temperature rasters in time melt a pack at their degree days",
        "A flat pack under uniform temperature bands at 0, 1 d and 4 d (-4, -1, 17 degrees C), "
        "a lapse rate that must not apply.",
        "The degree-day melt integrated over the linear interpolation of the bands.",
    ),
    "netcdf_rain": (
        "Gridded forcing: netCDF rain at irregular times",
        "A netCDF rain variable with a CF time coordinate at 0, 10, 40 and 100 min.",
        "The trapezoid integral of the band rates.",
    ),
    "snow_initial_rule": (
        "Snow: the initial pack with a transition band and a slope limit",
        "A ramp of 25 m then 60 m per 50 m column, snow line 400 m, band 200 m, max slope 35 "
        "degrees.",
        "Every cell against S0 clamp((z - 300) / 200, 0, 1) where the central-difference slope "
        "is below 35 degrees, else 0.",
    ),
    "green_ampt_ponded": (
        "Infiltration: ponded Green-Ampt against its implicit closed form",
        "4 x 4 flat cells of 2 km under 0.1 m of water, loam (K_sat 0.34 cm/h, psi 8.89 cm, "
        "delta theta 0.3), 2 h in steps of 10 s (and 600 s in ctest).",
        "F - S ln(1 + F / S) = K_sat t solved by bisection (Green & Ampt 1911); the depth loses "
        "F and the ledger books it.",
    ),
    "green_ampt_rain": (
        "Infiltration: rain below and above K_sat",
        "The loam dry, rain at K_sat / 2 and at 10 K_sat for 1 h in steps of 10 s.",
        "Below K_sat nothing ponds and all the rain soaks in; above it the surface ponds at "
        "t_p = F_p / r, F_p = S K / (r - K) (Mein & Larson 1973), then F follows the ponded "
        "relation from (t_p, F_p).",
    ),
    "green_ampt_store": (
        "Infiltration: a finite soil store",
        "0.1 m of water over a soil 5 cm deep (store L delta theta = 15 mm), 2 h.",
        "F stops at L delta theta; the rest stays on the surface.",
    ),
    "green_ampt_recovery": (
        "Infiltration: recovery of the capacity between storms",
        "10 mm soaked in, 2 days dry, then 50 mm of water again.",
        "F decays as e^(-k_r t) with SWMM's k_r = sqrt(K_sat [in/h]) / 75 per hour; the next "
        "step takes the Green-Ampt increment from the recovered F.",
    ),
    "stage_channel": (
        "Boundaries: a channel follows a rising stage",
        "A closed channel of 1 km (10 m cells, Manning 0.03), 0.5 m deep, its west edge held at a "
        "stage rising from 0.5 m to 1 m in 3 h.",
        "Quasi-static: the level is the stage on every cell, less the friction lag of the filling "
        "flow (about 2 mm).",
    ),
    "stage_segment": (
        "Boundaries: a level held on one edge segment",
        "A dry basin of 20 x 20 cells of 10 m, closed but for four west-edge cells that "
        "boundary.raster holds at 0.5 m.",
        "Water enters there only (the edge's corners are dry at 20 s); the basin fills to the level.",
    ),
    "stage_held_cell": (
        "Boundaries: an interior cell held at a rising stage",
        "A closed dry basin of 20 x 20 cells of 10 m with one interior cell coded fixed_level, "
        "the stage rising from 0.2 m to 0.4 m in 30 min.",
        "The basin fills to the stage.",
    ),
    "stoker": (
        "Dam break on a wet bed (Stoker)",
        "2 m onto 1 m, 1000 m channel of 2 m cells, frictionless, 40 s, dt = 0.2 s, theta = 0.8. "
        "Errors are relative L1 distances over the region the wave reached, divided by an idle "
        "solver's (an idle solver scores 1).",
        "Neither scheme has the advection term: local inertial converges to its own solution, "
        "0.27 from Stoker's at every dx (model error, see the convergence case); the pipes are "
        "linear shallow water about the depth A / w and are only required to have moved.",
    ),
    "ritter": (
        "Dam break on a dry bed (Ritter)",
        "1 m onto a dry bed, 1000 m of 2 m cells, 30 s; front where h > 1 mm.",
        "The dry front is supercritical, where the dropped advection term dominates: both "
        "fronts lag Ritter's by about 60 %, on every grid. The bounds are sanity bounds.",
    ),
    "li_convergence": (
        "Local inertial: convergence on the wet dam break",
        "Stoker's set-up on 600 m at dx = 4, 2, 1, 0.5 m (ctest) and 0.25 m (report), dt / dx = "
        "0.1 s/m; L1 distances between successive grids, finer solutions averaged onto coarser "
        "cells. The depth error against Stoker is reported beside it.",
        "Self-convergence of order 0.55-0.7 (first order only asymptotically); the distance to "
        "Stoker stays at 0.27: model error. With theta = 1 there is no convergence (reported).",
    ),
    "li_dt_sensitivity": (
        "Local inertial: error against a fixed time step at a fixed grid",
        "The Stoker dam break at dx = 2 m with dt from 0.3 s down to 0.025 s, and the Manning "
        "plane at dx = 10 m with fixed dt from 3 s down to 0.25 s (resolution column: dt in s).",
        "theta < 1 adds a diffusion of about (1 - theta) dx^2 / (2 dt) to the discharge. On the "
        "dam break it does not raise the error: the model error (0.27, no advection term) "
        "dominates, and the error falls slightly as dt shrinks (0.2715 at 0.3 s, 0.2481 at "
        "0.025 s). On the plane the inflow cell sits at the normal depth at every dt (to 1e-4) "
        "since the sources run after the flow and the friction is implicit (issue 14; before, "
        "it sat below the normal depth by 7.8 % per second of dt), and the interior is exact "
        "at every dt.",
    ),
    "kinematic_plane": (
        "Rain on a steep plane: the kinematic-wave rising limb",
        "50 mm/h on a dry 100 m plane of slope 0.3 and 1.0, n = 0.03, open foot; 2 m cells at the "
        "defaults (adaptive, CFL 0.7, dt_max 5 s), then 4 and 2 m cells (report: 1 m) with "
        "dt_max = dx / 2. The profile is the outlet's discharge per unit width against "
        "q = (sqrt(S)/n) (i t)^(5/3) until t_e, then i L.",
        "The film is 2-3 mm deep at Froude 2-4, where the semi-implicit friction used before "
        "issue 14 ran at 12x the Manning speed (errors 1.6-1.7); the implicit friction follows "
        "the kinematic wave at first order.",
    ),
    "wave_speed": (
        "Wave speed of each flow scheme",
        "A 1 cm Gaussian bump on a 1 m lake, 200 cells of 10 m, frictionless; speeds between "
        "300 m and 800 m of travel.",
        "Local inertial carries the pulse at sqrt(g h). The pipes carry waves at the speed of "
        "their reference depth A dx / (l dy), 0.99 m/s with A = 1 m^2 here, whatever the water's "
        "depth, and leave a plateau behind the front (the one-way pipes keep their discharge).",
    ),
    "manning_plane": (
        "Uniform flow down a Manning plane",
        "2 km channel, slope 1e-3, n = 0.03, q = 0.5 m^2/s by a line inflow, open outlet, "
        "adaptive dt, 8000 s; depth over the middle half against the normal depth 0.6392 m.",
        "Exact in the interior (the local-inertial friction term is Manning's).",
    ),
    "rain_plane": (
        "Rain on a tilted plane reaches equilibrium",
        "40 x 40 cells of 10 m, slope 0.01 to an open south edge, 50 mm/h, n = 0.03; outflow "
        "over 5400-6000 s against rain x area.",
        "A mass balance at steady state: both schemes.",
    ),
    "thermal": (
        "Thermal collapse relaxes to the talus angle",
        "A 20 m block of 10 x 10 cells on a flat 40 x 40 grid of 1 m, talus 35 deg, K_t dt = 0.5, "
        "6000 steps. The profile is the middle row of the bed.",
        "The steepest slope left must sit at the talus angle; material conserved.",
    ),
    "sediment_adaptation": (
        "Suspended sediment adapts to the capacity along a uniform flow",
        "A uniform flow of 1 m/s, 1 m deep, held fixed; clear water enters at the west face; "
        "C = 1 mm, K_s = 0.05 /s; dx = 1, 0.5, 0.25 m (ctest) and 0.125 m (report). Reference "
        "C (1 - exp(-K_s x / u)).",
        "Conservative transport converges at first order. Semi-Lagrangian transport cannot take "
        "a clear inflow through the grid's edge (its departure point is clamped to the grid): "
        "every cell settles at C, an error of 0.199 at every resolution (order 0).",
    ),
    "sediment_settling": (
        "Physical law: well-mixed settling",
        "Still water 0.5 m deep, 0.1 mm grains (w_s = 7.5 mm/s by Ferguson & Church 2004), "
        "s0 = 1 cm, 100 s in steps of 1 and 10 s (the resolution column is the step, s).",
        "The exact factor per step: exp(-w_s t / h) to rounding at both steps (explicit Euler "
        "would be 1.1 % and 15 % off); the bed rises by what settles over 1 - phi.",
    ),
    "sediment_threshold": (
        "Physical law: threshold of motion and the equilibrium concentration",
        "A uniform flow 2 m deep (n 0.03) held fixed over 0.5 mm sand, one step of 1 s, at "
        "theta' / theta_c = 0.5, 0.99, 1.01, 1.5, 3 (the resolution column), against Engelund & "
        "Hansen's c_eq and Garcia & Parker's E_s computed in the test.",
        "Nothing moves below the Soulsby-Whitehouse threshold; above it, the closed form to "
        "float32 rounding.",
    ),
    "sediment_adaptation_physical": (
        "Physical law: clear water adapts to the equilibrium over the settling length",
        "A uniform flow 1 m deep at 1 m/s held fixed over 0.1 mm sand, clear water entering at "
        "the west; L = u h / w_s = 133 m (27 cells of 5 m), channel 6 L.",
        "c_eq (1 - exp(-x / L)) to first-order upwind accuracy; the outlet flux is Engelund & "
        "Hansen's q_t.",
    ),
    "sediment_channel_at_capacity": (
        "Physical law: a channel fed at capacity carries the equilibrium flux",
        "A 2 km channel of slope 1e-3 (n 0.03, local inertial), 1 m^2/s fed with Engelund & "
        "Hansen's c_eq of its normal flow through a line inflow, 0.5 mm sand, 8000 s.",
        "The sediment flux through the middle half equals q_t of the closure.",
    ),
    "sediment_sea_inflow": (
        "Physical law: the sea brings its sediment in",
        "A dry basin of 30 x 10 cells of 2 m, 0.5-1.1 m below the sea, floods for 30 s from a "
        "fixed-level west edge or a column of sea nodata cells carrying "
        "boundary.sediment_concentration = 0.02; the bed neither gives nor takes.",
        "The suspended solid is 0.02 times the water that came in; the ledger books it.",
    ),
    "sediment_exner_box": (
        "Physical law: Exner with porosity in a closed box",
        "64 x 64 cells of Big Tujunga, closed edges, 100 mm/h for 600 s, default physical law.",
        "(1 - phi) dV_bed + V_suspended = 0 to rounding.",
    ),
    "sediment_layers": (
        "Physical law: a layered bed, detachment limited",
        "Cohesive soil 1 cm thick (M 1e-3 kg/m^2/s, phi 0.4) over cohesive bedrock (M 1e-4, phi "
        "0) under tau_b = 1 Pa (tau_c 0.1 Pa), no deposition; morfac 1 and 10.",
        "The soil erodes at its closed-form rate, runs out at t*, then the bedrock at its rate.",
    ),
    "evaporation": (
        "Evaporation follows the explicit decay",
        "A lake at rest 1 m deep, K_e dt = 0.1, 20 steps, against d0 (1 - K_e dt)^n.",
        "Exact to rounding (the ODE's d0 exp(-K_e t) would be 11 % off: the scheme is the "
        "explicit step).",
    ),
    "semi_lagrangian_loss": (
        "Semi-Lagrangian transport: measured loss",
        "The sloshing box (40 x 40 cells of 10 m) with erosion and semi-Lagrangian transport, "
        "3000 steps; the volume the transport removed from suspension against the eroded volume.",
        "Not conservative: about 80 % of the eroded volume is lost, most of it in cells "
        "shallower than 0.1 m. The ledger books it (closure to rounding).",
    ),
    "bedrock": (
        "Bedrock floor is never cut",
        "A 0.3 m mound under a held uniform flow, capacity 0.5 m, floor at 0.1 m, 200 steps.",
        "Every cell ends at min(start, floor); without the floor the bed is cut to -2.5 m.",
    ),
    "hunter": (
        "Flood front over a flat frictional bed (Hunter et al. 2005)",
        "A 5 km channel of 3 rows, flat, Manning n = 0.01, dry; the exact q(0, t) = u h(0, t) "
        "with u = 1 m/s fed through the west column as an inflow hydrograph sampled every "
        "second; 1 h with the default adaptive step; dx = 50 and 25 m. The profile is the depth "
        "along the channel at 1 h (dx = 25 m) against h = [(7/3) n^2 u^2 (u t - x)]^(3/7).",
        "The solution is exact for the zero-inertia and full equations, not for local inertial: "
        "its residual is of relative size Fr^2 (0.11 at x = 0, more towards the tip), the bound "
        "on the depth error; it is model error (0.039 at 50 m, 0.043 at 25 m). The front lags "
        "by 1-4 %, more on the finer grid, which resolves more of the tip where the dropped "
        "advection term dominates. The shallow-water scheme (issue 16) should converge here.",
    ),
    "fixed_level_fill": (
        "A fixed-level edge fills a dry channel (adaptive step)",
        "A dry frictionless channel of 300 cells of 2 m whose west edge holds the sea at 4 m; "
        "the default adaptive step (CFL 0.7, dt_max 5 s), 20 s; front where h > 1 mm.",
        "The adaptive step must see the sea's depth at the edge from the first step (before "
        "issue 14 it took dt_max and stopped with CFL 1.57 at step 1). The front is Ritter's "
        "dam break from 4 m and lags it as in the Ritter case (no advection term).",
    ),
    "inflow_hydrograph": (
        "A large inflow hydrograph into a dry basin (adaptive step)",
        "100 m^3/s reached over 1 min into the middle cell of a dry closed basin of 40 x 40 "
        "cells of 5 m (n = 0.05), 10 min with the default adaptive step.",
        "The adaptive step must see this step's inflow (it took dt_max = 5 s and stopped at "
        "step 1 before issue 14); all the water that came in is on the grid.",
    ),
    "line_inflow": (
        "A line inflow on a flat plain: no checkerboard, mirror-symmetric",
        "20 m^3/s into four 5 m cells of one row in the middle of a dry flat plain of 60 x 61 "
        "cells (n = 0.05, open edges), 1 h with the default adaptive step, against fixed steps "
        "of 0.25 s.",
        "Before issue 14 the inflow cells oscillated against their neighbours (0.10 m beside "
        "0.21 m), lost the mirror symmetry by up to 0.5 m and reached 3.05 m/s; with the "
        "sources after the flow and the adaptive step seeing the inflow the field is symmetric "
        "to rounding and the inflow cells stand above their ring.",
    ),
    "lake_at_rest": (
        "A lake at rest over bumpy terrain stays at rest",
        "48 x 48 cells of 10 m: a bed of 5 m +- 3 m of sinusoidal bumps and a 9 m peak that "
        "stands out of the water (a shoreline); level 10 m, closed edges, frictionless, 10000 "
        "steps of 0.5 s, both schemes.",
        "Well balanced: both schemes take the surface slope from levels, so only rounding "
        "moves the water. An idle solver passes this case; the wave-speed and real-DEM cases "
        "fail it.",
    ),
    "closed_box": (
        "Conservation in a closed box with erosion and slope collapse",
        "A 2 m hump of water sloshing over the bumpy bed (40 x 40 cells of 10 m) between "
        "closed walls, n = 0.02, erosion (capacity 0.5), conservative transport, thermal "
        "collapse at 20 deg, 10000 steps of 0.2 s.",
        "Nothing enters or leaves: water and material on the grid must not change beyond the "
        "rounding of what moved (the ledger's measure, not the whole volume).",
    ),
    "lake_at_rest_real_dem": (
        "Lake at rest on a real DEM with the sea as nodata, and a bump's arrival time",
        "A 100 x 176 crop of the Puget Sound DEM (160 m cells, the sea as nodata held at sea "
        "level) with the sea and the water raised to 20 m: a delta and its valley become a "
        "lake up to 16 m deep, connected to the sea cells; 2000 steps of 5 s at rest (report: "
        "10,000). Then a 1 cm Gaussian bump (sigma = 320 m) on the valley's 12.4 m floor is "
        "timed 2880 m away by the mean anomaly across the gauge's section, against the "
        "integral of ds / sqrt(g h) along the line (local inertial, by the peak) or the pipes' "
        "own c^2 = g A / dy (by the 5 % front). The profile's abscissa is t over the reference "
        "arrival time.",
        "Both schemes keep the lake exactly at rest over the real bed, shoreline and sea cells "
        "(speed 0 on every target), which an idle solver also does. The bump is the half an "
        "idle solver fails: local inertial's peak arrives at 0.984 of the sqrt(g h) travel "
        "time; the pipes' waves run at the speed of their fixed reference depth A / dy whatever "
        "the water's depth: with A = h dy their front arrives at 0.964 of the time at "
        "sqrt(g h), and with the default A = 1 m^2 they take 45 times as long (c = 0.25 m/s), "
        "on schedule for that speed.",
    ),
    "boundary_sediment": (
        "Sediment across open and fixed-level edges",
        "A 100 m x 8 m channel of 2 m cells (slope 0.02, n = 0.03) fed 0.1 m^2/s at its head, "
        "erosion on (K_c 0.2, K_s 0.5 /s), 1000 steps of 0.2 s, draining through an open or a "
        "fixed-level east edge (sea half the normal depth above the last bed); the material "
        "that left, summed per step from the fields ((bed + suspended) x area before minus "
        "after), against what the ledger books. A second case floods a dry basin 0.5-1.1 m "
        "below the sea through a fixed-level west edge for 150 s.",
        "Conservative transport: sediment leaves only with the water that leaves, at the edge "
        "cell's concentration, and the sea enters clear; the books close to rounding. "
        "Semi-Lagrangian transport has no boundary flux: it carries nothing out of a uniform "
        "concentration, lets the inlet cell keep its own concentration under clear inflow and "
        "makes material at wet/dry fronts (+12.6 m^3 in the flood case), all booked as "
        "transport_change. The frictionless pipes cut the channel about 1.5 m deep in 200 s: "
        "that run checks the books, not the physics.",
    ),
    "raster_parameters": (
        "Raster parameters: Manning n, hardness, rain factor, initial depth",
        "Every parameter written as a GeoTIFF and read through the DEM path. Two 2 km channels "
        "(3 x 200 cells of 10 m, slope 1e-3) apart by a nodata row, n = 0.03 and 0.06 from a "
        "raster, 0.5 m^2/s each from half their normal depth (an initial-depth raster), 8000 "
        "s; a hardness raster of 0 (north) and 1 (south) under a held uniform flow, against a "
        "uniform run; 50 mm/h for 600 s on three closed basins with rain factors 0.5, 2 and 0.",
        "Each Manning region reaches its own normal depth and speed; hardness 0 stops erosion "
        "exactly and hardness-1 cells compute as in the uniform run; the rain factor scales "
        "each basin's water to rounding. Parameters are per cell: the velocity at a change of "
        "n inside one channel is not checked.",
    ),
    "precision_ridged": (
        "float32 against float64: ridged 0-9000 m relief",
        "128^2 cells of 200 m, 1 h of 50 mm/h with erosion, transport and thermal collapse.",
        "The bed pair keeps float32 erosion within 1 % of float64 on high relief.",
    ),
    "precision_tujunga": (
        "float32 against float64: Big Tujunga crop",
        "256^2 cells of 30 m, the same storm.",
        "Bounded at 1 % since the thin-film fix of issue 14 (before it the float64 run itself "
        "moved 1.8 % under a change of rounding, and float32 differed by 1.3 %).",
    ),
    "ea_test1": (
        "EA benchmark test 1: flooding a disconnected water body (rebuilt)",
        "700 m x 100 m, bed along x through (0, 9.5), (100, 9.5), (300, 10.25), (350, 10.25), "
        "(450, 9.5), (550, 9.5), (650, 10.5), (700, 10.5) m; level on the west edge 9.7 m "
        "rising to 10.35 m at 1 h, held to 3 h, back to 9.7 m at 5 h; 20 h; n = 0.03; dx = 10 m "
        "(ctest) and 5 m (report). **Rebuilt**: the report's own profile, hydrograph and output "
        "points were not available to this work, only the description (a level hydrograph "
        "overtops a ridge and floods a depression that is then cut off). erodem has no "
        "time-varying level boundary: the level is imposed on the first column after each step, "
        "and the volume that moves is booked as the boundary's.",
        "No closed form. The reference is the mass balance: once the boundary falls below the "
        "crest the depression keeps the volume below its spill level, so the level that its "
        "stored volume gives must return to the crest (10.25 m); a few mm remain above it "
        "after 15 h as a thin Manning film drains (local inertial), and the pipes, whose "
        "fluxes carry inertia, overshoot it by about a mm on the way out. The figure shows the levels at "
        "x = 50, 250 and 500 m.",
    ),
    "ea_test2": (
        "EA benchmark test 2: filling of floodplain depressions (rebuilt)",
        "2 km x 2 km of 4 x 4 depressions, z = -0.5 sin^2(pi x / 500) sin^2(pi y / 500) m, "
        "20 m^3/s into the north-west depression's centre (ramped over 10 min, held to 50 min, "
        "off at 60 min: 60,000 m^3), 48 h, n = 0.03, dx = 20 m (ctest) and 10 m (report). "
        "**Rebuilt**: the published DEM and hydrograph were not available, only the "
        "description (an egg box of depressions filled from one corner).",
        "No closed form for the partly filled depressions (their share depends on the path). "
        "Checked: the mass balance (exact), the inflow's depression full to its spill level, no "
        "depression above its spill level, every wet depression flat. The figure shows the "
        "final level per depression against its spill level. **Local inertial fails at 20 m "
        "with the default Courant number 0.7** (dt = 6.3 s there; at 50 m dt_max = 10 s caps "
        "it at 0.44): the full depression never comes to rest, its levels still 0.15 m apart "
        "and 0.065-0.083 m over the spill level after 48 h (0.32 m and 0.12-0.16 m before issue "
        "14's flow changes), a sloshing that Manning friction does "
        "not damp. The same run at Courant 0.5 (`local_inertial cfl 0.5`) is at rest. The pipes "
        "pass at both resolutions.",
    ),
    "swashes_lake_at_rest": (
        "SWASHES 3.1.1: lake at rest with an immersed bump",
        "25 m channel, bed 0.2 - 0.05 (x - 10)^2 on 8 < x < 12 m, level 0.5 m, 20 s; dx = "
        "0.25 m (ctest) and 0.1, 0.05 m (report).",
        "Well balanced: both schemes compute the surface slope from levels, so the state is kept "
        "to rounding. The other SWASHES cases are not included: the MacDonald steady flows near "
        "Froude 1 and Thacker's moving shorelines need the advection term both schemes drop.",
    ),
}

# The full-size float32 scenarios (experiments/precision/compare.py): the report runs them as
# a user would, through the CLI; tests/test_precision.cpp runs their fast versions.
for _name in ("puget", "tujunga", "ridged"):
    CASES["precision_full_" + _name] = (
        "float32 against float64, full size: " + {
            "puget": "the Puget Sound main job",
            "tujunga": "a 1 h storm over all of Big Tujunga",
            "ridged": "ridged 0-9000 m relief, 512^2",
        }[_name],
        {
            "puget": "experiments/puget_sound/config.toml as the main job runs it (1025^2 cells "
                     "of 160 m, 0-4380 m, sea held at 0 m, 3 h storm, erosion, transport and "
                     "slope collapse), through the CLI.",
            "tujunga": "experiments/precision/tujunga.toml: all 1197 x 643 cells of 30 m "
                       "(315-2295 m), 1 h of 50 mm/h, erosion defaults, thermal collapse, open "
                       "edges, adaptive steps; through the CLI.",
            "ridged": "experiments/precision/ridged.toml: 512^2 cells of 100 m of ridged "
                      "0-9000 m relief, the same storm; through the CLI.",
        }[_name],
        "A plain float32 bed lost or biased the per-step changes below half an ulp (2.2 % "
        "less erosion on Puget Sound, 5 % more on Big Tujunga, up to 26 % on other tiles); the "
        "bed pair with the exact bed-sediment transfer (docs/model.md section 1) keeps the "
        "volumes within the issue's 1 %. Volumes from the final erosion field, as a user reads "
        "them.",
    )

REFERENCE_COLUMNS = {
    "depth_exact",
    "sediment_exact",
    "normal_depth",
    "level_exact",
    "bed",
    "bed_initial",
    "floor",
    "boundary_level",
    "spill_level",
    "pulse_exact",
}
SKIPPED_COLUMNS = {"u", "u_exact", "stored_m3", "t_s", "reference_arrival_s", "arrival_s"}
TARGET_STYLE = {"cpu_float64": "-", "cpu_float32": "--", "opencl_float32": ":"}
FIGURE_TARGET = "cpu_float64"


def run_cases(build: Path, records: Path, full: bool) -> int:
    binary = build / "tests" / "erodem_tests"
    if not binary.exists():
        sys.exit(f"run.py: {binary} is missing; build it first: "
                 f"cmake --build {build} --target erodem_tests")
    if records.exists():
        shutil.rmtree(records)
    records.mkdir(parents=True)
    env = dict(os.environ)
    env["ERODEM_VALIDATION_DIR"] = str(records)
    env["ERODEM_VALIDATION_LADDER"] = "full" if full else "coarse"
    env.setdefault("POCL_CACHE_DIR", str(build / "pocl-cache"))
    env.setdefault("OMP_NUM_THREADS", "2")
    with open(records / "gtest.log", "w") as log:
        proc = subprocess.run([str(binary), f"--gtest_filter={GTEST_FILTER}"], env=env,
                              stdout=log, stderr=subprocess.STDOUT, check=False)
    return proc.returncode


def run_full_size(build: Path, records: Path) -> bool:
    """Runs the full-size float32 scenarios of experiments/precision/compare.py and appends
    their figures to records.jsonl (replacing earlier ones). Returns False if a run failed."""
    sys.path.insert(0, str(ROOT / "experiments" / "precision"))
    import compare  # noqa: E402

    compare.ERODEM = str(build / "cli" / "erodem")
    path = records / "records.jsonl"
    kept = []
    if path.exists():
        kept = [line for line in path.read_text().splitlines()
                if line.strip() and not json.loads(line)["case"].startswith("precision_full_")]
    out = kept[:]
    ok = True
    cell = {"puget": 160.0, "tujunga": 30.0, "ridged": 100.0}
    for case in ("ridged", "tujunga", "puget"):
        cid = "precision_full_" + case
        reference = "the same run in float64 (cpu_float64)"

        def rec(target, quantity, value, bound):
            """One record; bound None: reported. A value of None fails its bound."""
            value = None if value is None else float(value)
            relation = "" if bound is None else "<"
            passed = bool(bound is None or (value is not None and abs(value) < bound))
            return json.dumps({
                "case": cid, "target": target, "scheme": "local_inertial", "quantity": quantity,
                "resolution": cell[case], "value": value, "order": None, "relation": relation,
                "bound": bound, "bound_hi": None, "pass": passed, "reference": reference,
                "full_ladder": True})

        try:
            rows = compare.run_case(case, log=lambda m: print("  " + m, flush=True))
        except Exception as e:  # a failed run is shown failing
            print(f"run.py: {case} failed: {e}", flush=True)
            ok = False
            out.append(rec("cpu_float32", f"the run failed: {e}", None, 0))
            continue
        ref = rows["cpu_float64"]

        out.append(rec("cpu_float64", "eroded volume (m^3)", ref[0], None))
        out.append(rec("cpu_float64", "deposited volume (m^3)", ref[1], None))
        out.append(rec("cpu_float64", "material closure (relative to moved)", abs(ref[4]), None))
        out.append(rec("cpu_float64", "wall time (s)", ref[5], None))
        for target, row in rows.items():
            if target == "cpu_float64":
                continue
            er, de, (ge, gd), _, rel, wall = row
            out.append(rec(target, "|eroded volume / float64's - 1|", abs(er / ref[0] - 1),
                           compare.VOLUME_BOUND))
            out.append(rec(target, "|deposited volume / float64's - 1|", abs(de / ref[1] - 1),
                           compare.VOLUME_BOUND))
            out.append(rec(target, "gross eroded (ledger) / float64's - 1", ge / ref[2][0] - 1,
                           None))
            out.append(rec(target, "gross deposited (ledger) / float64's - 1",
                           gd / ref[2][1] - 1, None))
            out.append(rec(target, "material closure (relative to moved)", abs(rel),
                           compare.CLOSURE_BOUND))
            out.append(rec(target, "wall time (s)", wall, None))
    path.write_text("\n".join(out) + "\n")
    return ok


def load_records(records: Path) -> list[dict]:
    path = records / "records.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def load_profiles(records: Path, case: str) -> list[tuple[str, str, dict]]:
    out = []
    for f in sorted((records / "profiles").glob(f"{case}__*.csv")):
        _, target, name = f.stem.split("__", 2)
        with open(f) as fh:
            rows = list(csv.DictReader(fh))
        cols = {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}
        out.append((target, name, cols))
    return out


def plot_case(case: str, recs: list[dict], profiles, path: Path) -> None:
    # The figure shows cpu_float64 (the table has every target).
    profiles = [p for p in profiles if p[0] == FIGURE_TARGET]
    series = collections.defaultdict(list)  # convergence: (target, scheme, quantity) -> points
    for r in recs:
        if r["value"] is not None and r["resolution"] and r["target"] == FIGURE_TARGET:
            series[(r["target"], r["scheme"], r["quantity"])].append((r["resolution"], r["value"]))
    ladders = {k: sorted(v) for k, v in series.items()
               if len({p[0] for p in v}) > 1 and all(p[1] > 0 for p in v) and "order" not in k[2]}
    panels = (1 if profiles else 0) + (1 if ladders else 0)
    width = 5.2 * panels if panels else 8.0
    fig, axes = plt.subplots(1, max(panels, 1), figsize=(width, 3.6), squeeze=False)
    axes = list(axes[0])
    if profiles:
        ax = axes.pop(0)
        drawn_refs = set()
        for target, name, cols in profiles:
            if target not in TARGET_STYLE:
                continue
            keys = list(cols)
            x = cols[keys[0]]
            for k in keys[1:]:
                if k in SKIPPED_COLUMNS:
                    continue
                if k in REFERENCE_COLUMNS:
                    if k in drawn_refs:
                        continue
                    drawn_refs.add(k)
                    ax.plot(x, cols[k], "k--" if "exact" in k or k == "normal_depth" else "0.6",
                            lw=1.0, label=k)
                else:
                    ls = "none" if keys[0] == "depression" else TARGET_STYLE[target]
                    marker = "o" if len(x) < 30 else None
                    ax.plot(x, cols[k], ls, marker=marker, ms=3, lw=1.2, label=f"{name} {k}")
        ax.set_xlabel(keys[0])
        ax.legend(fontsize=6, loc="best")
        ax.grid(alpha=0.3)
        ax.set_title("numerical against reference", fontsize=9)
    if ladders:
        ax = axes.pop(0)
        for (target, scheme, quantity), pts in sorted(ladders.items()):
            xs, ys = zip(*pts)
            ax.loglog(xs, ys, "-", marker="o", ms=3, label=f"{scheme}: {quantity[:48]}")
        ax.set_xlabel("resolution (dx in m, or dt in s)")
        ax.legend(fontsize=5, loc="best")
        ax.grid(alpha=0.3, which="both")
        ax.set_title("error against resolution", fontsize=9)
    if not panels:
        ax = axes.pop(0)
        bounded = [r for r in recs if r["bound"] is not None and r["value"] is not None]
        labels = [f"{r['scheme']}: {r['quantity'][:38]} ({r['target']})" for r in bounded]
        ratios = []
        for r in bounded:
            b = r["bound_hi"] if r["relation"] == "in" else r["bound"]
            ratios.append(abs(r["value"]) / abs(b) if b else float("nan"))
        colours = ["tab:green" if r["pass"] else "tab:red" for r in bounded]
        ax.barh(range(len(bounded)), ratios, color=colours)
        ax.set_yticks(range(len(bounded)))
        ax.set_yticklabels(labels, fontsize=5)
        for y, r in enumerate(bounded):
            ax.annotate(fmt(r["value"]), (1.0, y), xytext=(3, -2), textcoords="offset points",
                        fontsize=5)
        ax.axvline(1.0, color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("|measured| / |bound| (bound at 1)")
        ax.set_title("measured against bound", fontsize=9)
    fig.suptitle(textwrap.fill(CASES.get(case, (case,))[0], 90 if panels > 1 else 55), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def fmt(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float) and (math.isnan(v) or math.isinf(v)):
        return str(v)
    a = abs(v)
    return f"{v:.4g}" if a == 0 or 1e-3 <= a < 1e5 else f"{v:.2e}"


def bound_text(r: dict) -> str:
    if r["relation"] == "<":
        return f"< {fmt(r['bound'])}"
    if r["relation"] == ">":
        return f"> {fmt(r['bound'])}"
    if r["relation"] == "in":
        return f"{fmt(r['bound'])} .. {fmt(r['bound_hi'])}"
    return "reported"


def write_report(recs, records: Path, out_md: Path, images: Path, rc: int, wall: float,
                 full: bool, full_size: bool) -> bool:
    images.mkdir(parents=True, exist_ok=True)
    by_case = collections.OrderedDict()
    for name in CASES:
        by_case[name] = []
    for r in recs:
        by_case.setdefault(r["case"], []).append(r)
    failed = [r for r in recs if not r["pass"]]
    describe = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=ROOT,
                              capture_output=True, text=True, check=False).stdout.strip()
    lines = [
        "# Validation report",
        "",
        "Generated by `python3 experiments/validation/run.py` (build first: `cmake --build build "
        "--target erodem_tests erodem`), "
        f"{datetime.date.today().isoformat()}, `{describe}`, in {wall / 60:.1f} min. "
        "Do not edit by hand: rerun the command.",
        "",
        "Every case is a gtest case (`tests/test_analytical.cpp`, `test_validation.cpp`, "
        "`test_runoff.cpp`, `test_waves.cpp`, `test_physics.cpp`, `test_sources.cpp`, "
        "`test_boundaries_rasters.cpp`, `test_lake.cpp`, `test_precision.cpp`) run on the CPU reference in float32 and "
        "float64 and on OpenCL in float32; ctest runs the same cases at their coarse "
        "resolutions (label `validation`), this report the full ladders"
        + ("" if full else " (**this run: coarse only**)")
        + "; the full-size float32 scenarios (`precision_full_*`) are runs of the `erodem` CLI "
        "(experiments/precision/compare.py)"
        + ("" if full_size else " (**not in this run**)")
        + ". A row with a bound is asserted by the test; \"reported\" rows are measured, not "
        "bounded. Resolution is dx in m unless the quantity says dt in s. Order: the observed "
        "order against the previous rung of the ladder.",
        "",
        f"**{len(recs)} figures, {sum(r['pass'] for r in recs)} pass, {len(failed)} fail** "
        f"(exit status {rc}).",
        "",
        "| case | figures | failing |",
        "|---|---|---|",
    ]
    for case, rs in by_case.items():
        if rs:
            title = CASES.get(case, (case,))[0]
            lines.append(f"| [{title}](#{case}) | {len(rs)} | "
                         f"{sum(not r['pass'] for r in rs) or ''} |")
    for case, rs in by_case.items():
        if not rs:
            continue
        title, setup, note = CASES.get(case, (case, "", ""))
        png = images / f"{case}.png"
        plot_case(case, rs, load_profiles(records, case), png)
        refs = sorted({r["reference"] for r in rs if r["reference"]})
        lines += [
            "",
            f'<a id="{case}"></a>',
            f"## {title}",
            "",
            f"**Set-up.** {setup}",
            "",
            f"**Reference.** {'; '.join(refs)}.",
            "",
            f"**What the schemes can and cannot represent.** {note}",
            "",
            f"![{title}](images/validation/{case}.png)",
            "",
            "*Figure: cpu_float64; the table has every target.*",
            "",
            "| scheme | target | resolution | quantity | measured | order | bound | pass |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for r in rs:
            verdict = "pass" if r["pass"] else "**FAIL**"
            if r["relation"] == "":
                verdict = "reported"
            lines.append(
                f"| {r['scheme']} | {r['target']} | {fmt(r['resolution'])} | {r['quantity']} | "
                f"{fmt(r['value'])} | {fmt(r['order'])} | {bound_text(r)} | {verdict} |")
    out_md.write_text("\n".join(lines) + "\n")
    return not failed and rc == 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build", help="build folder (default: build)")
    ap.add_argument("--coarse", action="store_true",
                    help="the ctest rungs only (a quick check of the script)")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite the report from the records of the last run (build/validation)")
    ap.add_argument("--no-full-size", action="store_true",
                    help="leave out the full-size float32 scenarios (about an hour on 2 cores)")
    ap.add_argument("--full-size-only", action="store_true",
                    help="rerun only the full-size float32 scenarios, keeping the other records "
                         "of the last run")
    args = ap.parse_args()
    build = (ROOT / args.build).resolve()
    records = build / "validation"
    start = time.time()
    if args.report_only or args.full_size_only:
        state = json.loads((records / "run.json").read_text())
        rc, wall, args.coarse = state["rc"], state["wall"], state["coarse"]
        if args.full_size_only:
            full_ok = run_full_size(build, records)
            rc = rc or (0 if full_ok else 1)
            wall = state["gtest_wall"] + time.time() - start
            state.update(rc=rc, wall=wall, full_size=True)
            (records / "run.json").write_text(json.dumps(state))
    else:
        rc = run_cases(build, records, not args.coarse)
        gtest_wall = time.time() - start
        full = not args.coarse and not args.no_full_size
        # written now too, so --full-size-only can follow a run whose full-size part failed
        (records / "run.json").write_text(json.dumps(
            {"rc": rc, "wall": gtest_wall, "gtest_wall": gtest_wall, "coarse": args.coarse,
             "full_size": False}))
        if full and not run_full_size(build, records):
            rc = rc or 1
        wall = time.time() - start
        (records / "run.json").write_text(json.dumps(
            {"rc": rc, "wall": wall, "gtest_wall": gtest_wall, "coarse": args.coarse,
             "full_size": full}))
    recs = load_records(records)
    full_size = json.loads((records / "run.json").read_text()).get("full_size", False)
    ok = write_report(recs, records, ROOT / "docs" / "validation.md",
                      ROOT / "docs" / "images" / "validation", rc, wall, not args.coarse,
                      full_size)
    failed = sum(not r["pass"] for r in recs)
    print(f"validation: {len(recs)} figures, {failed} failing, test binary exit {rc}, "
          f"{wall:.0f} s; wrote docs/validation.md and docs/images/validation/")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
