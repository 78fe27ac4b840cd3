#!/usr/bin/env python3
"""Integration tests: the three processes over loopback (see harness.py)."""
import math
import re
import os
import signal
import subprocess
import sys
import time

import zmq

from harness import beta_limit, loosely_coupled_added_mass, main, monolithic_added_mass, probes, recurrence, summary


def end_to_end(env):
    """fsi run sdof_model for gamma in {0, 1, 10, 100}: the BDF1 recurrence to round-off."""
    for gamma in (0, 1, 10, 100):
        out = env.out(f"sdof_g{gamma}")
        code, log = env.fsi("sdof_model.yaml", out, f"coupling.gamma_n1={gamma}")
        assert code == 0, log
        s = summary(out)
        assert s["status"] == "completed" and s["steps"] == 500 and s["coupling_iterations"] == 500, s
        for key in ("solid_compute", "solid_messaging", "fluid_compute", "fluid_messaging", "total"):
            assert key in s["wall_time"], s["wall_time"]
        d = probes(os.path.join(out, "probes.csv"))["solid.d_x"]
        ref = recurrence(gamma, 500)
        err = max(abs(a - b) for a, b in zip(d, ref))
        assert len(d) == 500 and err < 1e-14, (gamma, err)
        with open(os.path.join(out, "iterations.csv")) as f:
            assert len(f.readlines()) == 501
        print(f"gamma={gamma}: max |d - recurrence| = {err:.2e}, d(10) = {d[-1]:.6f}")


def python_solid(env):
    """The Python solid in place of solid_server gives the same history to round-off."""
    cpp, py = env.out("cpp"), env.out("py")
    sets = ("coupling.gamma_n1=10",)
    code, log = env.fsi("sdof_model.yaml", cpp, *sets)
    assert code == 0, log
    solid = f"/usr/bin/python3 {env.source}/python/sdof_solid.py --proto-dir {env.proto}"
    code, log = env.fsi("sdof_model.yaml", py, *sets, extra=("--solid-command", solid))
    assert code == 0, log
    assert summary(py)["servers"]["solid"]["name"] == "python sdof_solid.py", summary(py)["servers"]
    a, b = probes(os.path.join(cpp, "probes.csv")), probes(os.path.join(py, "probes.csv"))
    for key in ("solid.d_x", "solid.v_x"):
        err = max(abs(x - y) for x, y in zip(a[key], b[key]))
        assert len(a[key]) == len(b[key]) == 500 and err <= 1e-15, (key, err)
        print(f"{key}: max |C++ - Python| = {err:.1e}")


def python_solid_3d(env):
    """A 3D external solid: the Python solid's rigid plate (quadrilateral faces) against the
    surrogate fluid's plate of triangles, over sockets, gives the C++ solid's history to
    round-off, and the interface vectors carry 3 values per node."""
    cpp, py = env.out("cpp3d"), env.out("py3d")
    code, log = env.fsi("sdof_3d.yaml", cpp, "time.output_every=0")
    assert code == 0, log
    solid = f"/usr/bin/python3 {env.source}/python/sdof_solid.py --proto-dir {env.proto}"
    code, log = env.fsi("sdof_3d.yaml", py, "time.output_every=0", extra=("--solid-command", solid))
    assert code == 0, log
    s = summary(py)
    assert s["servers"]["solid"]["name"] == "python sdof_solid.py", s["servers"]
    assert s["interface"]["solid_nodes"] == 9 and s["interface"]["fluid_nodes"] == 16, s["interface"]
    a, b = probes(os.path.join(cpp, "probes.csv")), probes(os.path.join(py, "probes.csv"))
    for key in ("solid.d_z", "solid.v_z"):
        err = max(abs(x - y) for x, y in zip(a[key], b[key]))
        assert len(a[key]) == len(b[key]) == 500 and err <= 1e-13, (key, err)
        print(f"{key}: max |C++ - Python| = {err:.1e}")
    assert max(abs(x) for x in b["solid.d_x"] + b["solid.d_y"]) == 0.0


def killed_server(env):
    """A server killed mid-run: the coupler names it, exits non-zero within seconds, and
    every accepted step is on disk."""
    for victim in ("solid", "fluid"):
        solid, solid_ep = env.start_server("solid")
        fluid, fluid_ep = env.start_server("fluid")
        out = env.out(f"killed_{victim}")
        coupler = env.spawn([env.exe("coupler"), env.config("sdof_model.yaml"), "--solid", solid_ep, "--fluid",
                             fluid_ep, "--out", out, "--set", "time.end=4000"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        probe_file = os.path.join(out, "probes.csv")
        deadline = time.time() + 20
        while time.time() < deadline and (not os.path.exists(probe_file) or os.path.getsize(probe_file) < 20000):
            time.sleep(0.05)
        assert coupler.poll() is None, "the coupler finished before the kill"
        (solid if victim == "solid" else fluid).send_signal(signal.SIGKILL)
        t0 = time.time()
        try:
            output, _ = coupler.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            raise AssertionError("the coupler did not notice the dead peer within 10 s")
        elapsed = time.time() - t0
        assert coupler.returncode not in (0, None), coupler.returncode
        assert f"{victim} server" in output, output[-2000:]
        s = summary(out)
        assert s["status"] == "failed" and f"{victim} server" in s["reason"], s
        rows = len(probes(probe_file)["time"])
        assert rows == s["steps"] and rows > 100, (rows, s["steps"])
        print(f"{victim} killed: coupler exited {coupler.returncode} after {elapsed:.2f} s with {rows} steps on disk; "
              f"reason: {s['reason']}")
        env.close()
        env.procs.clear()


def bad_messages(env):
    """Malformed, wrong-version, out-of-order, wrong-size and NaN requests get error
    replies; the server stays up and then serves a normal session."""
    from fsi.v1 import coupling_pb2 as pb
    server, endpoint = env.start_server("solid")
    ctx = zmq.Context.instance()
    sock = ctx.socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.RCVTIMEO, 5000)
    sock.connect(endpoint)

    def call(payload):
        sock.send(payload if isinstance(payload, bytes) else payload.SerializeToString())
        reply = pb.Reply()
        reply.ParseFromString(sock.recv())
        return reply

    def request(seq, **kw):
        r = pb.Request(protocol_version=1, sequence=seq)
        for k, v in kw.items():
            getattr(r, k).CopyFrom(v)
        return r

    def expect_error(reply, code, text):
        assert reply.WhichOneof("body") == "error", reply
        assert reply.error.code == code, reply
        assert text in reply.error.message, reply.error.message
        print(f"  {pb.Error.Code.Name(code)}: {reply.error.message}")

    expect_error(call(b"\xff\x00garbage that is not protobuf\x13"), pb.Error.MALFORMED, "not a fsi.v1.Request")
    r = request(1, hello=pb.Hello(client_name="t"))
    r.protocol_version = 2
    expect_error(call(r), pb.Error.VERSION_MISMATCH, "version")
    expect_error(call(pb.Request(protocol_version=1, sequence=2)), pb.Error.MALFORMED, "no body")
    # A request without bulk data is refused above its size limit before it is parsed (a 2 MiB Hello).
    huge = request(2, hello=pb.Hello(client_name="x" * (2 << 20)))
    expect_error(call(huge), pb.Error.MALFORMED, "a 'hello' request of 2097")
    step = pb.SolveStep(time=0.02, dt=0.02, step=1, iteration=1, interface_force=[1.0, 0.0])
    expect_error(call(request(3, solve_step=step)), pb.Error.BAD_SEQUENCE, "before 'configure'")
    with open(env.config("sdof_model.yaml")) as f:
        text = f.read()
    bad_cfg = pb.Configure(dt=0.02, end_time=1, scene_text=text, scene_path="sdof_model.yaml", section="solid",
                           overrides=["solid.masss=3"])
    expect_error(call(request(4, configure=bad_cfg)), pb.Error.INVALID_ARGUMENT, "solid.masss")
    hello = call(request(5, hello=pb.Hello(client_name="t")))
    assert hello.hello.kind == pb.SERVER_KIND_SOLID and hello.sequence == 5, hello
    cfg = pb.Configure(dt=0.02, end_time=1, scene_text=text, scene_path="sdof_model.yaml", section="solid",
                       interface_damping=10)
    assert call(request(6, configure=cfg)).configure.interface_nodes == 1
    wrong = pb.SolveStep(time=0.02, dt=0.02, step=1, iteration=1, interface_force=[1.0, 0.0, 3.0])
    expect_error(call(request(7, solve_step=wrong)), pb.Error.INVALID_ARGUMENT, "has 3 values, expected 2")
    nan = pb.SolveStep(time=0.02, dt=0.02, step=1, iteration=1, interface_force=[float("nan"), 0.0])
    expect_error(call(request(8, solve_step=nan)), pb.Error.INVALID_ARGUMENT, "not finite")
    zero_dt = pb.SolveStep(time=0.02, dt=0.0, step=1, iteration=1, interface_force=[1.0, 0.0])
    expect_error(call(request(8, solve_step=zero_dt)), pb.Error.INVALID_ARGUMENT, "dt must be positive, got 0")
    ok = call(request(9, solve_step=step))
    d = ok.solid_step.interface_displacement[0]
    expected = 1.0 / (1 / 0.02 ** 2 + (2.5 + 10) / 0.02 + 10)
    assert abs(d - expected) < 1e-15, (d, expected)
    assert call(request(10, stop=pb.Stop(reason="done"))).WhichOneof("body") == "stop"
    assert server.wait(timeout=5) == 0


def strict_protocol(env):
    """Exactly one frame after the envelope; a failed Configure leaves the server
    unconfigured (and the next request is told why); non-finite or negative Configure
    numbers are refused naming the field."""
    from fsi.v1 import coupling_pb2 as pb
    server, endpoint = env.start_server("solid")
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.RCVTIMEO, 5000)
    sock.connect(endpoint)

    def call(*frames):
        sock.send_multipart([b"", *[f if isinstance(f, bytes) else f.SerializeToString() for f in frames]])
        parts = sock.recv_multipart()
        assert parts[0] == b"" and len(parts) == 2, parts
        reply = pb.Reply()
        reply.ParseFromString(parts[1])
        return reply

    def expect_error(reply, code, text):
        assert reply.WhichOneof("body") == "error" and reply.error.code == code, reply
        assert text in reply.error.message, reply.error.message
        print(f"  {pb.Error.Code.Name(code)}: {reply.error.message}")

    hello = pb.Request(protocol_version=1, sequence=1, hello=pb.Hello(client_name="t"))
    expect_error(call(hello, b"extra"), pb.Error.MALFORMED, "2 frames after the envelope, expected exactly 1")
    expect_error(call(hello, hello), pb.Error.MALFORMED, "2 frames after the envelope")
    assert call(hello).hello.kind == pb.SERVER_KIND_SOLID
    with open(env.config("sdof_model.yaml")) as f:
        text = f.read()

    def configure(seq, **kw):
        args = dict(dt=0.02, end_time=1, scene_text=text, scene_path="sdof_model.yaml", section="solid")
        args.update(kw)
        c = pb.Configure(**args)
        return pb.Request(protocol_version=1, sequence=seq, configure=c)

    assert call(configure(2)).configure.interface_nodes == 1
    for seq, (field, value) in enumerate((("interface_damping", float("nan")), ("interface_damping", -1.0),
                                          ("end_time", float("inf"))), start=3):
        expect_error(call(configure(seq, **{field: value})), pb.Error.INVALID_ARGUMENT, field)
    step = pb.SolveStep(time=0.02, dt=0.02, step=1, iteration=1, interface_force=[1.0, 0.0])
    expect_error(call(pb.Request(protocol_version=1, sequence=9, solve_step=step)), pb.Error.BAD_SEQUENCE,
                 "the last 'configure' failed (configure: end_time must be finite")
    assert call(configure(10)).configure.interface_nodes == 1
    assert call(pb.Request(protocol_version=1, sequence=11, solve_step=step)).WhichOneof("body") == "solid_step"
    assert call(pb.Request(protocol_version=1, sequence=12, stop=pb.Stop(reason="done"))).WhichOneof("body") == "stop"
    assert server.wait(timeout=5) == 0


def sessions(env):
    """One coupler at a time: Hello opens a session; another client is answered BUSY naming
    it; the session ends when its client's connection closes, and the next client must
    configure again."""
    from fsi.v1 import coupling_pb2 as pb
    server, endpoint = env.start_server("solid")
    ctx = zmq.Context.instance()

    def client():
        sock = ctx.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.RCVTIMEO, 5000)
        sock.connect(endpoint)
        return sock

    def call(sock, seq, **body):
        r = pb.Request(protocol_version=1, sequence=seq)
        for k, v in body.items():
            getattr(r, k).CopyFrom(v)
        sock.send_multipart([b"", r.SerializeToString()])
        reply = pb.Reply()
        reply.ParseFromString(sock.recv_multipart()[-1])
        return reply

    with open(env.config("sdof_model.yaml")) as f:
        text = f.read()
    cfg = pb.Configure(dt=0.02, end_time=1, scene_text=text, scene_path="sdof_model.yaml", section="solid")
    a, b = client(), client()
    assert call(a, 1, hello=pb.Hello(client_name="coupler A", session="s-a")).hello.kind == pb.SERVER_KIND_SOLID
    assert call(a, 2, configure=cfg).configure.interface_nodes == 1
    for body in (dict(hello=pb.Hello(client_name="coupler B", session="s-b")), dict(configure=cfg)):
        r = call(b, 1, **body)
        assert r.WhichOneof("body") == "error" and r.error.code == pb.Error.BUSY, r
        assert "session 's-a' with 'coupler A'" in r.error.message, r.error.message
    print("  BUSY:", r.error.message)
    a.close(0)
    deadline = time.time() + 5
    while True:
        r = call(b, 2, hello=pb.Hello(client_name="coupler B", session="s-b"))
        if r.WhichOneof("body") == "hello" or time.time() > deadline:
            break
        time.sleep(0.05)
    assert r.WhichOneof("body") == "hello", f"session not released after its client left: {r}"
    step = pb.SolveStep(time=0.02, dt=0.02, step=1, iteration=1, interface_force=[1.0, 0.0])
    r = call(b, 3, solve_step=step)
    assert r.error.code == pb.Error.BAD_SEQUENCE, r  # the old configuration went with its session
    assert call(b, 4, configure=cfg).configure.interface_nodes == 1
    assert call(b, 5, solve_step=step).WhichOneof("body") == "solid_step"
    assert call(b, 6, stop=pb.Stop(reason="done")).WhichOneof("body") == "stop"
    assert server.wait(timeout=5) == 0


def added_mass(env):
    """Pure added mass over loopback: converges below the closed-form limit of beta and is
    reported as diverged above it, for Algorithm 1 and Algorithm 2 at several gamma."""
    m, c, k, m_a, dt = 1.0, 0.5, 4.0, 10.0, 0.01
    for algorithm, gamma in ((1, 0), (1, 100), (2, 10), (2, 100), (2, 300)):
        limit = beta_limit(algorithm, gamma, m, c, k, m_a, dt)
        for factor, want_code, want in ((0.9, 0, "completed"), (1.1, 2, "diverged")):
            out = env.out(f"am_{algorithm}_{gamma}_{factor}")
            code, log = env.fsi("added_mass.yaml", out, f"coupling.algorithm={algorithm}",
                                f"coupling.gamma_n1={gamma}", f"coupling.relaxation={factor * limit}")
            s = summary(out)
            assert code == want_code and s["status"] == want, (algorithm, gamma, factor, code, s["status"], s["reason"])
        print(f"algorithm {algorithm}, gamma {gamma}: beta limit {limit:.4f}: 0.9x converged, 1.1x diverged "
              f"({s['reason'][:60]}...)")


def options_3d(env):
    """The coupling options on the non-matching 3D plates of sdof_3d.yaml (area 1, the force
    along z) over loopback, against closed forms: the appendix problem iterated to convergence
    with IQN-IMVJ (Algorithm 2, gamma 10: the monolithic recurrence, gamma cancelling); the added-mass problem (m 1, m_a 10, beta 0.5, above the constant
    relaxation limit) converged by IQN-IMVJ, serial, and by the parallel scheme with IQN-ILS
    and IQN-IMVJ, to its monolithic BDF1 solution; coupling.robin_auto loosely coupled, serial
    and parallel, step by step the recurrence of the scheme, stable at m_a = 1.8 m and
    diverging at m_a = 2.2 m (limit m_a < 2 m)."""
    def run(name, *sets, want="completed"):
        out = env.out(name)
        code, log = env.fsi("sdof_3d.yaml", out, "time.output_every=0", *sets)
        s = summary(out)
        assert s["status"] == want, (name, code, s["status"], s["reason"], log[-2000:])
        assert s["interface"]["solid_nodes"] == 9 and s["interface"]["fluid_nodes"] == 16, s["interface"]
        p = probes(os.path.join(out, "probes.csv"))
        assert max(abs(x) for x in p["solid.d_x"] + p["solid.d_y"]) == 0.0, name
        return p["solid.d_z"], s

    d, _ = run("imvj_appendix", "coupling.acceleration=iqn-imvj", "coupling.iterations.max=20",
               "coupling.iterations.tolerance=1e-12", "time.end=2")
    ref = recurrence(0, 100)  # converged, gamma_N1 v cancels: the monolithic recurrence
    err = max(abs(a - b) for a, b in zip(d, ref))
    assert len(d) == 100 and err < 1e-12, err
    print(f"IQN-IMVJ, appendix problem converged: max |d_z - recurrence(gamma 0)| = {err:.1e}")

    am = ("time.end=0.2", "time.dt=0.01", "solid.mass=1", "solid.damping=0.5", "solid.stiffness=4",
          "fluid.added_mass=10", "fluid.force=[0, 0, 1]", "coupling.gamma_n1=10", "coupling.relaxation=0.5",
          "coupling.iterations.max=100", "coupling.iterations.tolerance=1e-12")
    ref = monolithic_added_mass(20)
    for name, sets in (("imvj_alg1", ("coupling.algorithm=1", "coupling.acceleration=iqn-imvj")),
                       ("imvj_alg2_svd", ("coupling.acceleration=iqn-imvj",
                                          "coupling.iqn={imvj: {restart: rs-svd, chunk_size: 3}, filter_type: qr3}")),
                       ("parallel_ils", ("coupling.scheme=parallel", "coupling.acceleration=iqn-ils")),
                       ("parallel_imvj", ("coupling.scheme=parallel", "coupling.acceleration=iqn-imvj"))):
        d, s = run(name, *am, *sets)
        err = max(abs(a - b) for a, b in zip(d, ref))
        assert len(d) == 20 and err < 1e-12 * max(map(abs, ref)), (name, err)
        print(f"{name}: added mass, max |d_z - monolithic| = {err:.1e} (d_z(0.2) = {d[-1]:.4e}), "
              f"{s['coupling_iterations']} iterations")

    m, dt = 1.0, 0.01
    for parallel in (False, True):
        for factor, want in ((0.9, "completed"), (1.1, "diverged")):
            m_a = factor * 2 * m
            name = f"robin_auto_{'parallel' if parallel else 'serial'}_{factor}"
            d, s = run(name, "coupling.algorithm=2", "coupling.gamma_n1=1", "coupling.robin_auto=solid",
                       "coupling.relaxation=1", "coupling.iterations.max=1", "coupling.iterations.tolerance=0",
                       "coupling.force_limit=1e6", f"coupling.scheme={'parallel' if parallel else 'serial'}",
                       "time.dt=0.01", "time.end=6", "solid.mass=1", "solid.damping=0", "solid.stiffness=0",
                       f"fluid.added_mass={m_a!r}", "fluid.force=[0, 0, 1]", want=want)
            ref = loosely_coupled_added_mass(parallel, m, m_a, m, dt, 600)
            # round-off accumulates over 600 steps of a recurrence whose error decays by |z| = 0.9
            # (serial) or sqrt(0.9) per step: 1e-12 relative measured, 5e-12 asserted
            err = max(abs(a - b) / (1 + abs(b)) for a, b in zip(d, ref))
            assert err < 5e-12, (name, err)
            assert want != "completed" or len(d) == 600, (name, len(d))
            assert want != "diverged" or "force_limit" in s["reason"], (name, s["reason"])
            print(f"{name}: {len(d)} steps, {s['status']}, max |d_z - recurrence| / (1 + |d|) = {err:.1e}")


def config_errors(env):
    """Bad scenes fail early with the key and the line, and a non-zero exit."""
    code, log = env.fsi("sdof_model.yaml", env.out("typo"), "solid.masss=3")
    assert code != 0 and "solid.masss" in log, log
    bad = env.out("not_a_scene.yaml")
    with open(bad, "w") as f:
        f.write("solid: [1, 2\n  fluid: }\n")
    code, log = env.run([env.exe("fsi"), "run", bad, "--out", env.out("bad")])
    assert code != 0 and "not_a_scene.yaml:" in log, log
    code, log = env.fsi("sdof_model.yaml", env.out("type"), "coupling.relaxation=fast")
    assert code != 0 and "'coupling.relaxation' must be a number" in log, log
    print("config errors reported:", [l for l in log.splitlines() if "relaxation" in l][-1][-90:])
    # A 3D solid (plate) with a 2D fluid: refused at the interface exchange, naming both servers.
    with open(env.config("sdof_3d.yaml")) as f:
        text = f.read()
    fluid = text.index("\nfluid:")
    mixed = env.out("mixed_dimensions.yaml")
    with open(mixed, "w") as f:
        f.write(text[:fluid] + "\nfluid:\n  model: surrogate\n  force: [0, 1.282]\n  added_mass: 0.0\n")
    out = env.out("mixed")
    code, log = env.run([env.exe("fsi"), "run", mixed, "--out", out])
    reason = summary(out)["reason"]
    assert code == 1 and "interface mismatch: the solid's interface is 3D (3 values per node), the fluid's 2D" in reason \
        and "solid 'fsi solid_server" in reason and "fluid 'fsi fluid_server" in reason, (code, reason)
    print("mixed dimensions refused:", reason[:160])
    # The fluid's plate twice as long as the solid's: the two face sets do not end on the same
    # boundary edges; refused at configure, naming both servers and the edge.
    out = env.out("larger_fluid")
    code, log = env.fsi("sdof_3d.yaml", out, "time.output_every=0", "fluid.surface.size=[1, 2]")
    reason = summary(out)["reason"]
    assert code == 1 and "interface mismatch: the solid's interface has a boundary edge" in reason \
        and "solid 'fsi solid_server" in reason and "fluid 'fsi fluid_server" in reason, (code, reason)
    print("face sets of different extent refused:", reason[:240])


def interrupt(env):
    """Ctrl-C on the launcher stops every process it started; the summary says so."""
    out = env.out("interrupted")
    p = env.spawn([env.exe("fsi"), "run", env.config("sdof_model.yaml"), "--out", out, "--set", "time.end=4000"],
                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    probe_file = os.path.join(out, "probes.csv")
    deadline = time.time() + 20
    while time.time() < deadline and not os.path.exists(probe_file):
        time.sleep(0.05)
    time.sleep(0.3)
    p.send_signal(signal.SIGINT)
    try:
        p.communicate(timeout=15)
    except subprocess.TimeoutExpired:
        raise AssertionError("the launcher did not stop within 15 s of Ctrl-C")
    assert p.returncode == 130, p.returncode
    s = summary(out)
    assert s["status"] == "interrupted" and "interrupted" in s["reason"], s
    leftovers = []
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as f:
                    if out.encode() in f.read():
                        leftovers.append(pid)
            except OSError:
                pass
    assert not leftovers, f"processes left running: {leftovers}"
    print(f"interrupted after {s['steps']} steps; no process left")


def curve(env):
    """ZeroMQ CURVE beyond loopback: `fsi keys` makes the key folder; a server started with
    --curve-keys serves the coupler holding the folder's client key, and refuses, with a
    clear error on the client's side, a client without keys or with other keys."""
    from fsi.v1 import coupling_pb2 as pb
    keys, other = env.out("keys"), env.out("other")
    for folder in (keys, other):
        code, text = env.run([env.exe("fsi"), "keys", folder], timeout=20)
        assert code == 0, text
    for name in ("server.key", "server.key_secret", "coupler.key", "coupler.key_secret"):
        assert os.path.exists(os.path.join(keys, name)), name
    for name in ("server.key_secret", "coupler.key_secret"):
        mode = os.stat(os.path.join(keys, name)).st_mode & 0o777
        assert mode == 0o600, f"{name} has mode {oct(mode)}"
    code, text = env.run([env.exe("fsi"), "keys", keys], timeout=20)
    assert code == 1 and "already holds keys" in text, text

    # pyzmq reads the same certificates (zmq.auth), so a Python coupler can talk to it.
    import zmq.auth
    server, endpoint = env.start_server("solid", ["--curve-keys", keys])
    client_public, client_secret = zmq.auth.load_certificate(os.path.join(keys, "coupler.key_secret"))
    server_public, _ = zmq.auth.load_certificate(os.path.join(keys, "server.key"))
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.RCVTIMEO, 5000)
    sock.curve_publickey, sock.curve_secretkey, sock.curve_serverkey = client_public, client_secret, server_public
    sock.connect(endpoint)
    r = pb.Request(protocol_version=1, sequence=1, hello=pb.Hello(client_name="python", session="py"))
    sock.send_multipart([b"", r.SerializeToString()])
    reply = pb.Reply()
    reply.ParseFromString(sock.recv_multipart()[-1])
    assert reply.hello.kind == pb.SERVER_KIND_SOLID, reply
    sock.close(0)

    # The coupler without keys, with another folder's keys, and with a folder that does not exist.
    fluid, fluid_endpoint = env.start_server("fluid")
    base = [env.exe("coupler"), env.config("sdof_model.yaml"), "--solid", endpoint, "--fluid", fluid_endpoint,
            "--connect-timeout", "5"]
    for extra, expected in (([], "it requires CURVE authentication (--curve-keys)"),
                            (["--curve-keys", other], "CURVE authentication failed with the keys of " + other),
                            (["--curve-keys", env.out("none")], "is not a folder")):
        start = time.time()
        code, text = env.run(base + ["--out", env.out(f"refused{len(extra)}_{expected[:3]}")] + extra, timeout=30)
        assert code == 1 and expected in text, (code, text)
        print(f"  refused in {time.time() - start:.2f} s: {expected}")
    env.kill(server)
    env.kill(fluid)

    # A whole run with keys, the Python example solid included: same numbers as without.
    plain, secured = env.out("plain"), env.out("secured")
    code, text = env.fsi("sdof_model.yaml", plain, extra=["--solid-command", f"{sys.executable} "
                                                          f"{env.source}/python/sdof_solid.py --proto-dir {env.proto}"])
    assert code == 0, text
    code, text = env.fsi("sdof_model.yaml", secured, extra=["--curve-keys", keys, "--solid-command",
                                                            f"{sys.executable} {env.source}/python/sdof_solid.py "
                                                            f"--proto-dir {env.proto}"])
    assert code == 0, text
    with open(os.path.join(plain, "probes.csv")) as a, open(os.path.join(secured, "probes.csv")) as b:
        assert a.read() == b.read(), "probes.csv differs with CURVE"
    with open(os.path.join(secured, "fluid_server.log")) as f:
        assert "CURVE: encrypted, 1 authorised client key(s)" in f.read()

    # Beyond loopback without keys: the server says so.
    log = env.out("open.log")
    with open(log, "w") as f:
        p = env.spawn([env.exe("solid_server"), "--bind", "tcp://0.0.0.0:*", "--port-file", env.out("open.port"),
                       "--idle-timeout", "1"], stdout=f, stderr=subprocess.STDOUT)
    p.wait(timeout=15)
    with open(log) as f:
        text = f.read()
    assert "accepts any client that can reach it: use --curve-keys DIR" in text, text
    print("  CURVE run identical to the plain one; open bind warned")


def misbehaving_solid(env):
    """An external solid that never answers Hello, never writes its port file, answers as
    a fluid or with another protocol version: the launcher stops, names the cause, leaves
    a final summary.json and no process behind, within its waits (--start-timeout 8 here:
    port file 8 s, Hello 4 s; the defaults are 60 s and 30 s; 1 s to exit after a failed run)."""
    fake = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fake_solid.py")
    expected = {"silent": "no reply from solid server at ", "noport": "did not report its endpoint within 8 s",
                "wrongkind": "is a SERVER_KIND_FLUID server, expected a SERVER_KIND_SOLID server",
                "oldversion": "speaks protocol version 7 (HelloReply.protocol_version), this coupler 1"}
    for mode, text in expected.items():
        out = env.out(mode)
        start = time.time()
        code, log = env.fsi("sdof_model.yaml", out, timeout=120,
                            extra=["--start-timeout", "8", "--solid-command",
                                   f"{sys.executable} {fake} --mode {mode} --proto-dir {env.proto}"])
        elapsed = time.time() - start
        assert code == 1, (mode, code, log)
        s = summary(out)
        assert s["status"] == "failed" and text in s["reason"], (mode, s)
        assert text in log, (mode, log)
        if mode == "silent":
            assert re.search(r"within (39\d\d|4000) ms", s["reason"]), s  # Hello waits half of --start-timeout
        leftovers = []
        for pid in os.listdir("/proc"):
            if pid.isdigit():
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        if out.encode() in f.read():
                            leftovers.append(pid)
                except OSError:
                    pass
        assert not leftovers, (mode, leftovers)
        print(f"  {mode}: exit 1 after {elapsed:.1f} s: {s['reason']}")


def bad_replies(env):
    """The coupler checks every field of every reply: an external solid whose interface
    mesh, step results, probes, timings, checkpoint or protocol version are wrong stops the
    run naming the field (exit 1, failed; non-finite results: exit 2, diverged)."""
    fake = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fake_solid.py")
    cases = {
        "negmeasure": (1, "lumped_measure of node 0 is -1 (must be finite and > 0"),
        "nancoord": (1, "coordinate y of node 0 is not finite"),
        "dupids": (1, "node id 0 appears twice"),
        "nodecount": (1, "announced 3 interface nodes (ConfigureReply.interface_nodes) but its interface mesh has 1"),
        "shortdisp": (1, "sent 1 values for 'interface_displacement', expected 2"),
        "nandisp": (2, "sent a non-finite 'interface_displacement' at node 0"),
        "commaprobe": (1, "sent a probe named 'd_x,d_y'"),
        "nancompute": (1, "with compute_seconds = nan (must be finite and >= 0)"),
        "emptystate": (1, "answered save_checkpoint of step 5 with an empty state"),
        "badversion": (1, "version 2"),
    }
    for mode, (expected_code, text) in cases.items():
        out = env.out(mode)
        code, log = env.fsi("sdof_model.yaml", out, "time.end=0.2", "time.checkpoint_every=5", timeout=60,
                            extra=["--recover", "0", "--solid-command",
                                   f"{sys.executable} {fake} --mode {mode} --proto-dir {env.proto}"])
        s = summary(out)
        assert code == expected_code and text in s["reason"], (mode, code, s.get("reason"), log[-2000:])
        assert s["status"] == ("diverged" if expected_code == 2 else "failed"), (mode, s)
        print(f"  {mode}: exit {code}, {s['reason'][:140]}")


if __name__ == "__main__":
    main({f.__name__: f for f in (end_to_end, python_solid, python_solid_3d, killed_server, bad_messages, strict_protocol, sessions, added_mass, options_3d,
                                  config_errors, interrupt, curve, misbehaving_solid, bad_replies)})
