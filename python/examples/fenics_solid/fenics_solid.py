#!/usr/bin/env python3
"""A FEniCS (legacy DOLFIN) finite-element solid served through fsi.server: it replaces
solid_server in any scene whose solid is a structured rectangle (2D, e.g. the Turek-Hron flag),
box or tube, or a gmsh file of tetrahedra (3D: the dimension is the mesh's).

    fsi run python/examples/fenics_solid/scenes/csm1.yaml --out runs/csm1_fenics \\
        --solid-command "python3 python/examples/fenics_solid/fenics_solid.py --cell triangle --degree 2"
    fsi run configs/block_3d.yaml --out runs/block_3d_fenics \\
        --solid-command "python3 python/examples/fenics_solid/fenics_solid.py"

It reads the same `solid` section as solid_server's `model: fem` (mesh rectangle, box, tube or gmsh,
material, density, gravity, analysis, time_scheme, load_steps, clamp, supports, interface,
tractions, point_loads, probes, newton, output_every), so one scene runs with either solid.
In 3D the interface is sent as faces (dimension 3): Q1 hexahedra (the default on a box) give
4-node faces, `--cell tetrahedron --degree 1|2` 3- or 6-node triangles (each hexahedron of the
box or tube cut into 6 tetrahedra); a gmsh mesh (`type: gmsh`, ASCII MSH 2.2, 4- or 10-node
tetrahedra with straight edges) gives P1 or P2 on its tetrahedra (P2 on 10-node ones: the space
of solid_server's Tet10) and 3- or 6-node faces from its named face groups. The element is this
solid's own choice: `--cell triangle --degree 2` (accurate on coarse meshes), or a section
`solid.fenics: {cell, degree, diagonal, quadrature_degree}` in a scene written for it alone
(solid_server refuses the key). By default it uses solid_server's element (Q1, 2 x 2 Gauss
points) and gives its numbers on the same mesh (docs/coupling-your-code.md). The physics is in fem.py beside this file.

Needs Debian's python3-dolfin (scripts/install-deps.sh). Under a python3 without dolfin
(pyenv's, say) it re-runs itself with the build's Python. DOLFIN compiles its forms on first
use and caches them in $DIJITSO_CACHE_DIR (default ~/.cache/dijitso, also inside a venv).
"""
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
try:
    import fsi.interpreter  # noqa: F401 - the package installed (pip install ./python)
except ImportError:  # from the source tree: python/ is two levels up
    sys.path.insert(0, os.path.dirname(os.path.dirname(HERE)))
from fsi.interpreter import require  # noqa: E402

require("dolfin", "scipy", "numpy", "yaml", "zmq", "google.protobuf")
# One form cache for every interpreter (dijitso would put a venv's inside the venv).
os.environ.setdefault("DIJITSO_CACHE_DIR", os.path.join(os.path.expanduser("~"), ".cache", "dijitso"))

import numpy as np  # noqa: E402

import fsi.server as fs  # noqa: E402

sys.path.insert(0, HERE)
# fem.py imports DOLFIN (several seconds): it is imported by configure, so that the port file
# appears and `hello` is answered at once (the launcher allows 10 s and 5 s for those).
fem = None


def _import_fem():
    global fem
    if fem is None:
        t0 = time.perf_counter()
        import fem as module
        fem = module
        _log(f"DOLFIN {module.df.__version__} imported in {time.perf_counter() - t0:.1f} s; form cache "
             f"{os.environ['DIJITSO_CACHE_DIR']}")
    return fem


def _log(text):
    print(f"[fenics_solid] {text}", file=sys.stderr, flush=True)


class FenicsSolid(fs.Solid):
    """The protocol side: each method is one request of fsi.v1 (proto/README.md)."""
    name = "python fenics_solid.py (DOLFIN)"
    # solve_step never changes the accepted state (d_n, v_n, a_n live in the model and change
    # only in accept_step / load), so fsi.server need not copy anything between iterations.
    restart = "none"

    def __init__(self, element=None):
        self.element = element or {}  # defaults of solid.fenics from the command line

    def configure(self, section, dt, end_time, interface_damping, output_dir):
        """Configure: build the mesh, the forms and the interface; return the interface nodes."""
        _import_fem()
        t0 = time.perf_counter()
        try:
            self.model = fem.FlagSolid(section, dt, interface_damping, log=_log, element=self.element,
                                        scene_path=self.scene_path)
        except fem.SceneError as e:
            raise fs.InvalidArgument(f"{self.scene_path}: {e}") from None
        m = self.model
        self.output_dir = output_dir
        _log(f"{m.dim}D {m.cell} mesh ({m.diagonal if m.cell == 'triangle' else m.mesh_file or 'structured'}), "
             f"{m.mesh.num_cells()} cells, "
             f"{'Q' if m.tensor else 'P'}{m.degree}, quadrature degree {m.quadrature_degree}, "
             f"{m.n} dofs ({m.free.size} free), "
             f"{m.law}, mu {m.mu:.6g}, lambda {m.lam:.6g}, {m.analysis}"
             + ("" if m.scheme == "static" else f" {m.scheme}") + f", {len(m.interface_nodes)} interface nodes, "
             f"gamma_N1 {interface_damping:g}; set up in {time.perf_counter() - t0:.2f} s")
        if m.dim == 2:
            return fs.Interface(coordinates=m.interface_xy.reshape(-1), segments=m.segments.reshape(-1),
                                node_ids=m.ix[m.interface_nodes])
        return fs.Interface(coordinates=m.interface_xy.reshape(-1), faces=m.faces, node_ids=m.ix[m.interface_nodes],
                            dimension=3)

    def set_interface_mass(self, matrix):
        """SolveStep.interface_mass (Algorithm 2): M_fs = gamma_N1 * M_G from now on."""
        self.model.set_interface_mass(matrix.rows, matrix.cols, matrix.values)

    def solve_step(self, step, time, dt, iteration, force):
        """SolveStep: Newton for step n+1 from the accepted state with this interface force."""
        try:
            d, v = self.model.solve(dt, np.asarray(force, dtype=float))
        except fem.NewtonFailed as e:  # SOLVER_FAILED: the coupler reports the run as diverged
            raise fs.SolverFailed(f"step {step} (t = {time:.6g}), iteration {iteration}: {e}") from None
        return d, v, self.model.newton_iterations

    def accept_step(self, step, time):
        """AcceptStep: the last solve becomes the state; the probes of A etc."""
        if not self.model.solved:
            raise fs.InvalidArgument(f"accept_step {step} without a solve_step")
        probes = self.model.accept()
        probes["newton_iterations"] = self.model.newton_iterations
        return probes

    def timings(self):
        """Cumulative seconds (setup, step = every solve, assembly and linear_solve inside it),
        shown as wall_time.solid_breakdown in summary.json."""
        return dict(self.model.timings)

    def save(self):
        """SaveCheckpoint: d, v, a (and the step before, for BDF2) of the accepted step."""
        return self.model.save()

    def load(self, state):
        """LoadCheckpoint: restore them; a state of another discretisation is refused."""
        self.model.load(state)

    def write_output(self, step, time):
        """WriteOutput: the displacement as a VTK series (solid.output_every as solid_server)."""
        m = self.model
        if not self.output_dir or m.output_every == 0 or step % m.output_every:
            return []
        return [m.write_vtk(self.output_dir, time)]


def main():
    parser = fs.argument_parser(__doc__.splitlines()[0])
    g = parser.add_argument_group("the element (defaults of the scene's solid.fenics, which wins when present)")
    g.add_argument("--cell", choices=("quadrilateral", "triangle", "hexahedron", "tetrahedron"),
                   help="default quadrilateral (2D, mesh type rectangle) / hexahedron (3D, mesh type box or tube)")
    g.add_argument("--degree", type=int, help="Lagrange degree (default 1; quadrilaterals and hexahedra: 1 only)")
    g.add_argument("--diagonal", choices=("crossed", "right", "left", "right/left", "left/right"),
                   help="how the rectangles of solid.mesh.elements are cut into triangles (default crossed; "
                        "2D only: the cells of a box or tube are cut into 6 tetrahedra each)")
    g.add_argument("--quadrature-degree", type=int, help="default 2 on quadrilaterals / hexahedra (2 x 2 (x 2) "
                                                           "Gauss), 2 x degree on triangles / tetrahedra")
    args = parser.parse_args()
    element = {"cell": args.cell, "degree": args.degree, "diagonal": args.diagonal,
               "quadrature_degree": args.quadrature_degree}
    return fs.serve(lambda a: FenicsSolid(element), args=args)


if __name__ == "__main__":
    sys.exit(main())
