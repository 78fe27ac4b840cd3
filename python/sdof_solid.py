#!/usr/bin/env python3
"""A solid server written outside C++: the seed paper's single-degree-of-freedom solid,
on top of fsi.server (python/fsi: the protocol, errors, sessions, checkpoints and the
launcher's command line). It proves an external solid code can replace solid_server.

    fsi run configs/sdof_model.yaml --out runs/py --solid-command "python3 python/sdof_solid.py"

The launcher appends --bind ENDPOINT --port-file FILE [--curve-keys DIR]. Runs from the
repository without installing anything (the fsi package next to this file is used), or
with the package installed (pip install ./python).

Physics (identical to solid_server's `sdof` model, BDF1, both components independent):
    m a + (c + gamma * measure) v + k d = F_interface + F_external
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
            "initial_displacement", "initial_velocity"}

    def configure(self, section, dt, end_time, interface_damping, output_dir):
        path = self.scene_path
        if section.get("model") != "sdof":
            raise InvalidArgument(f"{path}: this server only hosts 'solid.model: sdof'")
        unknown = sorted(set(section) - self.KEYS)
        if unknown:
            raise InvalidArgument(f"{path}: unknown key(s) in solid section: {', '.join(unknown)}")

        def number(key, default=None):
            value = section.get(key, default)
            if value is None:
                raise InvalidArgument(f"{path}: 'solid.{key}' is required but missing")
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise InvalidArgument(f"{path}: 'solid.{key}' must be a number, got {value!r}")
            return float(value)

        def vector(key):
            value = section.get(key, 0.0)
            if isinstance(value, list):
                if len(value) != 2:
                    raise InvalidArgument(f"{path}: 'solid.{key}' must be a number or [x, y]")
                return [float(value[0]), float(value[1])]
            return [number(key, 0.0), 0.0]

        self.m = number("mass")
        self.c = number("damping", 0.0)
        self.k = number("stiffness", 0.0)
        self.measure = number("interface_measure", 1.0)
        if self.m <= 0:
            raise InvalidArgument(f"{path}: 'solid.mass' must be positive")
        self.force = vector("force")
        self.d_n = vector("initial_displacement")
        self.v_n = vector("initial_velocity")
        self.d = list(self.d_n)
        self.v = list(self.v_n)
        self.gamma = interface_damping
        self.damping = interface_damping * self.measure
        return fs.Interface(coordinates=[0.0, 0.0], lumped_measure=[self.measure],
                            initial_displacement=self.d_n, initial_velocity=self.v_n)

    def solve_step(self, step, time, dt, iteration, force):
        m, c, k = self.m, self.c + self.damping, self.k
        lhs = m / (dt * dt) + c / dt + k
        for i in range(2):
            rhs = float(force[i]) + self.force[i] + m * (self.d_n[i] / (dt * dt) + self.v_n[i] / dt) \
                + c * self.d_n[i] / dt
            self.d[i] = rhs / lhs
            self.v[i] = (self.d[i] - self.d_n[i]) / dt
        return self.d, self.v

    def set_interface_mass(self, matrix):
        # Algorithm 2: M_fs = gamma_N1 * M_G with the coupler's M_G = H^T M_f H (1 x 1 here).
        self.damping = self.gamma * float(matrix.toarray()[0, 0])

    def accept_step(self, step, time):
        self.d_n, self.v_n = list(self.d), list(self.v)
        return {"d_x": self.d[0], "d_y": self.d[1], "v_x": self.v[0], "v_y": self.v[1]}

    # Checkpoints, our own format: a tag, then d_n and v_n (what the next step depends on).
    def save(self):
        return struct.pack(STATE_FORMAT, STATE_TAG, *self.d_n, *self.v_n)

    def load(self, state):
        if len(state) != struct.calcsize(STATE_FORMAT) or state[:8] != STATE_TAG:
            raise InvalidArgument(f"{len(state)} bytes, not a state of this solid "
                                  f"({struct.calcsize(STATE_FORMAT)} bytes starting {STATE_TAG!r})")
        values = struct.unpack(STATE_FORMAT, state)[1:]
        self.d_n, self.v_n = list(values[0:2]), list(values[2:4])
        self.d, self.v = list(self.d_n), list(self.v_n)


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
