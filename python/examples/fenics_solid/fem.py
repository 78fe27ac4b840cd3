"""The finite-element part of the FEniCS solid: legacy DOLFIN (Debian's python3-dolfin), no
protocol here (fenics_solid.py serves it through fsi.server).

A total Lagrangian hyperelastic solid (St. Venant-Kirchhoff or compressible neo-Hookean), 2D
plane strain or 3D, the dimension taken from the mesh (`rectangle`, `box`, `tube`, or `gmsh`:
an MSH 2.2 file of 4- or 10-node tetrahedra, gmsh_tetrahedra below; one code path for
both: Identity(dim), V.sub(c) for each component), Lagrange elements on triangles /
tetrahedra (P1, P2, ...) or quadrilaterals / hexahedra (Q1), full Newton with the consistent
tangent that UFL derives, and the time schemes of solid_server:

    M a_{n+1} + M_fs v_{n+1} + F_int(d_{n+1}) = F_dead + F_interface

    static    F_int(d) = F, the load taken from the last accepted one in `load_steps` increments
    newmark   trapezoidal rule (beta = 1/4, gamma = 1/2), a_0 = M^-1 F_dead
    bdf2      v = (3 d - 4 d_n + d_{n-1}) / (2 dt), a alike; the first step is bdf1
    bdf1      v = (d - d_n) / dt, a = (v - v_n) / dt

DOLFIN assembles the internal force F_int(d) and its tangent K(d) (the forms below), the mass
matrix M and the dead loads (gravity, edge / face tractions) once; everything nodal (the coupler's
interface force, the interface damping M_fs = gamma_N1 M_G, the time-scheme terms) is added to
the assembled arrays with scipy, and the Newton systems are solved on the free dofs with
SuperLU. Units: SI (m, kg, s, N, Pa), unit thickness in 2D.
"""
import io
import math
import os
import time as _time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import dolfin as df

df.set_log_level(40)  # DOLFIN's progress lines off; errors still raise
df.parameters["form_compiler"]["cpp_optimize"] = True
df.parameters["form_compiler"]["optimize"] = True

STATE_TAG = "fenics-solid-1"
SCHEMES = ("newmark", "bdf1", "bdf2")


class NewtonFailed(RuntimeError):
    """Newton did not converge, or the state is not finite (SOLVER_FAILED: the run diverged)."""


# -- reading the section: the SDK's strict reader (python/fsi/section.py) ----------------------
try:
    from fsi.section import SceneError, Section  # noqa: F401 - SceneError is this module's error too
except ImportError:  # fem.py imported on its own: the package fsi is two folders up
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    from fsi.section import SceneError, Section  # noqa: F401


TUBE_FACET_SETS = ("inner", "outer", "start", "end")


def tube_mesh(origin, r_inner, r_outer, length, n_theta, n_r, n_z):
    """solid_server's tube_mesh (solid_server/core/src/mesh.cpp): node (i radial, j around,
    k along) is (k n_theta + j) (n_r + 1) + i at (r_i cos theta_j, r_i sin theta_j, z_k) from
    the origin. Returns (nodes, hexahedra in DOLFIN's tensor-product vertex order: vertex a at
    (i, j, k) + bits of a, i.e. solid_server's (r, theta, z) hexahedron 0 1 2 3 4 5 6 7 as
    0 1 3 2 4 5 7 6, the same cells in the same order), (i, j, k) of each node)."""
    k, j, i = np.meshgrid(np.arange(n_z + 1), np.arange(n_theta), np.arange(n_r + 1), indexing="ij")
    ijk = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    r = r_inner + (r_outer - r_inner) * ijk[:, 0] / n_r
    theta = 2 * math.pi * ijk[:, 1] / n_theta
    nodes = np.stack([origin[0] + r * np.cos(theta), origin[1] + r * np.sin(theta),
                      origin[2] + length * ijk[:, 2] / n_z], axis=1)

    def node(i, j, k):
        return (k * n_theta + j % n_theta) * (n_r + 1) + i

    # DOLFIN takes a hexahedron whose vertex numbers rise in its own order only; the last cell
    # around (j + 1 = 0) is numbered from its j + 1 side, its second axis pointing to -theta
    # (a left-handed cell: DOLFIN integrates with |det J|)
    cells = [[node(i + di, (j + dj) if j < n_theta - 1 else (j + 1 - dj), k + dk)
              for dk in (0, 1) for dj in (0, 1) for di in (0, 1)]
             for k in range(n_z) for j in range(n_theta) for i in range(n_r)]
    return nodes, np.array(cells, dtype=np.int64), ijk


# -- gmsh meshes (solid.mesh.type: gmsh): MSH 2.2 ASCII, 3D, 4- or 10-node tetrahedra --------
# element dimension by gmsh type (the types a 3D solid mesh may hold; others are refused)
GMSH_DIMENSION = {15: 0, 1: 1, 8: 1, 26: 1, 2: 2, 3: 2, 9: 2, 10: 2, 16: 2, 20: 2, 21: 2,
                  4: 3, 5: 3, 6: 3, 7: 3, 11: 3, 12: 3, 13: 3, 14: 3, 17: 3, 18: 3, 19: 3, 29: 3}
GMSH_NAMES = {4: "4-node tetrahedra", 11: "10-node tetrahedra", 5: "8-node hexahedra", 17: "20-node hexahedra",
              12: "27-node hexahedra", 6: "6-node prisms", 7: "5-node pyramids", 2: "3-node triangles",
              9: "6-node triangles", 3: "4-node quadrilaterals", 10: "9-node quadrilaterals",
              16: "8-node quadrilaterals"}
TET10_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (2, 3), (1, 3))  # gmsh: nodes 4..9 at their midpoints
MIDPOINT_TOLERANCE = 1e-6  # |mid-edge node - edge midpoint| / edge length: a straight cell


def read_msh22(path):
    """A gmsh MSH 2.2 ASCII file: (physical names {(dim, tag): name}, node coordinates (n x 3),
    {gmsh node number: row}, elements [(number, type, physical tag, [gmsh node numbers])])."""
    try:
        with open(path) as fh:
            lines = fh.read().split("\n")
    except UnicodeDecodeError:
        raise SceneError(f"'{path}' is not a text file: this solid reads ASCII MSH 2.2 "
                         f"(gmsh -format msh22, without -bin)") from None
    sections, name, body = {}, None, []
    for line in lines:
        line = line.strip()
        if name is None:
            if line.startswith("$"):
                name, body = line[1:], []
        elif line == "$End" + name:
            sections[name], name = body, None
        else:
            body.append(line)
    if name is not None:
        raise SceneError(f"'{path}': section ${name} has no $End{name}")
    fmt = sections.get("MeshFormat", [""])[0].split()
    if len(fmt) < 2 or not fmt[0].startswith("2") or fmt[1] != "0":
        got = "no $MeshFormat" if not fmt else f"MSH {fmt[0]}{' binary' if len(fmt) > 1 and fmt[1] != '0' else ''}"
        raise SceneError(f"'{path}': {got}; this solid reads ASCII MSH 2.2 (gmsh -format msh22)")
    if "Nodes" not in sections or "Elements" not in sections:
        raise SceneError(f"'{path}': no $Nodes or no $Elements section")
    names = {}
    for line in sections.get("PhysicalNames", [])[1:]:
        parts = line.split(maxsplit=2)
        if len(parts) == 3:
            names[(int(parts[0]), int(parts[1]))] = parts[2].strip().strip('"')
    try:
        node_lines = sections["Nodes"][1:1 + int(sections["Nodes"][0])]
        table = np.array([line.split() for line in node_lines], dtype=float).reshape(-1, 4)
        elements = []
        for line in sections["Elements"][1:1 + int(sections["Elements"][0])]:
            v = [int(x) for x in line.split()]
            elements.append((v[0], v[1], v[3] if v[2] > 0 else 0, v[3 + v[2]:]))
    except (ValueError, IndexError) as e:
        raise SceneError(f"'{path}': not a readable MSH 2.2 file ({e})") from None
    row = {int(n): k for k, n in enumerate(table[:, 0])}
    return names, table[:, 1:], row, elements


def gmsh_tetrahedra(path, domain=None):
    """The 3D solid mesh of a gmsh MSH 2.2 file: the 3D physical groups (or only `domain`) of
    4- or 10-node tetrahedra are the cells, every 2D physical group of 3- or 6-node triangles a
    face set by its name. Legacy DOLFIN has straight cells: the mid-edge nodes of 10-node
    tetrahedra must sit at the middle of their edges (MIDPOINT_TOLERANCE of the edge length; a
    straight-sided gmsh mesh does), and only the vertices are kept (P2 on these straight cells
    is the space of solid_server's Tet10). Returns (vertex coordinates, cells (n x 4 vertex
    rows), {group: (n x 3 vertex rows, gmsh element numbers)}, 1 or 2: the file's order, the
    face groups with a face inside the solid (a side of two cells))."""
    names, X, row, elements = read_msh22(path)

    def group(dim, tag):
        return names.get((dim, tag), str(tag))

    volumes = [e for e in elements if GMSH_DIMENSION.get(e[1]) == 3]
    if not volumes:
        dims = sorted({GMSH_DIMENSION.get(e[1], -1) for e in elements})
        raise SceneError(f"'{path}' has no 3D elements (element dimensions {dims}): the FEniCS solid reads 3D "
                         f"gmsh meshes of 4- or 10-node tetrahedra (a 2D solid is mesh type rectangle)")
    groups3 = sorted({group(3, e[2]) for e in volumes})
    if domain is not None:
        if domain not in groups3:
            raise SceneError(f"'{path}' has no 3D physical group '{domain}' (its 3D groups: {', '.join(groups3)})")
        volumes = [e for e in volumes if group(3, e[2]) == domain]
    types = sorted({e[1] for e in volumes})
    for t in types:
        if t not in (4, 11):
            g = sorted({group(3, e[2]) for e in volumes if e[1] == t})
            raise SceneError(f"'{path}', group '{g[0]}': {GMSH_NAMES.get(t, f'gmsh element type {t}')}; the FEniCS "
                             f"solid takes 4- or 10-node tetrahedra from a file (hexahedra: mesh type box or tube)")
    if len(types) > 1:
        raise SceneError(f"'{path}': both 4- and 10-node tetrahedra; one cell type per mesh")
    order = 2 if types[0] == 11 else 1
    try:
        nodes = np.array([[row[n] for n in e[3]] for e in volumes], dtype=np.int64)
    except KeyError as e:
        raise SceneError(f"'{path}': an element refers to node {e}, which is not in $Nodes") from None
    if order == 2:
        a = X[nodes[:, [p for p, _ in TET10_EDGES]]]
        b = X[nodes[:, [q for _, q in TET10_EDGES]]]
        off = np.linalg.norm(X[nodes[:, 4:]] - 0.5 * (a + b), axis=2) / np.linalg.norm(b - a, axis=2)
        worst = int(np.argmax(off.max(axis=1)))
        if off[worst].max() > MIDPOINT_TOLERANCE:
            e = volumes[worst]
            curved = int((off > MIDPOINT_TOLERANCE).any(axis=1).sum())
            raise SceneError(f"'{path}', group '{group(3, e[2])}', element {e[0]}: a mid-edge node is off its edge's "
                             f"midpoint by {off[worst].max():.2e} of the edge length (a curved cell; {curved} "
                             f"such cells): legacy DOLFIN has straight cells only (mesh with gmsh -setnumber "
                             f"Mesh.SecondOrderLinear 1, or 4-node tetrahedra)")
    used = np.unique(nodes[:, :4])
    vertex = np.full(len(X), -1, dtype=np.int64)
    vertex[used] = np.arange(len(used))
    cells = vertex[nodes[:, :4]]
    # the face groups: every 2D physical group, by name; each facet a side of a cell
    sides = {}
    for c in cells:
        for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
            key = tuple(sorted(int(c[k]) for k in f))
            sides[key] = sides.get(key, 0) + 1
    faces = {}
    owner = {}
    for e in elements:
        if GMSH_DIMENSION.get(e[1]) != 2:
            continue
        name = group(2, e[2])
        if e[1] not in (2, 9):
            raise SceneError(f"'{path}', group '{name}': {GMSH_NAMES.get(e[1], f'gmsh element type {e[1]}')}; the "
                             f"face groups of a tetrahedron mesh are 3- or 6-node triangles")
        try:
            tri = tuple(int(vertex[row[n]]) for n in e[3][:3])
        except KeyError as err:
            raise SceneError(f"'{path}': an element refers to node {err}, which is not in $Nodes") from None
        key = tuple(sorted(tri))
        if -1 in tri or key not in sides:
            raise SceneError(f"'{path}', group '{name}', element {e[0]}: a triangle that is no side of a "
                             f"tetrahedron{'' if domain is None else f' of {domain}'}")
        if owner.get(key, name) != name:
            raise SceneError(f"'{path}', element {e[0]}: a face in both groups '{owner[key]}' and '{name}'; this "
                             f"solid takes disjoint face groups")
        owner[key] = name
        faces.setdefault(name, ([], []))
        faces[name][0].append(tri)
        faces[name][1].append(e[0])
    groups = {k: (np.array(v[0], dtype=np.int64).reshape(-1, 3), v[1]) for k, v in faces.items()}
    interior = sorted({owner[k] for k, n in sides.items() if n > 1 and k in owner})
    return X[used], cells, groups, order, interior


# -- the model ----------------------------------------------------------------------------------
class FlagSolid:
    """The solid of one run: mesh, function space, forms, state (d, v, a of the last accepted
    step and of the current solve) and the interface, in 2D or 3D (`dim`, from the mesh:
    `rectangle`, `box`, `tube` or `gmsh`: a file of tetrahedra). All vectors are numpy arrays
    over the DOLFIN dofs of V (`dim` components interleaved by DOLFIN's dof map, not
    necessarily x0 y0 x1 y1: `comp[:, c]` are the dofs of component c, node by node; `ix`,
    `iy`, `iz` the same by name)."""

    FACET_SETS = ("left", "right", "bottom", "top", "back", "front")  # x, y, z: the first 2 dim
    COMPONENTS = ("x", "y", "z")
    # the cells of each dimension: tensor-product (Q1) first, then simplices
    CELLS = {2: ("quadrilateral", "triangle"), 3: ("hexahedron", "tetrahedron")}
    # solid_server's `solid.element` per dimension: the plain one (this solid's default element,
    # the same numbers) and its enhanced-strain variant (no enhanced strains here: refused in
    # 2D as always; accepted with a line in the log in 3D, so that solid_server's 3D scenes run)
    SERVER_ELEMENTS = {2: ("q4", "q4_eas"), 3: ("hex8", "h8_eas")}
    MESH_DIM = {"rectangle": 2, "box": 3, "tube": 3, "gmsh": 3}

    def __init__(self, section, dt, interface_damping, log=print, element=None, scene_path=None):
        self.log = log
        s = Section(section, "solid")
        model = s.get("model", "fenics")
        if model not in ("fem", "fenics"):
            raise SceneError(f"'solid.model' must be 'fem' or 'fenics' for this solid, got {model!r}")
        t_setup = _time.perf_counter()
        self.dt = dt
        self.gamma = float(interface_damping)

        # 0. The dimension, from the mesh: rectangle (2D), box, tube or a gmsh file of tetrahedra (3D).
        m = s.child("mesh")
        mtype = m.get("type", "rectangle")
        if mtype not in self.MESH_DIM:
            raise SceneError(f"'solid.mesh.type: {mtype}': this solid builds only 'rectangle' (2D), 'box' and 'tube' "
                             f"(3D) meshes, or reads 'gmsh' (3D tetrahedra)")
        dim = self.dim = self.MESH_DIM[mtype]
        self.facet_sets = TUBE_FACET_SETS if mtype == "tube" else self.FACET_SETS[:2 * dim]
        self.mesh_file = None
        if mtype == "gmsh":  # read first: its face groups are the facet sets, its order the default degree
            self.mesh_file = self._resolve(m.get("file", required=True), scene_path)
            domain = m.get("domain")
            m.check_all_used()
            self._gmsh = gmsh_tetrahedra(self.mesh_file, str(domain) if domain else None)  # '': every group
            self.facet_sets = tuple(sorted(self._gmsh[2]))

        # 1. The discretisation: solid.fenics, else `element` (the server's command line), else
        #    Q1 quadrilaterals (hexahedra in 3D) with 2 x 2 (x 2) Gauss points, solid_server's own
        #    element, so that a scene written for solid_server gives its numbers.
        #    A gmsh file: its tetrahedra, P2 on 10-node (solid_server's Tet10), P1 on 4-node ones.
        element = {k: v for k, v in (element or {}).items() if v is not None}
        fe = s.child("fenics")
        tensor, simplex = self.CELLS[dim]
        cells = (simplex,) if mtype == "gmsh" else self.CELLS[dim]
        default_cell = simplex if mtype == "gmsh" else tensor
        if "cell" not in fe.data and element.get("cell", default_cell) not in cells:
            raise SceneError(f"--cell {element['cell']}: the mesh ('solid.mesh.type: {mtype}') is {dim}D, its cells are "
                             f"{' or '.join(cells)}" + (f" (the file {self.mesh_file})" if self.mesh_file else ""))
        self.cell = fe.choice("cell", element.get("cell", default_cell), cells)
        self.tensor = self.cell == tensor
        self.degree = fe.integer("degree", element.get("degree", self._gmsh[3] if mtype == "gmsh" else 1), minimum=1)
        if self.tensor and self.degree != 1:
            raise SceneError(f"'solid.fenics.degree' must be 1 on {tensor[:-2] + 'a' if dim == 3 else tensor + 's'} (legacy DOLFIN cannot evaluate Q2 "
                             f"at a probe point); use 'cell: {simplex}' for higher degrees")
        diagonal = fe.choice("diagonal", element.get("diagonal", "crossed"),
                             ("crossed", "right", "left", "right/left", "left/right"))
        qdeg = fe.integer("quadrature_degree", element.get("quadrature_degree",
                                                           2 if self.tensor else 2 * self.degree),
                          minimum=1)
        self.diagonal, self.quadrature_degree = diagonal, qdeg
        fe.check_all_used()
        plain, enhanced = self.SERVER_ELEMENTS[dim]
        if mtype == "gmsh":  # solid_server's element on a tetrahedron file: tet10 (its default there)
            plain, enhanced = "tet10", None
        element = s.get("element", plain)
        if mtype == "gmsh" and element == "tet10":
            if self.degree != 2 or self._gmsh[3] != 2:
                log(f"'solid.element: tet10' is solid_server's 10-node tetrahedron; this solid uses P{self.degree} on "
                    f"the {'10' if self._gmsh[3] == 2 else '4'}-node tetrahedra of {self.mesh_file}")
        elif mtype == "gmsh":
            raise SceneError(f"'solid.element: {element}': the mesh {self.mesh_file} has tetrahedra (solid_server: "
                             f"tet10; the FEniCS solid's element is set by 'solid.fenics' (cell, degree))")
        elif element == enhanced and dim == 3:
            # a 3D scene written for solid_server names its EAS element (configs/*_3d.yaml); the
            # run goes on with this solid's element, said in the log (not the same numbers in bending)
            log(f"'solid.element: {element}' is solid_server's enhanced-strain hexahedron; this solid uses its own "
                f"element ({self.cell}, degree {self.degree}; 'solid.fenics'), without enhanced strains")
        elif element != plain:
            raise SceneError(f"'solid.element: {element}' is solid_server's; the FEniCS solid's element is set by "
                             f"'solid.fenics' (cell, degree)")
        linear = s.get("linear_solver", "cholmod")
        if linear not in ("cholmod", "umfpack", "superlu"):
            raise SceneError(f"'solid.linear_solver' must be cholmod, umfpack or superlu, got {linear!r} "
                             f"(this solid always uses SuperLU)")

        # 2. Mesh: the structured rectangle / box / tube of solid_server, with its facet sets as
        #    markers 1, 2, ... in the order of self.facet_sets.
        if mtype == "tube":
            self.mesh, self.markers = self._tube(m)
        elif mtype == "gmsh":
            self.mesh, self.markers = self._gmsh_mesh()
        else:
            self.mesh, self.markers = self._rectangle_or_box(m, dim, diagonal)
        family = "Q" if self.tensor else "CG"
        self.V = df.VectorFunctionSpace(self.mesh, family, self.degree)
        self.n = self.V.dim()
        # comp[k, c]: the dof of component c at node k (node k: the node of V.sub(0)'s k-th dof)
        self.comp = np.stack([np.asarray(self.V.sub(c).dofmap().dofs(), dtype=np.int64) for c in range(dim)], axis=1)
        self.ix, self.iy = self.comp[:, 0], self.comp[:, 1]
        self.iz = self.comp[:, 2] if dim == 3 else None
        coords = self.V.tabulate_dof_coordinates().reshape(-1, dim)
        self.node_xy = coords[self.ix]  # one row per node (x, y (, z)), the node of dofs comp[k]
        if not all(np.allclose(coords[self.comp[:, c]], self.node_xy) for c in range(1, dim)):
            raise RuntimeError("the components' dofs of V are not paired node by node")

        shape = f"gmsh mesh {self.mesh_file}" if self.mesh_file else mtype

        def edge_ids(key, names):
            bad = [x for x in names if x not in self.facet_sets]
            if bad:
                raise SceneError(f"'solid.{key}': unknown {'edge' if dim == 2 else 'face'} set(s) {', '.join(bad)} "
                                 f"(the {shape} has {', '.join(self.facet_sets) or 'no face groups'})")
            inner = [x for x in names if self.mesh_file and x in self._gmsh[4]]
            if inner:
                raise SceneError(f"'solid.{key}': the face group(s) {', '.join(inner)} of {self.mesh_file} lie inside "
                                 f"the solid (faces of two tetrahedra); this solid takes boundary faces only")
            return [self.facet_sets.index(x) + 1 for x in names]

        # 3. Material (3D Lame relations; plane strain in 2D) and density.
        mat = s.child("material")
        law = mat.choice("law", "saint_venant_kirchhoff", ("saint_venant_kirchhoff", "neo_hookean"))
        nu = mat.number("poisson_ratio", required=True)
        if not -1 < nu < 0.5:
            raise SceneError(f"'solid.material.poisson_ratio' must be in (-1, 0.5), got {nu}")
        E_mod, mu = mat.number("youngs_modulus"), mat.number("shear_modulus")
        if (E_mod is None) == (mu is None):
            raise SceneError("'solid.material' needs exactly one of youngs_modulus or shear_modulus")
        if mu is None:
            if not E_mod > 0:
                raise SceneError("'solid.material.youngs_modulus' must be positive")
            mu = E_mod / (2 * (1 + nu))
        elif not mu > 0:
            raise SceneError("'solid.material.shear_modulus' must be positive")
        mat.check_all_used()
        lam = 2 * mu * nu / (1 - 2 * nu)
        self.mu, self.lam, self.law = mu, lam, law
        rho = s.number("density", required=True, positive=True)
        self.rho = rho

        # 4. Analysis, scheme, Newton.
        self.analysis = s.choice("analysis", "dynamic", ("static", "dynamic"))
        self.scheme = "static" if self.analysis == "static" else s.choice("time_scheme", "newmark", SCHEMES)
        if self.analysis == "static":
            s.get("time_scheme")  # read by the dynamic analysis only
        self.load_steps = s.integer("load_steps", 1, minimum=1)
        nw = s.child("newton")
        self.max_iterations = nw.integer("max_iterations", 25, minimum=1)
        self.rtol = nw.number("residual_tolerance", 1e-8, positive=True)
        self.dtol = nw.number("increment_tolerance", 1e-12, minimum=0.0)
        nw.check_all_used()

        # 5. The forms: internal virtual work and its tangent (UFL differentiates), mass, dead loads.
        self.u = df.Function(self.V)
        w, du = df.TestFunction(self.V), df.TrialFunction(self.V)
        dx = df.dx(metadata={"quadrature_degree": qdeg})
        # Material parameters as Constants, not literals: the compiled forms (dijitso's cache)
        # are then shared by every material, density and load.
        lam_c, mu_c, rho_c = df.Constant(lam), df.Constant(mu), df.Constant(rho)
        I = df.Identity(dim)
        H = df.grad(self.u)
        F = I + H
        E = 0.5 * (H + H.T + H.T * H)  # from H, not F^T F - I: full relative accuracy at tiny strains
        if law == "saint_venant_kirchhoff":
            W = 0.5 * lam_c * df.tr(E) ** 2 + mu_c * df.inner(E, E)
        else:  # Bonet & Wood; in plane strain (2D) tr C includes C33 = 1
            J = df.det(F)
            W = 0.5 * mu_c * (df.tr(F.T * F) + (3 - dim) - 3) - mu_c * df.ln(J) + 0.5 * lam_c * df.ln(J) ** 2
        f_int = df.derivative(W * dx, self.u, w)
        # compiled once (df.assemble of a UFL form would hash it again at every call)
        self.f_int_form, self.k_form = df.Form(f_int), df.Form(df.derivative(f_int, self.u, du))
        t0 = _time.perf_counter()
        self.M = self._csr(df.assemble(rho_c * df.inner(du, w) * dx))
        gravity = s.vector("gravity", dim, [0.0] * dim)
        dead = df.assemble(rho_c * df.inner(df.Constant(gravity), w) * dx).get_local()
        ds = df.Measure("ds", domain=self.mesh, subdomain_data=self.markers)
        tractions = s.get("tractions", []) or []
        if not isinstance(tractions, list):
            raise SceneError("'solid.tractions' must be a list of {boundary, traction}")
        for i, t in enumerate(tractions):
            ts = Section(t, f"solid.tractions[{i}]")
            ids = edge_ids(f"tractions[{i}].boundary", ts.names("boundary"))
            tr = ts.vector("traction", dim, required=True)
            ts.check_all_used()
            for j in ids:  # force per reference length (2D) / area (3D), consistent (int N^T t ds)
                dead += df.assemble(df.inner(df.Constant(tr), w) * ds(j)).get_local()
        point_loads = s.get("point_loads", []) or []
        if not isinstance(point_loads, list):
            raise SceneError("'solid.point_loads' must be a list of {point, force}")
        for i, p in enumerate(point_loads):  # at the node nearest to the point, as solid_server
            ps = Section(p, f"solid.point_loads[{i}]")
            k = int(np.argmin(np.sum((self.node_xy - ps.vector("point", dim, required=True)) ** 2, axis=1)))
            force = ps.vector("force", dim, required=True)
            ps.check_all_used()
            for c in range(dim):
                dead[self.comp[k, c]] += force[c]
        self.f_dead = dead

        # 6. Clamps: homogeneous Dirichlet on named facet sets, every component; supports: some
        #    components only (solid_server's `supports: [{boundary, fixed: [x|y|z ...]}]`); by elimination.
        clamp = edge_ids("clamp", s.names("clamp"))
        fixed = set()
        for j in clamp:
            fixed.update(df.DirichletBC(self.V, df.Constant((0.0,) * dim), self.markers, j).get_boundary_values().keys())
        supports = s.get("supports", []) or []
        if not isinstance(supports, list):
            raise SceneError("'solid.supports' must be a list of {boundary, fixed}")
        for i, sup in enumerate(supports):
            ss = Section(sup, f"solid.supports[{i}]")
            ids = edge_ids(f"supports[{i}].boundary", ss.names("boundary"))
            components = ss.names("fixed")
            ss.check_all_used()
            if not components:
                raise SceneError(f"'solid.supports[{i}].fixed' is required: some of {', '.join(self.COMPONENTS[:dim])}")
            for name in components:
                if name not in self.COMPONENTS[:dim]:
                    raise SceneError(f"'solid.supports[{i}].fixed': '{name}' is not a component of a {dim}D mesh "
                                     f"(give some of {', '.join(self.COMPONENTS[:dim])})")
                c = self.COMPONENTS.index(name)
                for j in ids:
                    fixed.update(df.DirichletBC(self.V.sub(c), df.Constant(0.0), self.markers, j)
                                 .get_boundary_values().keys())
        self.fixed = np.array(sorted(fixed), dtype=np.int64)
        mask = np.ones(self.n, dtype=bool)
        mask[self.fixed] = False
        self.free = np.flatnonzero(mask)

        # 7. Interface: every dof node on the named facet sets. 2D: segments join consecutive
        #    nodes of each edge (a P2 edge gives two segments, vertex-midpoint-vertex). 3D: each
        #    facet is a face, counter-clockwise seen from outside (4 nodes on hexahedra; 3 on
        #    tetrahedra, 6 for P2: corners, then the midpoints of edges 0-1, 1-2, 2-0).
        iface = s.names("interface")
        ids = edge_ids("interface", iface)
        if dim == 2:
            self.interface_nodes, self.segments = self._interface(ids)
            self.faces = None
        else:
            self.interface_nodes, self.faces = self._interface_faces(ids)
            self.segments = None
        n_if = len(self.interface_nodes)
        self.if_dofs = self.comp[self.interface_nodes]  # n_if x dim
        self.if_x, self.if_y = self.if_dofs[:, 0], self.if_dofs[:, 1]
        self.interface_xy = self.node_xy[self.interface_nodes]
        # int N^T N over the interface as sent (2D: the segments; 3D: the faces), reference configuration
        self.M_G = self._polyline_mass() if dim == 2 else self._face_mass(ids)
        self.M_fs = self._nodal_to_dofs(self.M_G * self.gamma) if self.gamma > 0 and n_if else None
        if self.gamma > 0 and not n_if:
            raise SceneError("'solid.interface' is required when the coupler asks for interface damping")

        # 8. Probes: displacement at points (weights of the dofs, computed once).
        self.probes = []
        probes = s.get("probes", []) or []
        if not isinstance(probes, list):
            raise SceneError("'solid.probes' must be a list of {name, point}")
        for i, p in enumerate(probes):
            ps = Section(p, f"solid.probes[{i}]")
            name = ps.get("name", required=True)
            point = ps.vector("point", dim, required=True)
            ps.check_all_used()
            weights = self._point_weights(point)
            if weights is None:
                raise SceneError(f"'solid.probes[{i}].point' {point} is not inside the solid mesh")
            self.probes.append((str(name), weights))
        self.output_every = s.integer("output_every", 1, minimum=0)
        s.check_all_used()

        # 9. State: at rest, undeformed; Newmark's consistent a_0 = M^-1 F_dead.
        z = np.zeros(self.n)
        self.d_n, self.v_n, self.a_n, self.f_n = z.copy(), z.copy(), z.copy(), z.copy()
        if self.scheme == "newmark":
            self.a_n = self._solve_free(self.M, self.f_dead)
        self.d_nm1, self.v_nm1 = z.copy(), z.copy()
        self.accepted_steps = 0
        self.d, self.v, self.a, self.f = self.d_n.copy(), self.v_n.copy(), self.a_n.copy(), self.f_n.copy()
        self.newton_iterations = 0
        self.solved = False
        self.timings = {"setup": _time.perf_counter() - t_setup, "assembly": 0.0, "linear_solve": 0.0, "step": 0.0}
        self.K = df.PETScMatrix()
        self.R = df.PETScVector()
        self._u_array = df.as_backend_type(self.u.vector()).vec().array

    # -- meshes -------------------------------------------------------------------------------
    def _rectangle_or_box(self, m, dim, diagonal):
        """solid_server's structured rectangle / box ('elements' / 'divisions': cells per
        direction); facet sets left, right, bottom, top (, back, front)."""
        origin = m.vector("origin", dim, required=True)
        size = m.vector("size", dim, required=True)
        if not all(x > 0 for x in size):
            raise SceneError("'solid.mesh.size' must be positive")
        cells_key = "elements" if dim == 2 else "divisions"
        ne = m.get(cells_key, required=True)
        if not (isinstance(ne, list) and len(ne) == dim
                and all(isinstance(n, int) and not isinstance(n, bool) and n >= 1 for n in ne)):
            raise SceneError(f"'solid.mesh.{cells_key}' must be [{', '.join('nx ny nz'.split()[:dim])}] (positive "
                             f"integers), got {ne!r}")
        m.check_all_used()
        p0, p1 = df.Point(*origin), df.Point(*(o + l for o, l in zip(origin, size)))
        if dim == 2 and self.tensor:
            mesh = df.RectangleMesh.create([p0, p1], ne, df.CellType.Type.quadrilateral)
        elif dim == 2:
            mesh = df.RectangleMesh(p0, p1, ne[0], ne[1], diagonal)
        elif self.tensor:
            mesh = df.BoxMesh.create([p0, p1], ne, df.CellType.Type.hexahedron)
        else:  # each hexahedron cut into 6 tetrahedra
            mesh = df.BoxMesh(p0, p1, ne[0], ne[1], ne[2])
        # markers 1..2 dim = left, right, bottom, top (, back, front)
        h = 1e-9 * max(size)
        markers = df.MeshFunction("size_t", mesh, dim - 1, 0)
        for i, name in enumerate(self.facet_sets):
            axis, value = i // 2, origin[i // 2] + (size[i // 2] if i % 2 else 0.0)
            df.CompiledSubDomain(f"near(x[{axis}], {value!r}, {h!r}) && on_boundary").mark(markers, i + 1)
        return mesh, markers

    def _tube(self, m):
        """solid_server's tube (mesh.cpp, tube_mesh): a straight tube along z, 'divisions':
        [n_theta around, n_r through the wall, n_z along]; the same nodes and hexahedra (or each
        hexahedron cut into 6 tetrahedra about its diagonal); facet sets inner, outer, start, end."""
        origin = m.vector("origin", 3, required=True)
        ri = m.number("inner_radius", required=True, positive=True)
        ro = m.number("outer_radius", required=True, positive=True)
        length = m.number("length", required=True, positive=True)
        if not ro > ri:
            raise SceneError(f"'solid.mesh.outer_radius' ({ro}) must be larger than 'inner_radius' ({ri})")
        ne = m.get("divisions", required=True)
        if not (isinstance(ne, list) and len(ne) == 3 and all(isinstance(n, int) and not isinstance(n, bool) for n in ne)
                and ne[0] >= 3 and ne[1] >= 1 and ne[2] >= 1):
            raise SceneError(f"'solid.mesh.divisions' must be [n_theta >= 3, n_r >= 1, n_z >= 1] (integers), got {ne!r}")
        m.check_all_used()
        nodes, cells, ijk = tube_mesh(origin, ri, ro, length, *ne)
        if not self.tensor:  # Kuhn's split, about the diagonal 0-7: conforming across the faces
            cells = cells[:, [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7],
                              [0, 4, 6, 7]]].reshape(-1, 4)
        mesh = df.Mesh()
        editor = df.MeshEditor()
        editor.open(mesh, self.cell, 3, 3)
        editor.init_vertices(len(nodes))
        editor.init_cells(len(cells))
        for v, x in enumerate(nodes):
            editor.add_vertex(v, x)
        for c, verts in enumerate(cells):
            editor.add_cell(c, verts.astype(np.uintp))
        editor.close(not self.tensor)  # DOLFIN cannot reorder hexahedra (they are in its order already)
        # a boundary facet belongs to the set whose nodes carry all its vertices
        n_theta, n_r, n_z = ne
        mesh.init(2, 3)
        markers = df.MeshFunction("size_t", mesh, 2, 0)
        tests = ((0, 0), (0, n_r), (2, 0), (2, n_z))  # inner, outer, start, end: (index, value) of (i, j, k)
        arr = markers.array()
        for f in df.facets(mesh):
            if f.num_entities(3) != 1:
                continue
            v = ijk[f.entities(0)]
            for s_id, (axis, value) in enumerate(tests):
                if np.all(v[:, axis] == value):
                    arr[f.index()] = s_id + 1
                    break
        return mesh, markers

    @staticmethod
    def _resolve(given, scene_path):
        """A mesh file as solid_server finds it: absolute; else relative to the scene file's
        folder, to the working directory, or to configs/ (the first that exists)."""
        given = str(given)
        if os.path.isabs(given):
            if not os.path.exists(given):
                raise SceneError(f"'solid.mesh.file': file '{given}' does not exist")
            return given
        scene_dir = os.path.dirname(scene_path) if scene_path and scene_path != "<scene>" else ""
        candidates = [os.path.join(scene_dir or ".", given), given, os.path.join("configs", given)]
        for c in candidates:
            if os.path.exists(c):
                return os.path.abspath(c)
        raise SceneError(f"'solid.mesh.file': file '{given}' not found (tried {', '.join(candidates)})")

    def _gmsh_mesh(self):
        """The DOLFIN mesh of the gmsh file's tetrahedra (vertices only: straight cells) and its
        face groups as markers 1, 2, ... in the order of self.facet_sets."""
        X, cells, groups, order, _ = self._gmsh
        mesh = df.Mesh()
        editor = df.MeshEditor()
        editor.open(mesh, "tetrahedron", 3, 3)
        editor.init_vertices(len(X))
        editor.init_cells(len(cells))
        for v, x in enumerate(X):
            editor.add_vertex(v, x)
        for c, verts in enumerate(cells):
            editor.add_cell(c, verts.astype(np.uintp))
        editor.close(True)
        mesh.init(2)
        facet_of = {tuple(sorted(v)): f for f, v in
                    enumerate(np.array(mesh.topology()(2, 0)(), dtype=np.int64).reshape(-1, 3).tolist())}
        markers = df.MeshFunction("size_t", mesh, 2, 0)
        arr = markers.array()
        for i, name in enumerate(self.facet_sets):
            for tri in groups[name][0].tolist():
                arr[facet_of[tuple(sorted(tri))]] = i + 1
        return mesh, markers

    # -- helpers ----------------------------------------------------------------------------
    @staticmethod
    def _csr(matrix):
        indptr, indices, data = df.as_backend_type(matrix).mat().getValuesCSR()
        return sp.csr_matrix((data, indices, indptr), shape=(matrix.size(0), matrix.size(1)))

    def _solve_free(self, A, b):
        x = np.zeros(self.n)
        if self.free.size:
            Aff = A[self.free][:, self.free].tocsc()
            x[self.free] = spla.spsolve(Aff, b[self.free])
        return x

    def _interface(self, ids):
        """(interface nodes as indices into node_xy, segments as pairs of local indices)."""
        node_of_xdof = {int(d): k for k, d in enumerate(self.ix)}
        dm = self.V.sub(0).dofmap()
        nodes, local, segments = [], {}, []
        facets = [f for f in range(self.mesh.num_facets()) if self.markers[f] in ids]
        for f in facets:
            ks = [node_of_xdof[int(d)] for d in dm.entity_closure_dofs(self.mesh, 1, [f])]
            xy = self.node_xy[ks]
            e = xy.max(axis=0) - xy.min(axis=0)
            axis = int(np.argmax(e))
            ks = [k for _, k in sorted(zip(xy[:, axis], ks))]  # along the (straight) facet
            for k in ks:
                if k not in local:
                    local[k] = len(nodes)
                    nodes.append(k)
            segments += [(local[a], local[b]) for a, b in zip(ks[:-1], ks[1:])]
        return np.array(nodes, dtype=np.int64), np.array(segments, dtype=np.int64).reshape(-1, 2)

    def _interface_faces(self, ids):
        """3D: (interface nodes as indices into node_xy, faces as lists of local indices), each
        face counter-clockwise seen from outside (the normal by the right-hand rule points out
        of the solid); a P2 triangle in gmsh order: corners, then the midpoints of 0-1, 1-2, 2-0."""
        node_of_xdof = {int(d): k for k, d in enumerate(self.ix)}
        dm = self.V.sub(0).dofmap()
        X = self.mesh.coordinates()
        self.mesh.init(2, 3)
        nodes, local, faces = [], {}, []
        for f in range(self.mesh.num_facets()):
            if self.markers[f] not in ids:
                continue
            facet = df.Facet(self.mesh, f)
            ks = [node_of_xdof[int(d)] for d in dm.entity_closure_dofs(self.mesh, 2, [f])]
            xyz = self.node_xy[ks]
            corners_xyz = X[facet.entities(0)]
            # the corners among the facet's nodes (the vertices), the others are mid-edge nodes (P2)
            corners = [ks[int(np.argmin(np.sum((xyz - p) ** 2, axis=1)))] for p in corners_xyz]
            centre = corners_xyz.mean(axis=0)
            cell = df.Cell(self.mesh, int(facet.entities(3)[0]))
            outward = centre - X[cell.entities(0)].mean(axis=0)
            # order the corners by angle about the outward normal (convex, planar facets)
            e1 = corners_xyz[0] - centre
            e2 = np.cross(outward, e1)
            rel = self.node_xy[corners] - centre
            angle = np.arctan2(rel @ e2, rel @ e1)
            corners = [corners[i] for i in np.argsort(angle, kind="stable")]
            face = list(corners)
            if len(ks) > len(corners):  # P2 triangle: the node at the middle of each edge
                if len(corners) != 3 or len(ks) != 6:
                    raise RuntimeError(f"a facet with {len(ks)} nodes: only P1/P2 triangles and Q1 quadrilaterals")
                for a, b in ((0, 1), (1, 2), (2, 0)):
                    mid = 0.5 * (self.node_xy[corners[a]] + self.node_xy[corners[b]])
                    face.append(ks[int(np.argmin(np.sum((xyz - mid) ** 2, axis=1)))])
            for k in face:
                if k not in local:
                    local[k] = len(nodes)
                    nodes.append(k)
            faces.append([local[k] for k in face])
        return np.array(nodes, dtype=np.int64), faces

    def _face_mass(self, ids):
        """3D: the consistent mass of the interface faces, int N^T N dA (reference configuration),
        assembled by DOLFIN on the interface facets, as a scalar matrix on interface nodes."""
        n_if = len(self.interface_nodes)
        if not n_if:
            return sp.csr_matrix((0, 0))
        w, du = df.TestFunction(self.V), df.TrialFunction(self.V)
        ds = df.Measure("ds", domain=self.mesh, subdomain_data=self.markers,
                        metadata={"quadrature_degree": 2 * self.degree})
        M = self._csr(df.assemble(sum(df.inner(du, w) * ds(j) for j in ids)))
        return M[self.if_x][:, self.if_x].tocsr()  # the x block: the same for every component

    def _polyline_mass(self):
        n = len(self.interface_nodes)
        rows, cols, vals = [], [], []
        for a, b in self.segments:
            L = float(np.linalg.norm(self.interface_xy[b] - self.interface_xy[a]))
            rows += [a, b, a, b]
            cols += [a, b, b, a]
            vals += [L / 3, L / 3, L / 6, L / 6]
        return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))

    def _nodal_to_dofs(self, nodal):
        """A scalar matrix on interface nodes -> the n x n matrix acting on every component alike."""
        c = sp.coo_matrix(nodal)
        rows = np.concatenate([self.if_dofs[c.row, k] for k in range(self.dim)])
        cols = np.concatenate([self.if_dofs[c.col, k] for k in range(self.dim)])
        return sp.csr_matrix((np.concatenate([c.data] * self.dim), (rows, cols)), shape=(self.n, self.n))

    def set_interface_mass(self, rows, cols, values):
        """Algorithm 2: M_fs = gamma_N1 * M_G with the coupler's M_G (interface nodes)."""
        if not self.gamma > 0:
            return
        n_if = len(self.interface_nodes)
        M_G = sp.coo_matrix((np.asarray(values, dtype=float), (rows, cols)), shape=(n_if, n_if)).tocsr()
        if not getattr(self, "_mass_compared", False):  # once: the coupler's M_G against this solid's
            self._mass_compared = True
            scale = abs(self.M_G).max() if self.M_G.nnz else 0.0
            diff = abs(M_G - self.M_G).max() if n_if else 0.0
            self.log(f"the coupler's interface mass M_G (sum {M_G.sum():.6g}) against this solid's own "
                     f"(sum {self.M_G.sum():.6g}): max |difference| {diff / scale if scale else diff:.1e} of its "
                     f"largest entry (the same matrix only when the fluid's interface nodes are these)")
        self.M_fs = self._nodal_to_dofs(sp.coo_matrix((np.asarray(values) * self.gamma, (rows, cols)),
                                                      shape=(n_if, n_if)))

    def _point_weights(self, point):
        """Per component c, [(dof, weight)] with u_c(point) = sum weight * u[dof], or None if outside."""
        x = np.array(point, dtype=float)
        dim = self.dim
        dm = self.V.dofmap()
        if not self.tensor:
            tree = self.mesh.bounding_box_tree()
            c = tree.compute_first_entity_collision(df.Point(*x))
            if c >= self.mesh.num_cells():
                return None
            cell = df.Cell(self.mesh, c)
            basis = self.V.element().evaluate_basis_all(x, cell.get_vertex_coordinates(), 0)
            basis = basis.reshape(-1, dim)  # per cell dof: (value x, value y (, value z))
            dofs = dm.cell_dofs(c)
            return tuple([(int(d), float(b[k])) for d, b in zip(dofs, basis) if b[k] != 0] for k in range(dim))
        # Q1: invert the multilinear map of each cell (DOLFIN's vertex order is the tensor
        # product: vertex a sits at xi_k = bit k of a, i.e. (0,0), (1,0), (0,1), (1,1) in 2D,
        # then the same at xi_2 = 1 in 3D; bilinear legacy DOLFIN cannot do this, nor a bounding
        # box collision on non-simplex cells)
        v2d = df.vertex_to_dof_map(self.V).reshape(-1, dim)
        bits = np.array([[(a >> k) & 1 for k in range(dim)] for a in range(2 ** dim)])

        def shape(xi):
            f = np.where(bits == 1, xi, 1 - xi)  # per vertex and direction: xi_k or 1 - xi_k
            N = np.ones(2 ** dim)
            dN = np.ones((2 ** dim, dim))
            for k in range(dim):
                N = N * f[:, k]
                for j in range(dim):
                    dN[:, j] = dN[:, j] * (f[:, k] if k != j else 2 * bits[:, k] - 1)
            return N, dN

        best = None
        for c in range(self.mesh.num_cells()):
            verts = self.mesh.cells()[c]
            X = self.mesh.coordinates()[verts]
            lo, hi = X.min(axis=0), X.max(axis=0)
            if np.any(x < lo - 1e-9 * (hi - lo).max()) or np.any(x > hi + 1e-9 * (hi - lo).max()):
                continue
            xi = np.full(dim, 0.5)
            for _ in range(20):
                N, dN = shape(xi)
                r = N @ X - x
                Jm = X.T @ dN
                step = np.linalg.solve(Jm, r)
                xi -= step
                if np.abs(step).max() < 1e-14:
                    break
            outside = np.abs(xi - 0.5).max()
            if best is None or outside < best[0]:
                best = (outside, verts, xi.copy())
        if best is None or best[0] > 0.5 + 1e-9:
            return None
        _, verts, xi = best
        N, _ = shape(xi)
        return tuple([(int(v2d[v, k]), float(w)) for v, w in zip(verts, N)] for k in range(dim))

    def probe_values(self, d):
        out = {}
        for name, weights in self.probes:
            for k, wk in enumerate(weights):
                out[f"{name}_{self.COMPONENTS[k]}"] = float(sum(w * d[i] for i, w in wk))
        return out

    # -- Newton ------------------------------------------------------------------------------
    def _assemble(self, d, f, cm, a_hist, cv, v_hist):
        """Residual R(d) and tangent J(d) on the free dofs:
        R = F_int(d) + M (cm d + a_hist) + M_fs (cv d + v_hist) - f,  J = K(d) + cm M + cv M_fs."""
        t0 = _time.perf_counter()
        self._u_array[:] = d  # the PETSc vector's own array (serial): no assembly of the vector
        df.assemble(self.f_int_form, tensor=self.R)
        df.assemble(self.k_form, tensor=self.K)
        self.timings["assembly"] += _time.perf_counter() - t0
        r = self.R.get_local() - f
        J = self._csr(self.K)
        if cm:
            r += self.M @ (cm * d + a_hist)
            J = J + cm * self.M
        if cv and self.M_fs is not None:
            r += self.M_fs @ (cv * d + v_hist)
            J = J + cv * self.M_fs
        return r[self.free], J

    def newton(self, d, f, cm=0.0, a_hist=None, cv=0.0, v_hist=None):
        """Full Newton from d (changed in place): converged when |R| <= rtol max(|R_0|, |F|) on
        the free dofs, or |du| <= dtol |d| and |R| <= sqrt(rtol) max(|R_0|, |F|)."""
        f_norm = float(np.linalg.norm(f[self.free]))
        r0 = None
        for it in range(self.max_iterations + 1):
            r, J = self._assemble(d, f, cm, a_hist, cv, v_hist)
            res = float(np.linalg.norm(r))
            if r0 is None:
                r0 = res
            ref = max(r0, f_norm)
            if not (math.isfinite(res) and math.isfinite(ref)):
                raise NewtonFailed(f"the residual is not finite (Newton iteration {it})")
            if res <= self.rtol * ref or res == 0:
                return it, res
            if it == self.max_iterations:
                break
            t0 = _time.perf_counter()
            Jff = J[self.free][:, self.free].tocsc()
            try:
                dd = spla.spsolve(Jff, -r, permc_spec="COLAMD")  # MMD_AT_PLUS_A: 100 x slower on Q1 320 x 16
            except RuntimeError as e:  # singular
                raise NewtonFailed(f"the tangent is singular ({e})") from None
            finally:
                self.timings["linear_solve"] += _time.perf_counter() - t0
            if not np.all(np.isfinite(dd)):
                raise NewtonFailed(f"the Newton increment is not finite (iteration {it + 1})")
            d[self.free] += dd
            self.newton_iterations += 1
            if np.linalg.norm(dd) <= self.dtol * np.linalg.norm(d[self.free]):
                r, _ = self._assemble(d, f, cm, a_hist, cv, v_hist)
                res = float(np.linalg.norm(r))
                if math.isfinite(res) and res <= math.sqrt(self.rtol) * ref:
                    return it + 1, res
                break
        raise NewtonFailed(f"Newton did not converge in {self.max_iterations} iterations (|R| {res:.3e}, "
                           f"initial {r0:.3e})")

    # -- one step, from the last accepted state -------------------------------------------------
    def solve(self, dt, interface_force):
        """Solve the step for this interface force (dim per interface node, interleaved), from
        the accepted state. Returns the interface displacement and velocity (interleaved)."""
        t0 = _time.perf_counter()
        try:
            return self._solve(dt, interface_force)
        finally:
            self.timings["step"] += _time.perf_counter() - t0

    def _solve(self, dt, interface_force):
        f = self.f_dead.copy()
        for c in range(self.dim):
            f[self.if_dofs[:, c]] += interface_force[c::self.dim]
        self.f = f
        self.newton_iterations = 0
        d_n, v_n, a_n = self.d_n, self.v_n, self.a_n
        d = d_n.copy()
        if self.scheme == "static":
            for k in range(1, self.load_steps + 1):
                self.newton(d, self.f_n + (k / self.load_steps) * (f - self.f_n))
            v = np.zeros(self.n)
            a = np.zeros(self.n)
        elif self.scheme == "bdf2" and self.accepted_steps >= 1:
            cv = 1.5 / dt
            v_hist = (-4.0 * d_n + self.d_nm1) / (2.0 * dt)
            cm = 1.5 / dt * cv
            a_hist = 1.5 / dt * v_hist - (4.0 * v_n - self.v_nm1) / (2.0 * dt)
            d += dt * v_n
            self.newton(d, f, cm, a_hist, cv, v_hist)
            v, a = cv * d + v_hist, cm * d + a_hist
        elif self.scheme in ("bdf1", "bdf2"):
            cm, a_hist = 1.0 / dt ** 2, -d_n / dt ** 2 - v_n / dt
            cv, v_hist = 1.0 / dt, -d_n / dt
            d += dt * v_n
            self.newton(d, f, cm, a_hist, cv, v_hist)
            v = (d - d_n) / dt
            a = (v - v_n) / dt
        else:  # newmark, beta = 1/4, gamma = 1/2
            beta, gam = 0.25, 0.5
            cm = 1.0 / (beta * dt * dt)
            a_hist = -(d_n + dt * v_n) / (beta * dt * dt) - (0.5 / beta - 1.0) * a_n
            cv = gam * dt * cm
            v_hist = v_n + dt * (1 - gam) * a_n + gam * dt * a_hist
            d += dt * v_n
            self.newton(d, f, cm, a_hist, cv, v_hist)
            a, v = cm * d + a_hist, cv * d + v_hist
        self.d, self.v, self.a = d, v, a
        self.solved = True
        return self.interface_values(d), self.interface_values(v)

    def interface_values(self, x):
        out = np.empty(self.dim * len(self.interface_nodes))
        for c in range(self.dim):
            out[c::self.dim] = x[self.if_dofs[:, c]]
        return out

    def accept(self):
        self.d_nm1, self.v_nm1 = self.d_n, self.v_n
        self.d_n, self.v_n, self.a_n, self.f_n = self.d, self.v, self.a, self.f
        self.accepted_steps += 1
        self.solved = False
        return self.probe_values(self.d_n)

    # -- checkpoints: our own format (numpy .npz), with a fingerprint of the discretisation ------
    def fingerprint(self):
        return f"{self.cell} P{self.degree} {self.n} dofs {self.scheme}"

    def save(self):
        buf = io.BytesIO()
        np.savez(buf, tag=np.array(STATE_TAG), fingerprint=np.array(self.fingerprint()),
                 accepted_steps=np.array(self.accepted_steps), d_n=self.d_n, v_n=self.v_n, a_n=self.a_n,
                 f_n=self.f_n, d_nm1=self.d_nm1, v_nm1=self.v_nm1)
        return buf.getvalue()

    def load(self, state):
        try:
            z = np.load(io.BytesIO(state), allow_pickle=False)
            tag, fp = str(z["tag"]), str(z["fingerprint"])
        except Exception as e:  # noqa: BLE001 - any unreadable state
            raise ValueError(f"{len(state)} bytes that are not a checkpoint of this solid ({type(e).__name__})") from None
        if tag != STATE_TAG:
            raise ValueError(f"checkpoint format '{tag}', this solid reads '{STATE_TAG}'")
        if fp != self.fingerprint():
            raise ValueError(f"checkpoint of '{fp}', this configuration is '{self.fingerprint()}'")
        self.accepted_steps = int(z["accepted_steps"])
        for k in ("d_n", "v_n", "a_n", "f_n", "d_nm1", "v_nm1"):
            setattr(self, k, np.array(z[k], dtype=float))
        self.d, self.v, self.a, self.f = self.d_n.copy(), self.v_n.copy(), self.a_n.copy(), self.f_n.copy()
        self.solved = False

    def write_vtk(self, folder, time):
        if not hasattr(self, "_file"):
            self._file = df.File(os.path.join(folder, "fenics_solid.pvd"))
            self._out = df.Function(self.V, name="displacement")
        self._out.vector().set_local(self.d_n)
        self._out.vector().apply("insert")
        self._file << (self._out, float(time))
        return os.path.join(folder, "fenics_solid.pvd")
