#!/usr/bin/env python3
"""A solid server written outside C++: the seed paper's single-degree-of-freedom solid,
on top of fsi.server (python/fsi: the protocol, errors, sessions, checkpoints and the
launcher's command line). It proves an external solid code can replace solid_server.

    fsi run configs/sdof_model.yaml --out runs/py --solid-command "python3 python/sdof_solid.py"

The launcher appends --bind ENDPOINT --port-file FILE [--curve-keys DIR]. Runs from the
repository without installing anything (the fsi package next to this file is used), or
with the package installed (pip install ./python).

Physics (identical to solid_server's `sdof` model, BDF1, every component independent):
    m a + (c + gamma * measure) v + k d = F_interface + F_external
In 3D (``dimension: 3``) the interface is a point with 3 values, or, with ``surface``, a rigid
flat plate of quadrilaterals or triangles (faces sent to the coupler) that moves as one body
under the resultant of its nodal forces, as solid_server's model does.
"""
import math
import os
import struct
import sys
import weakref

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # python/fsi, without installing

import fsi.server as fs  # noqa: E402
from fsi.server import InvalidArgument, apply_overrides  # noqa: E402,F401 (kept importable from here)

VERSION = fs.VERSION
STATE_TAG = b"PYSDOF01"
STATE_FORMAT = "<8s4d"


class SdofSolid(fs.Solid):
    name = "python sdof_solid.py"
    KEYS = {"model", "mass", "damping", "stiffness", "force", "interface_measure",
            "initial_displacement", "initial_velocity", "dimension", "surface", "substeps"}

    def configure(self, section, dt, end_time, interface_damping, output_dir):
        path = self.scene_path
        if section.get("model") != "sdof":
            raise InvalidArgument(f"{path}: this server only hosts 'solid.model: sdof'")
        unknown = sorted(set(section) - self.KEYS)
        if unknown:
            raise InvalidArgument(f"{path}: unknown key(s) in solid section: {', '.join(unknown)}")
        # Waveform iterations: this example takes one step per coupling window (it does not
        # declare ConfigureReply.supports_substeps), so only `substeps: 1` is accepted.
        if section.get("substeps", 1) != 1:
            raise InvalidArgument(f"{path}: 'solid.substeps: {section['substeps']}' needs a solid that takes "
                                  "substeps (waveform iterations); this one takes one step per window "
                                  "(set solid.substeps: 1)")

        def number(key, default=None):
            value = section.get(key, default)
            if value is None:
                raise InvalidArgument(f"{path}: 'solid.{key}' is required but missing")
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise InvalidArgument(f"{path}: 'solid.{key}' must be a number, got {value!r}")
            return float(value)

        dim = section.get("dimension", 2)
        if dim not in (2, 3):
            raise InvalidArgument(f"{path}: 'solid.dimension' must be 2 or 3, got {dim!r}")
        self.dim = dim

        def vector(key):
            value = section.get(key, 0.0)
            if isinstance(value, list):
                if len(value) != dim or not all(isinstance(x, (int, float)) for x in value):
                    raise InvalidArgument(f"{path}: 'solid.{key}' must be a number or {dim} numbers")
                return [float(x) for x in value]
            return [number(key, 0.0)] + [0.0] * (dim - 1)

        self.m = number("mass")
        self.c = number("damping", 0.0)
        self.k = number("stiffness", 0.0)
        plate = section.get("surface")
        if plate is not None:
            if dim != 3:
                raise InvalidArgument(f"{path}: 'solid.surface' (a plate interface) needs dimension: 3")
            if "interface_measure" in section:
                raise InvalidArgument(f"{path}: 'solid.interface_measure' is the plate's area when 'surface' is given")
            interface, self.measure = plate_interface(plate, path)
        else:
            self.measure = number("interface_measure", 1.0)
            interface = None
        if self.m <= 0:
            raise InvalidArgument(f"{path}: 'solid.mass' must be positive")
        self.force = vector("force")
        self.d_n = vector("initial_displacement")
        self.v_n = vector("initial_velocity")
        self.d = list(self.d_n)
        self.v = list(self.v_n)
        self.gamma = interface_damping
        self.damping = interface_damping * self.measure
        if interface is None:
            interface = fs.Interface(coordinates=[0.0] * dim, lumped_measure=[self.measure], dimension=dim)
        self.nodes = interface.nodes
        interface.initial_displacement = fs._vector(self.d_n * self.nodes, "initial_displacement")
        interface.initial_velocity = fs._vector(self.v_n * self.nodes, "initial_velocity")
        return interface

    def solve_step(self, step, time, dt, iteration, force):
        m, c, k = self.m, self.c + self.damping, self.k
        lhs = m / (dt * dt) + c / dt + k
        d = self.dim
        total = force[:d] if self.nodes == 1 else force.reshape(-1, d).sum(axis=0)  # a rigid body: the resultant
        for i in range(d):
            rhs = float(total[i]) + self.force[i] + m * (self.d_n[i] / (dt * dt) + self.v_n[i] / dt) \
                + c * self.d_n[i] / dt
            self.d[i] = rhs / lhs
            self.v[i] = (self.d[i] - self.d_n[i]) / dt
        return self.d * self.nodes, self.v * self.nodes

    def set_interface_mass(self, matrix):
        # Algorithm 2: M_fs = gamma_N1 * M_G with the coupler's M_G = H^T M_f H; a rigid body's
        # uniform velocity sees 1^T M_G 1 (the only entry at a point).
        a = matrix.toarray()
        self.damping = self.gamma * float(a[0, 0] if self.nodes == 1 else a.sum())

    def accept_step(self, step, time):
        self.d_n, self.v_n = list(self.d), list(self.v)
        probes = {"d_x": self.d[0], "d_y": self.d[1], "v_x": self.v[0], "v_y": self.v[1]}
        if self.dim == 3:
            probes.update(d_z=self.d[2], v_z=self.v[2])
        return probes

    # Checkpoints, our own format: a tag, then d_n and v_n (what the next step depends on).
    def _format(self):
        return STATE_FORMAT if self.dim == 2 else "<8s6d"  # 2D: the format of earlier versions

    def save(self):
        return struct.pack(self._format(), STATE_TAG, *self.d_n, *self.v_n)

    def load(self, state):
        fmt, d = self._format(), self.dim
        if len(state) != struct.calcsize(fmt) or state[:8] != STATE_TAG:
            raise InvalidArgument(f"{len(state)} bytes, not a state of this solid "
                                  f"({struct.calcsize(fmt)} bytes starting {STATE_TAG!r})")
        values = struct.unpack(fmt, state)[1:]
        self.d_n, self.v_n = list(values[0:d]), list(values[d:2 * d])
        self.d, self.v = list(self.d_n), list(self.v_n)


def plate_interface(plate, path):
    """A flat rectangular plate parallel to z = 0 (solid.surface: size [a, b], divisions
    [n_x, n_y], faces quad | triangle, centre [x, y, z]), as solid_server builds it: node
    (i, j) is j (n_x + 1) + i, each cell split into (0, 1, 2) and (0, 2, 3) for triangles.
    Returns the interface and its area."""
    try:
        a, b = (float(x) for x in plate["size"])
        nx, ny = (int(x) for x in plate.get("divisions", [1, 1]))
        cx, cy, cz = (float(x) for x in plate.get("centre", [0, 0, 0]))
    except (KeyError, TypeError, ValueError) as e:
        raise InvalidArgument(f"{path}: 'solid.surface' needs size [a, b] (and divisions [n_x, n_y], "
                              f"centre [x, y, z]): {e}") from None
    kind = plate.get("faces", "quad")
    if a <= 0 or b <= 0 or nx < 1 or ny < 1 or kind not in ("quad", "triangle"):
        raise InvalidArgument(f"{path}: 'solid.surface': sizes > 0, divisions >= 1, faces quad or triangle")
    xyz, faces, area = [], [], a * b
    for j in range(ny + 1):
        for i in range(nx + 1):
            xyz += [cx + a * (i / nx - 0.5), cy + b * (j / ny - 0.5), cz]
    for j in range(ny):
        for i in range(nx):
            p = [j * (nx + 1) + i, j * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i]
            cells = [p] if kind == "quad" else [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
            faces += cells
    return fs.Interface(coordinates=xyz, faces=faces, dimension=3), area


_SERVERS = weakref.WeakKeyDictionary()  # solid -> its fs.Server, for handle()


def handle(pb, solid, request):
    """One request -> (reply, stop), for tests that drive the solid without a socket
    (tests/integration/fake_solid.py). ``pb`` is accepted for compatibility: the replies
    are fsi.v1 messages of the package's generated module."""
    server = _SERVERS.get(solid)
    if server is None:
        server = _SERVERS[solid] = fs.Server(solid)
    return server.handle(request)


def main():
    parser = fs.argument_parser(__doc__.splitlines()[0])
    parser.add_argument("--proto-dir", default=None,
                        help="accepted for compatibility: the generated protocol module now comes with the fsi "
                             "package; a DIR/fsi/v1/coupling_pb2.py of another protocol is reported")
    args = parser.parse_args()
    if args.proto_dir:
        fs.check_proto_dir(args.proto_dir)
    return fs.serve(SdofSolid, args=args)


if __name__ == "__main__":
    sys.exit(main())
