"""Reads a 3D fluid .vtu with meshio (test_tet_motion.cpp, Vtk3): prints the number of points,
of quadratic tetrahedra, the velocity's largest deviation from u = (x, 2 y, -3 z) at the points,
the pressure's length, how many midpoints are not at the middle of their VTK edge (01 12 20 03
13 23) and how many tetrahedra have a negative volume; with VTK's own reader (python3-vtk9, what
ParaView uses) if installed, the number of cells and their type."""
import sys

import meshio
import numpy as np

m = meshio.read(sys.argv[1])
x = m.points
print("points", len(x))
cells = np.concatenate([c.data for c in m.cells if c.type == "tetra10"]) if any(
    c.type == "tetra10" for c in m.cells) else np.zeros((0, 10), dtype=int)
print("tetra10", len(cells))
# The velocity was set on the reference mesh: u = (x, 2 y, -3 z); the points are the current
# positions minus mesh_displacement.
ref = x - m.point_data["mesh_displacement"]
u = m.point_data["velocity"]
expected = np.column_stack([ref[:, 0], 2 * ref[:, 1], -3 * ref[:, 2]])
print("velocity_error", np.abs(u - expected).max())
print("pressure_points", len(np.ravel(m.point_data["pressure"])))
edges = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
off = 0
for c in cells:
    for k, (a, b) in enumerate(edges):
        if np.abs(x[c[4 + k]] - 0.5 * (x[c[a]] + x[c[b]])).max() > 1e-9:
            off += 1
print("midpoints_off_their_edge", off)
vol = np.einsum("ij,ij->i", x[cells[:, 1]] - x[cells[:, 0]],
                np.cross(x[cells[:, 2]] - x[cells[:, 0]], x[cells[:, 3]] - x[cells[:, 0]]))
print("negative_volumes", int((vol <= 0).sum()))
# VTK itself (what ParaView reads with), when installed: cells and their type (24 = quadratic tetra).
try:
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
except ImportError:
    vtkXMLUnstructuredGridReader = None
if vtkXMLUnstructuredGridReader is not None:
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(sys.argv[1])
    reader.Update()
    grid = reader.GetOutput()
    types = {grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}
    print("vtk_cells", grid.GetNumberOfCells())
    print("vtk_cell_type", types.pop() if len(types) == 1 else -1)
