#!/usr/bin/python3
"""fsi.units: the unit of every probes.csv column from the scene's `units` (SI or CGS), its
dimension (forces, work and power per unit depth in 2D) and the probes it declares; fsi plot's
test for a probe that is constant (drawn flat with its value, not round-off magnified)."""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(ROOT / "tools"))
from fsi import units as U  # noqa: E402
import fsi_plot  # noqa: E402

from checks import check, failures  # noqa: E402

thick = {"units": "CGS", "solid": {"probes": [{"name": "A", "point": [1.0, 0.5]}]},
         "fluid": {"pressure_probes": {"p_front": [0, 0]}, "pressure_differences": {"dp": ["p_front", "p_back"]}}}
tube = {"units": "CGS", "fluid": {"dimension": 3, "pressure_probes": {"p2": [0, 0, 2.5]}},
        "solid": {"probes": [{"name": "r2", "point": [0.5, 0, 2.5]}]}}
want = [
    ("time", {}, "s"),
    ("solid.d_x", {}, "m"), ("solid.v_y", {}, "m/s"), ("fluid.force_x", {}, "N/m"),
    ("solid.A_x", thick, "cm"), ("solid.A_y", {"solid": thick["solid"]}, "m"),
    ("fluid.drag", thick, "dyn/cm"), ("fluid.flag_lift", thick, "dyn/cm"), ("fluid.cd", thick, "1"),
    ("fluid.p_front", thick, "dyn/cm²"), ("fluid.dp", thick, "dyn/cm²"),
    ("coupling.work_solid", thick, "erg/cm"), ("coupling.power_fluid", {}, "W/m"),
    ("coupling.solid_force_y", {}, "N/m"),
    ("fluid.p2", tube, "dyn/cm²"), ("solid.r2_z", tube, "cm"), ("coupling.solid_force_z", tube, "dyn"),
    ("coupling.work_fluid", tube, "erg"), ("coupling.power_solid", tube, "erg/s"),
    ("coupling.iterations", tube, "1"), ("fluid.mesh_min_scaled_jacobian", {}, "1"), ("coupling.residual", {}, "1"),
    ("solid.unknown_x", {}, None), ("fluid.p9", thick, None), ("whatever", {}, None),
]
for column, params, unit in want:
    got = U.unit(column, params)
    check(got == unit, f"{column} with {params.get('units', 'SI')}: {got!r}, want {unit!r}")
check(U.label("solid.A_x", thick) == "solid.A_x [cm]", U.label("solid.A_x", thick))
check(U.label("solid.unknown_x", {}) == "solid.unknown_x", "a column of no known quantity keeps its bare name")
try:
    U.unit("solid.d_x", {"units": "furlongs"})
    check(False, "units: furlongs accepted")
except ValueError as e:
    check("furlongs" in str(e) and "SI" in str(e), str(e))

steady = 0.123456 + 1e-12 * np.arange(50)
check(fsi_plot.constant_to(steady) is not None and fsi_plot.constant_to(steady) < 1e-9,
      f"a probe steady to 1e-11: {fsi_plot.constant_to(steady)}")
check(fsi_plot.constant_to(np.linspace(0.0, 1.0, 50) + 1.0) is None, "a changing probe is not constant")
check(fsi_plot.constant_to(np.zeros(5)) is None, "a zero probe is not drawn at all (no relative spread)")

sys.exit(1 if failures else 0)
