#!/usr/bin/env python3
"""A solid server written outside C++: the seed paper's single-degree-of-freedom solid,
speaking the project's wire protocol (proto/fsi/v1/coupling.proto) through Python's zmq
and protobuf alone. It proves an external solid code can replace solid_server.

    fsi run configs/sdof_model.yaml --out runs/py --solid-command "python3 python/sdof_solid.py"

The launcher appends --bind ENDPOINT --port-file FILE. The generated module coupling_pb2
is found through --proto-dir, $FSI_PYTHON_PROTO, or build*/python next to this repo.

Physics (identical to solid_server's `sdof` model, BDF1, both components independent):
    m a + (c + gamma * measure) v + k d = F_interface + F_external
"""
import argparse
import glob
import math
import os
import signal
import struct
import sys

import yaml
import zmq
import zmq.auth
from zmq.auth.thread import ThreadAuthenticator

VERSION = 1


def find_proto(proto_dir):
    candidates = [proto_dir, os.environ.get("FSI_PYTHON_PROTO")]
    here = os.path.dirname(os.path.abspath(__file__))
    candidates += sorted(glob.glob(os.path.join(here, "..", "build*", "python")))
    for c in candidates:
        if c and os.path.exists(os.path.join(c, "fsi", "v1", "coupling_pb2.py")):
            sys.path.insert(0, c)
            from fsi.v1 import coupling_pb2  # noqa: E402
            return coupling_pb2
    sys.exit("sdof_solid.py: cannot find the generated coupling_pb2.py (build the project, or pass --proto-dir)")


class InvalidArgument(Exception):
    pass


def apply_overrides(scene, overrides):
    for item in overrides:
        key, _, value = item.partition("=")
        node = scene
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = yaml.safe_load(value)


class SdofSolid:
    KEYS = {"model", "mass", "damping", "stiffness", "force", "interface_measure",
            "initial_displacement", "initial_velocity"}

    def configure(self, section, scene_path, interface_damping):
        unknown = sorted(set(section) - self.KEYS)
        if unknown:
            raise InvalidArgument(f"{scene_path}: unknown key(s) in solid section: {', '.join(unknown)}")

        def number(key, default=None):
            value = section.get(key, default)
            if value is None:
                raise InvalidArgument(f"{scene_path}: 'solid.{key}' is required but missing")
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise InvalidArgument(f"{scene_path}: 'solid.{key}' must be a number, got {value!r}")
            return float(value)

        def vector(key):
            value = section.get(key, 0.0)
            if isinstance(value, list):
                if len(value) != 2:
                    raise InvalidArgument(f"{scene_path}: 'solid.{key}' must be a number or [x, y]")
                return [float(value[0]), float(value[1])]
            return [number(key, 0.0), 0.0]

        self.m = number("mass")
        self.c = number("damping", 0.0)
        self.k = number("stiffness", 0.0)
        self.measure = number("interface_measure", 1.0)
        if self.m <= 0:
            raise InvalidArgument(f"{scene_path}: 'solid.mass' must be positive")
        self.force = vector("force")
        self.d_n = vector("initial_displacement")
        self.v_n = vector("initial_velocity")
        self.d = list(self.d_n)
        self.v = list(self.v_n)
        self.damping = interface_damping * self.measure

    def solve(self, dt, interface_force):
        m, c, k = self.m, self.c + self.damping, self.k
        lhs = m / (dt * dt) + c / dt + k
        for i in range(2):
            rhs = interface_force[i] + self.force[i] + m * (self.d_n[i] / (dt * dt) + self.v_n[i] / dt) \
                + c * self.d_n[i] / dt
            self.d[i] = rhs / lhs
            self.v[i] = (self.d[i] - self.d_n[i]) / dt
        return self.d, self.v

    def accept(self):
        self.d_n, self.v_n = list(self.d), list(self.v)
        return {"d_x": self.d[0], "d_y": self.d[1], "v_x": self.v[0], "v_y": self.v[1]}


STATE_TAG = b"PYSDOF01"
STATE_FORMAT = "<8s4d"


def handle(pb, solid, request):
    reply = pb.Reply(protocol_version=VERSION, sequence=request.sequence)
    if request.protocol_version != VERSION:
        reply.error.code = pb.Error.VERSION_MISMATCH
        reply.error.message = f"protocol version mismatch: request has {request.protocol_version}, this server speaks {VERSION}"
        return reply, False
    body = request.WhichOneof("body")
    try:
        if body == "hello":
            reply.hello.kind = pb.SERVER_KIND_SOLID
            reply.hello.server_name = "python sdof_solid.py"
            reply.hello.protocol_version = VERSION
            reply.hello.supports_interface_damping = True
            reply.hello.supports_checkpoint = True
        elif body == "configure":
            c = request.configure
            scene = yaml.safe_load(c.scene_text) or {}
            apply_overrides(scene, list(c.overrides))
            section = scene.get(c.section or "solid")
            if not isinstance(section, dict):
                raise InvalidArgument(f"{c.scene_path}: no '{c.section}' section")
            if section.get("model") != "sdof":
                raise InvalidArgument(f"{c.scene_path}: this server only hosts 'solid.model: sdof'")
            solid.configure(section, c.scene_path, c.interface_damping)
            reply.configure.interface_nodes = 1
        elif body == "get_interface":
            mesh = reply.interface
            mesh.node_ids.append(0)
            mesh.coordinates.extend([0.0, 0.0])
            mesh.lumped_measure.append(solid.measure)
            mesh.initial_displacement.extend(solid.d_n)
            mesh.initial_velocity.extend(solid.v_n)
        elif body == "solve_step":
            s = request.solve_step
            force = list(s.interface_force)
            if len(force) != 2:
                raise InvalidArgument(f"'interface_force' has {len(force)} values, expected 2")
            if not all(math.isfinite(f) for f in force):
                raise InvalidArgument("'interface_force' is not finite")
            d, v = solid.solve(s.dt, force)
            reply.solid_step.interface_displacement.extend(d)
            reply.solid_step.interface_velocity.extend(v)
            reply.solid_step.newton_iterations = 1
        elif body == "accept_step":
            for name, value in solid.accept().items():
                reply.accept.probes[name] = value
        elif body == "save_checkpoint":
            # Our own format: a tag, then d_n and v_n (what the next step depends on).
            reply.checkpoint.state = struct.pack(STATE_FORMAT, STATE_TAG, *solid.d_n, *solid.v_n)
        elif body == "load_checkpoint":
            state = request.load_checkpoint.state
            if len(state) != struct.calcsize(STATE_FORMAT) or state[:8] != STATE_TAG:
                raise InvalidArgument(f"checkpoint of step {request.load_checkpoint.step}: {len(state)} bytes, not a "
                                      f"state of this solid ({struct.calcsize(STATE_FORMAT)} bytes starting {STATE_TAG!r})")
            values = struct.unpack(STATE_FORMAT, state)[1:]
            solid.d_n, solid.v_n = list(values[0:2]), list(values[2:4])
            solid.d, solid.v = list(solid.d_n), list(solid.v_n)
            reply.loaded.SetInParent()
        elif body == "write_output":
            reply.output.SetInParent()
        elif body == "stop":
            reply.stop.SetInParent()
            return reply, True
        else:
            reply.error.code = pb.Error.UNSUPPORTED
            reply.error.message = f"a solid server does not handle '{body}'"
    except InvalidArgument as e:
        reply.error.code = pb.Error.INVALID_ARGUMENT
        reply.error.message = str(e)
    except AttributeError as e:  # a step before configure
        reply.error.code = pb.Error.BAD_SEQUENCE
        reply.error.message = f"'{body}' before 'configure' ({e})"
    return reply, False


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bind", default="tcp://127.0.0.1:5555")
    parser.add_argument("--port-file", default="")
    parser.add_argument("--proto-dir", default=None)
    parser.add_argument("--curve-keys", default=None,
                        help="ZeroMQ CURVE key folder made by `fsi keys DIR`")
    args = parser.parse_args()
    pb = find_proto(args.proto_dir)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))

    socket = zmq.Context.instance().socket(zmq.REP)
    if args.curve_keys:  # encrypted; only the clients whose *.key is in the folder
        auth = ThreadAuthenticator(zmq.Context.instance())
        auth.start()
        auth.configure_curve(domain="*", location=args.curve_keys)
        public, secret = zmq.auth.load_certificate(
            os.path.join(args.curve_keys, "server.key_secret"))
        socket.curve_secretkey = secret
        socket.curve_publickey = public
        socket.curve_server = True
    socket.bind(args.bind)
    endpoint = socket.getsockopt(zmq.LAST_ENDPOINT).decode()
    if args.port_file:
        with open(args.port_file + ".tmp", "w") as f:
            f.write(endpoint + "\n")
        os.replace(args.port_file + ".tmp", args.port_file)
    print(f"python sdof solid listening on {endpoint}", file=sys.stderr, flush=True)

    solid = SdofSolid()
    while True:
        data = socket.recv()
        request = pb.Request()
        try:
            request.ParseFromString(data)
        except Exception:  # noqa: BLE001 - any parse failure is a malformed message
            reply = pb.Reply(protocol_version=VERSION)
            reply.error.code = pb.Error.MALFORMED
            reply.error.message = f"message of {len(data)} bytes is not a fsi.v1.Request"
            socket.send(reply.SerializeToString())
            continue
        reply, stop = handle(pb, solid, request)
        socket.send(reply.SerializeToString())
        if stop:
            break


if __name__ == "__main__":
    main()
