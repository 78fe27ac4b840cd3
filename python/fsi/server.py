"""fsi.server: an external solid in a few lines.

You write the physics; this module speaks the protocol (proto/fsi/v1/coupling.proto):
the launcher's command line (``--bind ENDPOINT --port-file FILE [--curve-keys DIR]``),
the ZeroMQ socket, the atomic port file, version and order checks, error replies,
sequence numbers, Hello capabilities, sessions, ``--set`` overrides applied to the scene,
restarting every coupling iteration from the last accepted state, checkpoints, SIGTERM,
one coupler at a time (others get BUSY).

    import sys
    import fsi.server as fs

    class PointMass(fs.Solid):
        def configure(self, section, dt, end_time, interface_damping, output_dir):
            self.m, self.gamma = float(section["mass"]), interface_damping
            self.d, self.v = fs.zeros(1), fs.zeros(1)           # one interface node
            return fs.Interface(coordinates=[0.0, 0.0], lumped_measure=[1.0])

        def solve_step(self, step, time, dt, iteration, force):
            # m (v - v_n)/dt + gamma v = F; self.d, self.v are the last accepted state
            self.v = (self.m * self.v / dt + force) / (self.m / dt + self.gamma)
            self.d = self.d + dt * self.v
            return self.d, self.v

        def accept_step(self, step, time):
            return {"d_x": self.d[0]}

    sys.exit(fs.serve(PointMass))     # 0 after Stop, 130 after SIGTERM, 3 after --idle-timeout

A 3D solid describes its interface with 3 values per node and faces (triangles and
quadrilaterals, 3/4 nodes, or quadratic 6/8/9 nodes in gmsh's order); its vectors then carry
x, y, z per node:

    fs.Interface(coordinates=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
                 faces=[[0, 1, 2, 3]], dimension=3)

The methods (positional arguments, in this order):

``configure(section, dt, end_time, interface_damping, output_dir) -> Interface``
    ``section`` is your part of the scene (a dict, ``--set`` overrides applied); the whole
    scene is ``self.scene``, its path ``self.scene_path``. Raise ``InvalidArgument`` for a
    bad key (the run stops, naming it); ``fsi.section.Section(section, "solid")`` reads keys
    strictly (types, ranges, and ``check_all_used()`` names every key nobody read), its
    ``SceneError`` answered the same way. A ``configure`` without an ``interface_damping``
    parameter (e.g. ``configure(self, section, dt, end_time)``) declares that the solid
    cannot run Algorithm 2 with gamma > 0 (``supports_interface_damping = False``);
    parameters are then passed by name. Return an ``Interface`` (or a dict of its
    arguments).
``solve_step(step, time, dt, iteration, force) -> (displacement, velocity[, newton_iterations])``
    ``force`` is a numpy array of d values per interface node (interleaved x, y and, for a
    3D interface, z), already
    checked for size and finiteness. Return arrays of the same size. Every call starts
    from the last accepted state: this module puts it back before a repeated call (see
    ``restart`` below). Raise ``SolverFailed`` (or an exception in ``solver_errors``) when
    your solver fails: the coupler reports the run as diverged.
``accept_step(step, time) -> dict``
    The last solve becomes the accepted state; return the probes (name -> number).
``save() -> bytes`` and ``load(state: bytes)`` (optional)
    Your state after the last accepted step, in your own format; with both, the server
    answers ``supports_checkpoint = true``. ``load`` raises ``InvalidArgument`` (or any
    exception) for a state it cannot use.
``timings() -> dict`` (optional)
    Cumulative wall seconds of your solver by category ("assembly", "linear_solve", ...),
    sent with every AcceptReply: summary.json shows the last as ``wall_time.solid_breakdown``.
``diagnostics() -> dict`` (optional)
    Statistics of the run so far (e.g. contact with the scene's ``solid.obstacles``:
    "contact_active_time", "contact_min_gap"), sent with every AcceptReply: summary.json shows
    the last as ``solid_diagnostics``. Keep them in your checkpoint state.
``write_output(step, time) -> list of file names`` (optional)
    With it, ``supports_output = true``.
``set_interface_mass(matrix)`` (optional, Algorithm 2)
    With it, ``supports_interface_mass = true``: before a ``solve_step`` the coupler may send
    the interface mass ``M_G = H^T M_f H`` (a ``NodalMatrix``: ``size``, ``rows``, ``cols``,
    ``values``, ``toarray()``, ``matvec(v)`` for interleaved v), the fluid's own operator in
    its current configuration mapped to your nodes. Use ``interface_damping * M_G`` as your
    Robin damping from then on: the gamma_N1 terms then cancel exactly at convergence.
    Without it, your own ``int N^T N`` is used and the coupler reports the part that does
    not cancel (``coupling.work_uncancelled``).

Class attributes: ``name`` (the HelloReply.server_name, default the class name),
``restart`` (how a repeated ``solve_step`` goes back to the accepted state: ``"auto"``
= ``save``/``load`` if you have them, else a deep copy of the object's attributes;
``"save"``, ``"copy"``, or ``"none"`` when your ``solve_step`` never changes the accepted
state itself), ``solver_errors`` (exception types answered as SOLVER_FAILED).
"""
import argparse
import copy
import inspect
import math
import os
import signal
import sys
import time as _time
import traceback

from fsi.interpreter import require as _require

_require("numpy", "yaml", "zmq", "google.protobuf")  # a script under another python3: re-run with FSI_PYTHON

import numpy as np  # noqa: E402
import yaml  # noqa: E402

from fsi.section import SceneError, Section  # noqa: E402,F401 - the strict section reader, for solids
from fsi.v1 import coupling_pb2 as pb  # noqa: E402

VERSION = 1
CONFIGURE_ARGS = ("dt", "end_time", "interface_damping", "output_dir")

__all__ = ["Solid", "Interface", "NodalMatrix", "Server", "serve", "argument_parser", "InvalidArgument", "SolverFailed",
           "Unsupported", "apply_overrides", "zeros", "VERSION", "pb"]


class InvalidArgument(Exception):
    """A bad scene key or request field: answered as Error INVALID_ARGUMENT (the run fails)."""


class SolverFailed(Exception):
    """Your solver failed (no convergence, singular matrix): Error SOLVER_FAILED (the run diverged)."""


class Unsupported(Exception):
    """Something this solid does not do: Error UNSUPPORTED."""


class _BadSequence(Exception):
    pass


def zeros(nodes, dimension=2):
    """A zero vector of ``dimension`` values per interface node (2 or 3)."""
    return np.zeros(dimension * nodes)


def apply_overrides(scene, overrides):
    """Apply ``--set`` strings ("a.b=c", values parsed as YAML) to the scene dict, in order."""
    for item in overrides:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise InvalidArgument(f"override '{item}' is not of the form key=value")
        node = scene
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                raise InvalidArgument(f"override '{item}': '{p}' is not a section")
        node[parts[-1]] = yaml.safe_load(value)
    return scene


def _vector(values, what, size=None, per_node=2):
    try:
        v = np.asarray(values, dtype=float).reshape(-1)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what} is not a vector of numbers ({e})") from None
    if size is not None and v.size != size:
        raise ValueError(f"{what} has {v.size} values, expected {size} ({per_node} per interface node)")
    return v


_FACE_SIZES = (3, 4, 6, 8, 9)  # triangles (3, 6 nodes) and quadrilaterals (4, 8, 9), gmsh node order


class Interface:
    """The interface mesh, in 2D or 3D (``dimension``; default 2).

    ``coordinates``: n x dimension (or interleaved), reference configuration [m]. Then exactly
    one of: ``segments`` (2D: pairs of local node indices, 2-node lines), ``faces`` (3D: a list
    of faces, each a list of 3, 4, 6, 8 or 9 local node indices: linear and quadratic triangles
    and quadrilaterals in gmsh's node order) or ``lumped_measure`` (n values, the diagonal of
    int N^T N: a point interface). Optional: ``node_ids`` (your numbers, default 0..n-1),
    ``initial_displacement`` and ``initial_velocity`` (dimension x n; default at rest)."""

    def __init__(self, coordinates, segments=None, lumped_measure=None, node_ids=None,
                 initial_displacement=None, initial_velocity=None, faces=None, dimension=2):
        if dimension not in (2, 3):
            raise ValueError(f"Interface.dimension is {dimension}: must be 2 or 3")
        self.dimension = d = int(dimension)
        c = _vector(coordinates, "Interface.coordinates")
        if c.size == 0 or c.size % d:
            raise ValueError(f"Interface.coordinates has {c.size} values: need {d} per node, at least one node")
        if not np.all(np.isfinite(c)):
            raise ValueError("Interface.coordinates is not finite")
        self.coordinates = c
        n = c.size // d
        if sum(x is not None for x in (segments, faces, lumped_measure)) != 1:
            raise ValueError("Interface needs exactly one of segments (2D), faces (3D) or lumped_measure (points)")
        self.segments = None
        self.faces = None
        self.lumped_measure = None
        if segments is not None:
            if d != 2:
                raise ValueError("Interface.segments describe a 2D interface: in 3D give faces")
            s = np.asarray(segments, dtype=np.int64).reshape(-1)
            if s.size == 0 or s.size % 2 or s.min() < 0 or s.max() >= n:
                raise ValueError(f"Interface.segments must be pairs of node indices in [0, {n})")
            self.segments = s
        elif faces is not None:
            if d != 3:
                raise ValueError("Interface.faces describe a 3D interface: give dimension=3")
            self.faces = [np.asarray(f, dtype=np.int64).reshape(-1) for f in faces]
            if not self.faces:
                raise ValueError("Interface.faces is empty")
            for i, f in enumerate(self.faces):
                if f.size not in _FACE_SIZES:
                    raise ValueError(f"Interface.faces[{i}] has {f.size} nodes: a face has 3, 4, 6, 8 or 9")
                if f.min() < 0 or f.max() >= n:
                    raise ValueError(f"Interface.faces[{i}] has a node index outside [0, {n})")
        else:
            m = _vector(lumped_measure, "Interface.lumped_measure", n, 1)
            if not np.all(np.isfinite(m)) or not np.all(m > 0):
                raise ValueError("Interface.lumped_measure must be finite and > 0 at every node")
            self.lumped_measure = m
        self.node_ids = np.arange(n) if node_ids is None else np.asarray(node_ids, dtype=np.int64).reshape(-1)
        if self.node_ids.size != n or len(set(self.node_ids.tolist())) != n:
            raise ValueError(f"Interface.node_ids must be {n} distinct numbers")
        self.initial_displacement = (np.zeros(0) if initial_displacement is None else
                                     _vector(initial_displacement, "Interface.initial_displacement", d * n, d))
        self.initial_velocity = (np.zeros(0) if initial_velocity is None else
                                 _vector(initial_velocity, "Interface.initial_velocity", d * n, d))

    @property
    def nodes(self):
        return self.coordinates.size // self.dimension

    @property
    def values(self):
        """Values of an interface vector: dimension per node."""
        return self.coordinates.size

    def to_proto(self, mesh):
        if self.dimension != 2:
            mesh.dimension = self.dimension  # 0 (absent) = 2: a 2D interface sends what it always did
        mesh.node_ids.extend(int(i) for i in self.node_ids)
        mesh.coordinates.extend(float(x) for x in self.coordinates)
        if self.segments is not None:
            mesh.segments.extend(int(i) for i in self.segments)
        elif self.faces is not None:
            for f in self.faces:
                mesh.face_sizes.append(int(f.size))
                mesh.faces.extend(int(i) for i in f)
        else:
            mesh.lumped_measure.extend(float(x) for x in self.lumped_measure)
        mesh.initial_displacement.extend(float(x) for x in self.initial_displacement)
        mesh.initial_velocity.extend(float(x) for x in self.initial_velocity)


class NodalMatrix:
    """A sparse scalar matrix on the interface nodes (fsi.v1.NodalMatrix): it acts on every
    component (x, y and, in 3D, z) alike. Duplicate (row, col) entries add up."""

    def __init__(self, size, rows, cols, values):
        self.size = int(size)
        self.rows = np.asarray(rows, dtype=np.int64).reshape(-1)
        self.cols = np.asarray(cols, dtype=np.int64).reshape(-1)
        self.values = np.asarray(values, dtype=float).reshape(-1)
        if not (self.rows.size == self.cols.size == self.values.size):
            raise ValueError(f"NodalMatrix: {self.rows.size} rows, {self.cols.size} cols, {self.values.size} values")
        if self.values.size and (self.rows.min() < 0 or self.cols.min() < 0 or self.rows.max() >= self.size
                                 or self.cols.max() >= self.size):
            raise ValueError(f"NodalMatrix: an index is outside {self.size} x {self.size}")
        if not np.all(np.isfinite(self.values)):
            raise ValueError("NodalMatrix: a value is not finite")

    @classmethod
    def from_proto(cls, m, size):
        if m.size != size:
            raise ValueError(f"interface_mass has size {m.size}, expected {size} (interface nodes)")
        return cls(m.size, list(m.rows), list(m.cols), list(m.values))

    def toarray(self):
        a = np.zeros((self.size, self.size))
        np.add.at(a, (self.rows, self.cols), self.values)
        return a

    def matvec(self, v):
        """(M (x) I_d) v for an interleaved vector v of d values per node (d = v.size / size)."""
        v = np.asarray(v, dtype=float)
        v = v.reshape(self.size, -1) if self.size else v.reshape(0, 2)
        out = np.zeros_like(v)
        np.add.at(out, self.rows, self.values[:, None] * v[self.cols])
        return out.reshape(-1)


class Solid:
    """Base class of an external solid (optional: any object with the same methods works).
    See the module documentation for the methods and attributes."""
    name = None
    restart = "auto"
    solver_errors = ()
    scene = None          # the whole scene (dict), set before configure
    scene_path = "<scene>"

    def configure(self, section, dt, end_time, interface_damping, output_dir):
        raise NotImplementedError("configure(section, dt, end_time, interface_damping, output_dir) -> Interface")

    def solve_step(self, step, time, dt, iteration, force):
        raise NotImplementedError("solve_step(step, time, dt, iteration, force) -> (displacement, velocity)")

    def accept_step(self, step, time):
        return {}


def _implements(obj, method):
    return callable(getattr(obj, method, None))


def _log(name, text):
    print(f"[{name}] {text}", file=sys.stderr, flush=True)


class Server:
    """The protocol state machine around one solid: ``handle(request) -> (reply, stop)``
    for a parsed fsi.v1.Request, ``handle_frames(frames) -> (bytes, stop)`` for what a
    REP socket received. No sockets here (``serve`` owns them), so it is easy to test."""

    def __init__(self, solid, name=None):
        self.solid = solid
        self.name = name or getattr(solid, "name", None) or type(solid).__name__
        self._configure_kwargs = self._inspect_configure()
        declared = getattr(solid, "supports_interface_damping", None)
        self.supports_interface_damping = (declared if declared is not None else
                                           self._configure_kwargs is None or "interface_damping" in self._configure_kwargs)
        self.supports_checkpoint = _implements(solid, "save") and _implements(solid, "load")
        self.supports_output = _implements(solid, "write_output")
        self.supports_interface_mass = _implements(solid, "set_interface_mass")
        mode = getattr(solid, "restart", "auto")
        if mode in (None, False, "none"):
            mode = "none"
        elif mode == "auto":
            mode = "save" if self.supports_checkpoint else "copy"
        if mode not in ("save", "copy", "none"):
            raise ValueError(f"{self.name}: restart must be 'auto', 'save', 'copy' or 'none', got {mode!r}")
        if mode == "save" and not self.supports_checkpoint:
            raise ValueError(f"{self.name}: restart = 'save' needs save() and load()")
        self.restart = mode
        self.solver_errors = (SolverFailed,) + tuple(getattr(solid, "solver_errors", ()) or ())
        self.session = None        # the open session's id (Hello.session), None when none is open
        self.session_peer = None   # the connection it came on (serve(): the ROUTER identity)
        self.session_client = ""
        self.session_since = ""
        self.requests = 0
        self._reset()

    def _inspect_configure(self):
        """None: pass the documented positional arguments; else the names to pass by keyword."""
        try:
            params = list(inspect.signature(self.solid.configure).parameters.values())[1:]
        except (TypeError, ValueError):
            return None
        if any(p.kind == p.VAR_KEYWORD for p in params):
            return list(CONFIGURE_ARGS)
        names = [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
        if any(p.kind == p.VAR_POSITIONAL for p in params) or not set(names) <= set(CONFIGURE_ARGS):
            return None  # other names: positional, in the documented order
        return names

    def _reset(self):
        self.configured = False
        self.interface = None
        self.configure_failure = ""
        self._snapshot = None
        self._dirty = False

    # -- requests ----------------------------------------------------------------------
    def peer_gone(self, peer):
        """The connection of ``peer`` closed: if it held the session (the coupler died), the
        session ends and the configuration is forgotten; the next coupler says Hello again."""
        if self.session_peer is None or peer != self.session_peer:
            return False
        _log(self.name, f"session '{self.session}' of '{self.session_client}' ended: its connection closed")
        self._close_session()
        self._reset()
        return True

    def _close_session(self):
        self.session, self.session_peer, self.session_client, self.session_since = None, None, "", ""

    def handle_frames(self, frames, peer=None):
        """frames: the message parts after the envelope (what a REP socket delivers); ``peer``:
        who sent them (any hashable; None = a socket that has one client anyway)."""
        if len(frames) != 1:
            reply = pb.Reply(protocol_version=VERSION)
            reply.error.code = pb.Error.MALFORMED
            reply.error.message = (f"message has {len(frames)} frames after the envelope, expected exactly 1 "
                                   f"(one serialised fsi.v1.Request)")
            return reply.SerializeToString(), False
        request = pb.Request()
        try:
            request.ParseFromString(frames[0])
        except Exception:  # noqa: BLE001 - any parse failure is a malformed message
            reply = pb.Reply(protocol_version=VERSION)
            reply.error.code = pb.Error.MALFORMED
            reply.error.message = f"message of {len(frames[0])} bytes is not a fsi.v1.Request"
            return reply.SerializeToString(), False
        reply, stop = self.handle(request, peer)
        return reply.SerializeToString(), stop

    def handle(self, request, peer=None):
        """One parsed fsi.v1.Request -> (fsi.v1.Reply, stop). While a session is open (from
        Hello to Stop, or until its connection closes: ``peer_gone``), a request of another
        ``peer`` gets Error BUSY naming the session, as the C++ servers answer."""
        self.requests += 1
        start = _time.perf_counter()
        reply = pb.Reply(protocol_version=VERSION, sequence=request.sequence)
        if request.protocol_version != VERSION:
            return self._error(reply, pb.Error.VERSION_MISMATCH, f"protocol version mismatch: request has "
                               f"{request.protocol_version}, this server speaks {VERSION}"), False
        if self.session_peer is not None and peer is not None and peer != self.session_peer:
            return self._error(reply, pb.Error.BUSY, f"this server is in session '{self.session}' with "
                               f"'{self.session_client}' (since {self.session_since}); it serves one coupler at "
                               f"a time"), False
        body = request.WhichOneof("body")
        if body is None:
            return self._error(reply, pb.Error.MALFORMED, "request has no body"), False
        stop = False
        try:
            stop = self._dispatch(body, request, reply, peer)
        except (InvalidArgument, SceneError) as e:
            self._error(reply, pb.Error.INVALID_ARGUMENT, str(e))
        except _BadSequence as e:
            self._error(reply, pb.Error.BAD_SEQUENCE, str(e))
        except Unsupported as e:
            self._error(reply, pb.Error.UNSUPPORTED, str(e))
        except self.solver_errors as e:
            self._error(reply, pb.Error.SOLVER_FAILED, f"{body}: {e}")
        except Exception as e:  # noqa: BLE001 - a bug of the solid: INTERNAL, the server stays up
            traceback.print_exc(file=sys.stderr)
            self._error(reply, pb.Error.INTERNAL, f"{body}: {type(e).__name__}: {e}")
        if body == "configure":
            self.configure_failure = reply.error.message if reply.HasField("error") else ""
        reply.compute_seconds = _time.perf_counter() - start
        return reply, stop

    @staticmethod
    def _error(reply, code, message):
        reply.error.code = code
        reply.error.message = message
        return reply

    def _need_configured(self, body):
        if not self.configured:
            if self.configure_failure:
                raise _BadSequence(f"'{body}' on an unconfigured server: the last 'configure' failed "
                                   f"({self.configure_failure})")
            raise _BadSequence(f"'{body}' before 'configure'")

    def _dispatch(self, body, request, reply, peer=None):
        s = self.solid
        if body == "hello":
            h = request.hello
            self.session = h.session or "unnamed"
            self.session_peer = peer
            self.session_client = h.client_name or "a client"
            self.session_since = _time.strftime("%H:%M:%S")
            _log(self.name, f"session '{self.session}' of '{self.session_client}'")
            r = reply.hello
            r.kind = pb.SERVER_KIND_SOLID
            r.server_name = self.name
            r.protocol_version = VERSION
            r.supports_interface_damping = bool(self.supports_interface_damping)
            r.supports_output = self.supports_output
            r.supports_checkpoint = self.supports_checkpoint
            r.supports_interface_mass = self.supports_interface_mass
        elif body == "configure":
            self._configure(request.configure, reply)
        elif body == "get_interface":
            self._need_configured(body)
            self.interface.to_proto(reply.interface)
        elif body == "solve_step":
            self._need_configured(body)
            self._solve(request.solve_step, reply)
        elif body == "accept_step":
            self._need_configured(body)
            a = request.accept_step
            probes = s.accept_step(int(a.step), float(a.time)) or {}
            for key, value in dict(probes).items():
                reply.accept.probes[str(key)] = float(value)
            if _implements(s, "timings"):
                for key, value in dict(s.timings() or {}).items():
                    reply.accept.timings[str(key)] = float(value)
            if _implements(s, "diagnostics"):
                for key, value in dict(s.diagnostics() or {}).items():
                    reply.accept.diagnostics[str(key)] = float(value)
            self._take_snapshot()
        elif body in ("save_checkpoint", "load_checkpoint"):
            self._need_configured(body)
            if not self.supports_checkpoint:
                raise Unsupported(f"solid '{self.name}' does not support checkpoints (it has no save() and load())")
            if body == "save_checkpoint":
                reply.checkpoint.state = bytes(s.save())
            else:
                lc = request.load_checkpoint
                try:
                    s.load(bytes(lc.state))
                except Exception as e:  # noqa: BLE001 - a state it cannot use
                    raise InvalidArgument(f"checkpoint of step {lc.step}: {e}") from None
                self._take_snapshot()
                reply.loaded.SetInParent()
        elif body == "write_output":
            self._need_configured(body)
            if not self.supports_output:
                raise Unsupported(f"solid '{self.name}' does not write output")
            w = request.write_output
            files = s.write_output(int(w.step), float(w.time)) or []
            reply.output.files.extend(str(f) for f in files)
        elif body == "stop":
            _log(self.name, f"stop ({request.stop.reason or 'no reason given'})")
            reply.stop.SetInParent()
            self._close_session()
            return True
        else:
            raise Unsupported(f"a solid server does not handle '{body}'")
        return False

    def _configure(self, c, reply):
        self._reset()  # a failed configure leaves the server unconfigured, not with the old state
        if not (math.isfinite(c.dt) and c.dt > 0):
            raise InvalidArgument(f"configure: dt must be positive, got {c.dt}")
        if not math.isfinite(c.interface_damping) or c.interface_damping < 0:
            raise InvalidArgument(f"configure: interface_damping must be finite and >= 0, got {c.interface_damping}")
        if not math.isfinite(c.end_time) or c.end_time < 0:
            raise InvalidArgument(f"configure: end_time must be finite and >= 0, got {c.end_time}")
        if c.interface_damping > 0 and not self.supports_interface_damping:
            raise Unsupported(f"solid '{self.name}' cannot add interface damping (Algorithm 2)")
        path = c.scene_path or "<scene>"
        try:
            scene = yaml.safe_load(c.scene_text) or {}
        except yaml.YAMLError as e:
            raise InvalidArgument(f"{path}: not YAML: {e}") from None
        if not isinstance(scene, dict):
            raise InvalidArgument(f"{path}: the scene is not a mapping")
        apply_overrides(scene, list(c.overrides))
        name = c.section or "solid"
        section = scene.get(name)
        if not isinstance(section, dict):
            raise InvalidArgument(f"{path}: no '{name}' section")
        self.solid.scene, self.solid.scene_path = scene, path
        values = {"dt": c.dt, "end_time": c.end_time, "interface_damping": c.interface_damping,
                  "output_dir": c.output_dir}
        if self._configure_kwargs is None:
            result = self.solid.configure(section, *(values[k] for k in CONFIGURE_ARGS))
        else:
            result = self.solid.configure(section, **{k: values[k] for k in self._configure_kwargs})
        if isinstance(result, dict):
            result = Interface(**result)
        if not isinstance(result, Interface):
            raise TypeError(f"configure returned {type(result).__name__}, expected fsi.server.Interface")
        self.interface = result
        self.configured = True
        self._take_snapshot()
        reply.configure.interface_nodes = result.nodes

    def _solve(self, st, reply):
        d = self.interface.dimension
        n2 = d * self.interface.nodes
        force = np.array(st.interface_force, dtype=float)
        if force.size != n2:
            raise InvalidArgument(f"'interface_force' has {force.size} values, expected {n2}")
        bad = np.flatnonzero(~np.isfinite(force))
        if bad.size:
            i = int(bad[0])
            raise InvalidArgument(f"'interface_force' is not finite at node {i // d} ({'xyz'[i % d]}): {force[i]}")
        if not (math.isfinite(st.dt) and st.dt > 0):
            raise InvalidArgument(f"solve_step: dt must be positive, got {st.dt}")
        if not math.isfinite(st.time):
            raise InvalidArgument(f"solve_step: time must be finite, got {st.time}")
        if self._dirty:
            self._restore()  # a repeated solve_step: start again from the last accepted state
        self._dirty = True
        if st.HasField("interface_mass") and self.supports_interface_mass:
            try:
                matrix = NodalMatrix.from_proto(st.interface_mass, self.interface.nodes)
            except ValueError as e:
                raise InvalidArgument(str(e)) from None
            self.solid.set_interface_mass(matrix)
        result = self.solid.solve_step(int(st.step), float(st.time), float(st.dt), int(st.iteration), force)
        if not isinstance(result, (tuple, list)) or len(result) not in (2, 3):
            raise TypeError("solve_step must return (displacement, velocity) or (displacement, velocity, "
                            "newton_iterations)")
        out = reply.solid_step
        for what, values, field in (("displacement", result[0], out.interface_displacement),
                                    ("velocity", result[1], out.interface_velocity)):
            v = _vector(values, f"solve_step's {what}", n2, d)
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                i = int(bad[0])
                raise SolverFailed(f"solid step ({what}) produced a non-finite value at node {i // d} "
                                   f"({'xyz'[i % d]}): {v[i]}")
            field.extend(v.tolist())
        out.newton_iterations = int(result[2]) if len(result) == 3 else 1

    def _take_snapshot(self):
        self._dirty = False
        if self.restart == "save":
            self._snapshot = bytes(self.solid.save())
        elif self.restart == "copy":
            self._snapshot = copy.deepcopy(self.solid.__dict__)

    def _restore(self):
        if self.restart == "save":
            self.solid.load(self._snapshot)
        elif self.restart == "copy":
            self.solid.__dict__.update(copy.deepcopy(self._snapshot))


def check_proto_dir(folder):
    """Warn when FOLDER/fsi/v1/coupling_pb2.py (e.g. a build's) describes another protocol
    than this package's generated module. Returns True when they agree (or it is absent)."""
    import ast
    path = os.path.join(folder, "fsi", "v1", "coupling_pb2.py")
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return True
    key = "AddSerializedFile("
    start = text.find(key)
    try:
        theirs = ast.literal_eval(text[start + len(key):text.find(")\n", start)]) if start >= 0 else None
    except (SyntaxError, ValueError):
        theirs = None
    if theirs != pb.DESCRIPTOR.serialized_pb:
        _log("fsi.server", f"warning: {path} describes another protocol than the fsi package's "
                           f"{pb.__file__} (regenerate with python/tools/check_generated.py --update)")
        return False
    return True


# -- the process ---------------------------------------------------------------------------
def argument_parser(description=None):
    """The launcher's command line; add your own options to it and pass it to serve()."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--bind", default="tcp://127.0.0.1:5555",
                   help="ZeroMQ endpoint to bind (the launcher passes tcp://127.0.0.1:*)")
    p.add_argument("--port-file", default="", help="write the bound endpoint there, atomically")
    p.add_argument("--curve-keys", default=None, help="ZeroMQ CURVE key folder made by `fsi keys DIR`")
    p.add_argument("--idle-timeout", type=float, default=0.0,
                   help="exit (code 3) when no request arrives for this many seconds (0 = never)")
    return p


_SIGNALLED = []


def _on_signal(signum, frame):
    # Only a flag, as the C++ servers: the request being computed is finished and answered,
    # then serve() returns 130. (An exception raised here would surface inside the solid's
    # code and be answered as an INTERNAL error, and the server would go on.)
    _SIGNALLED.append(signum)


def _split_envelope(frames):
    """ROUTER frames -> (envelope, payload frames): the identity and every frame up to and
    including the empty delimiter, if there is one."""
    for i in range(1, len(frames)):
        if len(frames[i]) == 0:
            return frames[:i + 1], frames[i + 1:]
    return frames[:1], frames[1:]


def write_port_file(path, endpoint):
    """Write the endpoint as one line, atomically (the launcher reads the file once non-empty)."""
    with open(path + ".tmp", "w") as f:
        f.write(endpoint + "\n")
    os.replace(path + ".tmp", path)


def serve(solid, argv=None, parser=None, args=None):
    """Serve one solid until Stop; returns the exit code: 0 after Stop, 130 after SIGTERM or
    SIGINT (the request in progress is answered first), 3 after --idle-timeout. Pass it on:
    ``sys.exit(fs.serve(MySolid))``. ``solid``: an instance, a class (instantiated without
    arguments), or a function of the parsed arguments returning an instance.

    One ROUTER socket, like the C++ servers: a Hello opens a session for its connection; the
    requests of any other client get BUSY until Stop or until that connection closes (the
    coupler died: the configuration is then forgotten)."""
    import zmq
    from zmq.utils.monitor import recv_monitor_message

    if args is None:
        args = (parser or argument_parser()).parse_args(argv)
    if inspect.isclass(solid):
        solid = solid()
    elif callable(solid) and not _implements(solid, "solve_step"):
        solid = solid(args)
    server = Server(solid)
    name = server.name
    ctx = zmq.Context.instance()
    sock = ctx.socket(zmq.ROUTER)  # [identity, "", request] in, [identity, "", reply] out
    sock.setsockopt(zmq.LINGER, 1000)
    monitor = sock.get_monitor_socket(zmq.EVENT_DISCONNECTED)  # a coupler's connection closed
    peer_of_fd = {}  # the connection (file descriptor) each peer's requests came on
    auth = None
    if args.curve_keys:  # encrypted; only the clients whose *.key is in the folder
        import zmq.auth
        from zmq.auth.thread import ThreadAuthenticator
        if not os.path.isdir(args.curve_keys):
            sys.exit(f"{name}: --curve-keys {args.curve_keys} is not a folder")
        auth = ThreadAuthenticator(ctx)
        auth.start()
        auth.configure_curve(domain="*", location=args.curve_keys)
        sock.curve_publickey, sock.curve_secretkey = zmq.auth.load_certificate(
            os.path.join(args.curve_keys, "server.key_secret"))
        sock.curve_server = True
    elif not any(h in args.bind for h in ("127.0.0.1", "localhost", "[::1]")):
        _log(name, f"{args.bind} accepts any client that can reach it: use --curve-keys DIR (fsi keys DIR) "
                   f"beyond loopback")
    sock.bind(args.bind)
    endpoint = sock.getsockopt(zmq.LAST_ENDPOINT).decode()
    if args.port_file:
        write_port_file(args.port_file, endpoint)
    _log(name, f"listening on {endpoint}")
    def drain_disconnects(wait_ms):
        while monitor.poll(wait_ms):
            wait_ms = 0
            event = recv_monitor_message(monitor)
            peer = peer_of_fd.pop(event.get("value"), None)
            if event.get("event") == zmq.EVENT_DISCONNECTED and peer is not None:
                server.peer_gone(peer)

    del _SIGNALLED[:]
    old = {s: signal.signal(s, _on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    code = 0
    try:
        idle_since = _time.monotonic()
        while not _SIGNALLED:
            ready = sock.poll(200)
            drain_disconnects(0)
            if not ready:
                if args.idle_timeout > 0 and _time.monotonic() - idle_since > args.idle_timeout:
                    _log(name, f"no request for {args.idle_timeout:g} s, exiting")
                    code = 3
                    break
                continue
            frames = sock.recv_multipart(copy=False)
            idle_since = _time.monotonic()
            if len(frames) < 2:
                continue  # no identity: nobody to answer
            peer = frames[0].bytes
            # A closed connection whose event is still in flight must be seen before a new
            # peer's request is judged (a coupler restarted after its predecessor died).
            known = peer in peer_of_fd.values()
            drain_disconnects(100 if not known and peer_of_fd else 0)
            try:
                fd = frames[-1].get(zmq.SRCFD)
            except zmq.ZMQError:
                fd = -1
            if fd >= 0:
                for f in [f for f, p in peer_of_fd.items() if p == peer and f != fd]:
                    del peer_of_fd[f]
                peer_of_fd[fd] = peer
            envelope, payload = _split_envelope([f.bytes for f in frames])
            data, stop = server.handle_frames(payload, peer)
            sock.send_multipart(envelope + [data])
            if stop:
                break
        if _SIGNALLED:
            _log(name, f"interrupted by signal {_SIGNALLED[0]}, exiting")
            code = 130
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        sock.disable_monitor()
        monitor.close(linger=0)
        sock.close(linger=1000 if code == 0 else 0)
        if auth is not None:
            auth.stop()
    return code
