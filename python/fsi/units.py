"""Units of probes.csv columns, for axis labels and tables.

The solvers take no unit system of their own: every value is in the units of the scene's
numbers. A scene says which system its numbers are in with its top-level key ``units`` (SI,
the default, or CGS); a run's summary.json holds the scene in ``parameters``. From it and a
column's name (and the probes the scene declares) this module gives the column's unit:

    >>> unit("fluid.drag", {"units": "CGS"})
    'dyn/cm'
    >>> label("solid.A_x", {"solid": {"probes": [{"name": "A", "point": [1, 2]}]}})
    'solid.A_x [m]'

Forces, work and power are per unit depth in 2D (the README's table); in 3D they are totals.
A column whose quantity is not known gets no unit (its label is the bare name).
"""
import re

SYSTEMS = ("SI", "CGS")

# quantity -> (SI, CGS); the 2D (per unit depth) and 3D forms where they differ.
_UNITS = {
    "time": ("s", "s"),
    "length": ("m", "cm"),
    "velocity": ("m/s", "cm/s"),
    "pressure": ("Pa", "dyn/cm²"),
    "force_2d": ("N/m", "dyn/cm"),
    "force_3d": ("N", "dyn"),
    "work_2d": ("J/m", "erg/cm"),
    "work_3d": ("J", "erg"),
    "power_2d": ("W/m", "erg/(s cm)"),
    "power_3d": ("W", "erg/s"),
    "angle": ("degrees", "degrees"),
    "one": ("1", "1"),
}

_COUNTS = ("iterations", "factorisations", "solves")


def system(parameters):
    """'SI' or 'CGS': the scene's ``units`` (SI when absent). Raises ValueError for another."""
    s = (parameters or {}).get("units", "SI")
    if s not in SYSTEMS:
        raise ValueError(f"units: '{s}' is not one of {', '.join(SYSTEMS)}")
    return s


def dimension(parameters):
    """2 or 3: the scene's fluid.dimension or solid.dimension (2 when neither says)."""
    p = parameters or {}
    for section in ("fluid", "solid"):
        d = (p.get(section) or {}).get("dimension")
        if d in (2, 3, "2", "3"):
            return int(d)
    mesh = ((p.get("solid") or {}).get("mesh") or {})
    if mesh.get("type") in ("box", "tube") or len(mesh.get("divisions") or []) == 3:
        return 3
    return 2


def _names(value):
    if isinstance(value, dict):
        return set(value)
    if isinstance(value, list):
        return {v.get("name", "") for v in value if isinstance(v, dict)}
    return set()


def quantity(column, parameters=None):
    """The quantity of a probes.csv column ('length', 'force', 'pressure', ...), or None."""
    p = parameters or {}
    if column == "time":
        return "time"
    part, _, name = column.partition(".")
    if not name:
        return None
    if name.endswith(_COUNTS) or name in ("residual", "nonlinear_change") or name.startswith("mesh_min_"):
        return "one"
    if name == "mesh_max_angle":
        return "angle"
    if part == "coupling":
        if name.startswith("work_"):
            return "work"
        if name.startswith("power_"):
            return "power"
        if name.startswith("solid_force_"):
            return "force"
        return None
    if part == "fluid":
        fluid = p.get("fluid") or {}
        if name in _names(fluid.get("pressure_probes")) or name in _names(fluid.get("pressure_differences")):
            return "pressure"
        if re.fullmatch(r"force_[xyz]", name) or name.endswith(("drag", "lift", "side")):
            return "force"
        if name.endswith(("cd", "cl")):
            return "one"
        if re.fullmatch(r"p_\w+|dp", name):
            return "pressure"
        return None
    if part == "solid":
        m = re.fullmatch(r"(\w+)_([xyz])", name)
        if m is None:
            return None
        if m.group(1) == "d":
            return "length"
        if m.group(1) == "v":
            return "velocity"
        if m.group(1) in _names((p.get("solid") or {}).get("probes")):
            return "length"
        return None
    return None


def unit(column, parameters=None):
    """The unit of a probes.csv column in the scene's system ('m', 'dyn/cm', '1'), or None."""
    q = quantity(column, parameters)
    if q is None:
        return None
    if q in ("force", "work", "power"):
        q += "_3d" if dimension(parameters) == 3 else "_2d"
    return _UNITS[q][SYSTEMS.index(system(parameters))]


def label(column, parameters=None):
    """'column [unit]' for an axis label; the bare name when the unit is not known."""
    u = unit(column, parameters)
    return f"{column} [{u}]" if u else column
