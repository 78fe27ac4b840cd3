"""The finite-element part of the FEniCS solid: legacy DOLFIN (Debian's python3-dolfin), no
protocol here (fenics_solid.py serves it through fsi.server).

A 2D plane-strain, total Lagrangian hyperelastic solid (St. Venant-Kirchhoff or compressible
neo-Hookean), Lagrange elements on triangles (P1, P2, ...) or quadrilaterals (Q1), full Newton
with the consistent tangent that UFL derives, and the time schemes of solid_server:

    M a_{n+1} + M_fs v_{n+1} + F_int(d_{n+1}) = F_dead + F_interface

    static    F_int(d) = F, the load taken from the last accepted one in `load_steps` increments
    newmark   trapezoidal rule (beta = 1/4, gamma = 1/2), a_0 = M^-1 F_dead
    bdf2      v = (3 d - 4 d_n + d_{n-1}) / (2 dt), a alike; the first step is bdf1
    bdf1      v = (d - d_n) / dt, a = (v - v_n) / dt

DOLFIN assembles the internal force F_int(d) and its tangent K(d) (the forms below), the mass
matrix M and the dead loads (gravity, edge tractions) once; everything nodal (the coupler's
interface force, the interface damping M_fs = gamma_N1 M_G, the time-scheme terms) is added to
the assembled arrays with scipy, and the Newton systems are solved on the free dofs with
SuperLU. Units: SI (m, kg, s, N, Pa), unit thickness.
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


class SceneError(ValueError):
    """A bad key in the solid section (the server answers INVALID_ARGUMENT naming it)."""


class NewtonFailed(RuntimeError):
    """Newton did not converge, or the state is not finite (SOLVER_FAILED: the run diverged)."""


# -- reading the section -----------------------------------------------------------------------
def _as_number(v):
    """A YAML number; PyYAML (YAML 1.1) reads 0.5e6 or 1e-8 as a string where yaml-cpp reads a
    number, so a string that is a plain decimal number counts as one."""
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return v
    return v


class Section:
    """A dict with the path of its keys for messages, and a record of the keys read."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise SceneError(f"'{where}' must be a mapping, got {data!r}")
        self.data, self.where, self.used = data, where, set()

    def key(self, name):
        return f"{self.where}.{name}"

    def get(self, name, default=None, required=False):
        self.used.add(name)
        if name not in self.data or self.data[name] is None:
            if required:
                raise SceneError(f"'{self.key(name)}' is required but missing")
            return default
        return self.data[name]

    def number(self, name, default=None, required=False, positive=False, minimum=None):
        v = self.get(name, default, required)
        if v is None:
            return None
        v = _as_number(v)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SceneError(f"'{self.key(name)}' must be a finite number, got {v!r}")
        if positive and not v > 0:
            raise SceneError(f"'{self.key(name)}' must be positive, got {v!r}")
        if minimum is not None and v < minimum:
            raise SceneError(f"'{self.key(name)}' must be >= {minimum}, got {v!r}")
        return float(v)

    def integer(self, name, default=None, minimum=None):
        v = self.get(name, default)
        if isinstance(v, bool) or not isinstance(v, int) or (minimum is not None and v < minimum):
            raise SceneError(f"'{self.key(name)}' must be an integer" + (f" >= {minimum}" if minimum is not None else "")
                             + f", got {v!r}")
        return v

    def vector2(self, name, default=None, required=False):
        v = self.get(name, default, required)
        if isinstance(v, (list, tuple)):
            v = [_as_number(x) for x in v]
        if (not isinstance(v, (list, tuple)) or len(v) != 2
                or any(isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) for x in v)):
            raise SceneError(f"'{self.key(name)}' must be [x, y] (two finite numbers), got {v!r}")
        return [float(v[0]), float(v[1])]

    def choice(self, name, default, allowed):
        v = self.get(name, default)
        if v not in allowed:
            raise SceneError(f"'{self.key(name)}' must be one of {', '.join(map(str, allowed))}, got {v!r}")
        return v

    def names(self, name):
        v = self.get(name, [])
        v = [v] if isinstance(v, str) else v
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise SceneError(f"'{self.key(name)}' must be an edge set name or a list of names, got {v!r}")
        return v

    def child(self, name):
        v = self.get(name, {})
        return Section(v or {}, self.key(name))

    def check_all_used(self, ignored=()):
        unknown = sorted(set(self.data) - self.used - set(ignored))
        if unknown:
            raise SceneError(f"unknown key(s) in '{self.where}': {', '.join(unknown)}")


# -- the model ----------------------------------------------------------------------------------
class FlagSolid:
    """The solid of one run: mesh, function space, forms, state (d, v, a of the last accepted
    step and of the current solve) and the interface. All vectors are numpy arrays over the
    DOLFIN dofs of V (2 components interleaved by DOLFIN's dof map, not necessarily x0 y0 x1
    y1: use `ix`/`iy` to pick components)."""

    EDGE_SETS = ("left", "right", "bottom", "top")

    def __init__(self, section, dt, interface_damping, log=print, element=None):
        self.log = log
        s = Section(section, "solid")
        model = s.get("model", "fenics")
        if model not in ("fem", "fenics"):
            raise SceneError(f"'solid.model' must be 'fem' or 'fenics' for this solid, got {model!r}")
        t_setup = _time.perf_counter()
        self.dt = dt
        self.gamma = float(interface_damping)

        # 1. The discretisation: solid.fenics, else `element` (the server's command line), else
        #    Q1 quadrilaterals with 2 x 2 Gauss points, solid_server's own element, so that a
        #    scene written for solid_server gives its numbers.
        element = {k: v for k, v in (element or {}).items() if v is not None}
        fe = s.child("fenics")
        self.cell = fe.choice("cell", element.get("cell", "quadrilateral"), ("quadrilateral", "triangle"))
        self.degree = fe.integer("degree", element.get("degree", 1), minimum=1)
        if self.cell == "quadrilateral" and self.degree != 1:
            raise SceneError("'solid.fenics.degree' must be 1 on quadrilaterals (legacy DOLFIN cannot evaluate Q2 "
                             "at a probe point); use 'cell: triangle' for higher degrees")
        diagonal = fe.choice("diagonal", element.get("diagonal", "crossed"),
                             ("crossed", "right", "left", "right/left", "left/right"))
        qdeg = fe.integer("quadrature_degree", element.get("quadrature_degree",
                                                           2 if self.cell == "quadrilateral" else 2 * self.degree),
                          minimum=1)
        self.diagonal, self.quadrature_degree = diagonal, qdeg
        fe.check_all_used()
        element = s.get("element", "q4")
        if element != "q4":
            raise SceneError(f"'solid.element: {element}' is solid_server's; the FEniCS solid's element is set by "
                             f"'solid.fenics' (cell, degree)")
        linear = s.get("linear_solver", "cholmod")
        if linear not in ("cholmod", "umfpack", "superlu"):
            raise SceneError(f"'solid.linear_solver' must be cholmod, umfpack or superlu, got {linear!r} "
                             f"(this solid always uses SuperLU)")

        # 2. Mesh: the structured rectangle of solid_server ('elements': cells per direction).
        m = s.child("mesh")
        mtype = m.get("type", "rectangle")
        if mtype != "rectangle":
            raise SceneError(f"'solid.mesh.type: {mtype}': this solid builds only 'rectangle' meshes")
        x0, y0 = m.vector2("origin", required=True)
        lx, ly = m.vector2("size", required=True)
        if not (lx > 0 and ly > 0):
            raise SceneError("'solid.mesh.size' must be positive")
        ne = m.get("elements", required=True)
        if not (isinstance(ne, list) and len(ne) == 2 and all(isinstance(n, int) and not isinstance(n, bool) and n >= 1
                                                               for n in ne)):
            raise SceneError(f"'solid.mesh.elements' must be [nx, ny] (positive integers), got {ne!r}")
        m.check_all_used()
        self.box = (x0, y0, x0 + lx, y0 + ly)
        p0, p1 = df.Point(x0, y0), df.Point(x0 + lx, y0 + ly)
        if self.cell == "quadrilateral":
            self.mesh = df.RectangleMesh.create([p0, p1], ne, df.CellType.Type.quadrilateral)
            family = "Q"
        else:
            self.mesh = df.RectangleMesh(p0, p1, ne[0], ne[1], diagonal)
            family = "CG"
        self.V = df.VectorFunctionSpace(self.mesh, family, self.degree)
        self.n = self.V.dim()
        self.ix = np.asarray(self.V.sub(0).dofmap().dofs(), dtype=np.int64)
        self.iy = np.asarray(self.V.sub(1).dofmap().dofs(), dtype=np.int64)
        coords = self.V.tabulate_dof_coordinates().reshape(-1, 2)
        self.node_xy = coords[self.ix]  # one row per node, the node of dofs ix[k], iy[k]
        if not np.allclose(coords[self.iy], self.node_xy):
            raise RuntimeError("the x and y dofs of V are not paired node by node")

        # Edge sets of the rectangle: facet markers 1..4 = left, right, bottom, top.
        h = 1e-9 * max(lx, ly)
        self.markers = df.MeshFunction("size_t", self.mesh, 1, 0)
        for i, where in enumerate((f"near(x[0], {x0!r}, {h!r})", f"near(x[0], {x0 + lx!r}, {h!r})",
                                   f"near(x[1], {y0!r}, {h!r})", f"near(x[1], {y0 + ly!r}, {h!r})")):
            df.CompiledSubDomain(where + " && on_boundary").mark(self.markers, i + 1)

        def edge_ids(key, names):
            bad = [x for x in names if x not in self.EDGE_SETS]
            if bad:
                raise SceneError(f"'solid.{key}': unknown edge set(s) {', '.join(bad)} (the rectangle has "
                                 f"{', '.join(self.EDGE_SETS)})")
            return [self.EDGE_SETS.index(x) + 1 for x in names]

        # 3. Material (plane strain, 3D Lame relations) and density.
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
        I = df.Identity(2)
        H = df.grad(self.u)
        F = I + H
        E = 0.5 * (H + H.T + H.T * H)  # from H, not F^T F - I: full relative accuracy at tiny strains
        if law == "saint_venant_kirchhoff":
            W = 0.5 * lam_c * df.tr(E) ** 2 + mu_c * df.inner(E, E)
        else:  # Bonet & Wood, plane strain: tr C includes C33 = 1
            J = df.det(F)
            W = 0.5 * mu_c * (df.tr(F.T * F) + 1 - 3) - mu_c * df.ln(J) + 0.5 * lam_c * df.ln(J) ** 2
        f_int = df.derivative(W * dx, self.u, w)
        # compiled once (df.assemble of a UFL form would hash it again at every call)
        self.f_int_form, self.k_form = df.Form(f_int), df.Form(df.derivative(f_int, self.u, du))
        t0 = _time.perf_counter()
        self.M = self._csr(df.assemble(rho_c * df.inner(du, w) * dx))
        gravity = s.vector2("gravity", [0.0, 0.0])
        dead = df.assemble(rho_c * df.inner(df.Constant(gravity), w) * dx).get_local()
        ds = df.Measure("ds", domain=self.mesh, subdomain_data=self.markers)
        tractions = s.get("tractions", []) or []
        if not isinstance(tractions, list):
            raise SceneError("'solid.tractions' must be a list of {boundary, traction}")
        for i, t in enumerate(tractions):
            ts = Section(t, f"solid.tractions[{i}]")
            ids = edge_ids(f"tractions[{i}].boundary", ts.names("boundary"))
            tr = ts.vector2("traction", required=True)
            ts.check_all_used()
            for j in ids:  # force per reference length, consistent (int N^T t ds)
                dead += df.assemble(df.inner(df.Constant(tr), w) * ds(j)).get_local()
        point_loads = s.get("point_loads", []) or []
        if not isinstance(point_loads, list):
            raise SceneError("'solid.point_loads' must be a list of {point, force}")
        for i, p in enumerate(point_loads):  # at the node nearest to the point, as solid_server
            ps = Section(p, f"solid.point_loads[{i}]")
            k = int(np.argmin(np.sum((self.node_xy - ps.vector2("point", required=True)) ** 2, axis=1)))
            fx, fy = ps.vector2("force", required=True)
            ps.check_all_used()
            dead[self.ix[k]] += fx
            dead[self.iy[k]] += fy
        self.f_dead = dead

        # 6. Clamps: homogeneous Dirichlet on named edges, both components, by elimination.
        clamp = edge_ids("clamp", s.names("clamp"))
        fixed = set()
        for j in clamp:
            fixed.update(df.DirichletBC(self.V, df.Constant((0.0, 0.0)), self.markers, j).get_boundary_values().keys())
        self.fixed = np.array(sorted(fixed), dtype=np.int64)
        mask = np.ones(self.n, dtype=bool)
        mask[self.fixed] = False
        self.free = np.flatnonzero(mask)

        # 7. Interface: every dof node on the named edges; segments join consecutive nodes of
        #    each facet (a P2 edge gives two segments, vertex-midpoint-vertex).
        iface = s.names("interface")
        self.interface_nodes, self.segments = self._interface(edge_ids("interface", iface))
        n_if = len(self.interface_nodes)
        self.if_x, self.if_y = self.ix[self.interface_nodes], self.iy[self.interface_nodes]
        self.interface_xy = self.node_xy[self.interface_nodes]
        self.M_G = self._polyline_mass()  # int N^T N over the segments, reference configuration
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
            point = ps.vector2("point", required=True)
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
        """A scalar matrix on interface nodes -> the n x n matrix acting on x and y alike."""
        c = sp.coo_matrix(nodal)
        rows = np.concatenate([self.if_x[c.row], self.if_y[c.row]])
        cols = np.concatenate([self.if_x[c.col], self.if_y[c.col]])
        return sp.csr_matrix((np.concatenate([c.data, c.data]), (rows, cols)), shape=(self.n, self.n))

    def set_interface_mass(self, rows, cols, values):
        """Algorithm 2: M_fs = gamma_N1 * M_G with the coupler's M_G (interface nodes)."""
        if not self.gamma > 0:
            return
        n_if = len(self.interface_nodes)
        self.M_fs = self._nodal_to_dofs(sp.coo_matrix((np.asarray(values) * self.gamma, (rows, cols)),
                                                      shape=(n_if, n_if)))

    def _point_weights(self, point):
        """[(dof, weight)] with u(point) = sum weight * u[dof] per component, or None if outside."""
        x = np.array(point, dtype=float)
        tree = self.mesh.bounding_box_tree()
        dm = self.V.dofmap()
        if self.cell == "triangle":
            c = tree.compute_first_entity_collision(df.Point(*x))
            if c >= self.mesh.num_cells():
                return None
            cell = df.Cell(self.mesh, c)
            basis = self.V.element().evaluate_basis_all(x, cell.get_vertex_coordinates(), 0)
            basis = basis.reshape(-1, 2)  # per cell dof: (value x, value y)
            dofs = dm.cell_dofs(c)
            wx = [(int(d), float(b[0])) for d, b in zip(dofs, basis) if b[0] != 0]
            wy = [(int(d), float(b[1])) for d, b in zip(dofs, basis) if b[1] != 0]
            return wx, wy
        # Q1: invert the bilinear map of each cell (DOLFIN's vertex order: (0,0), (1,0), (0,1), (1,1))
        v2d = df.vertex_to_dof_map(self.V).reshape(-1, 2)
        best = None
        for c in range(self.mesh.num_cells()):
            verts = self.mesh.cells()[c]
            X = self.mesh.coordinates()[verts]
            lo, hi = X.min(axis=0), X.max(axis=0)
            if np.any(x < lo - 1e-9 * (hi - lo).max()) or np.any(x > hi + 1e-9 * (hi - lo).max()):
                continue
            xi = np.array([0.5, 0.5])
            for _ in range(20):
                N = np.array([(1 - xi[0]) * (1 - xi[1]), xi[0] * (1 - xi[1]), (1 - xi[0]) * xi[1], xi[0] * xi[1]])
                dN = np.array([[-(1 - xi[1]), -(1 - xi[0])], [1 - xi[1], -xi[0]], [-xi[1], 1 - xi[0]], [xi[1], xi[0]]])
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
        N = [(1 - xi[0]) * (1 - xi[1]), xi[0] * (1 - xi[1]), (1 - xi[0]) * xi[1], xi[0] * xi[1]]
        return ([(int(v2d[v, 0]), float(w)) for v, w in zip(verts, N)],
                [(int(v2d[v, 1]), float(w)) for v, w in zip(verts, N)])

    def probe_values(self, d):
        out = {}
        for name, (wx, wy) in self.probes:
            out[name + "_x"] = float(sum(w * d[i] for i, w in wx))
            out[name + "_y"] = float(sum(w * d[i] for i, w in wy))
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
        """Solve the step for this interface force (2 per interface node, interleaved), from
        the accepted state. Returns the interface displacement and velocity (interleaved)."""
        t0 = _time.perf_counter()
        try:
            return self._solve(dt, interface_force)
        finally:
            self.timings["step"] += _time.perf_counter() - t0

    def _solve(self, dt, interface_force):
        f = self.f_dead.copy()
        f[self.if_x] += interface_force[0::2]
        f[self.if_y] += interface_force[1::2]
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
        out = np.empty(2 * len(self.interface_nodes))
        out[0::2], out[1::2] = x[self.if_x], x[self.if_y]
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
