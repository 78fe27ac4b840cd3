#!/usr/bin/python3
"""fsi.server's sessions and exit codes, over real sockets, as the C++ servers behave
(proto/README.md, "Sessions"):

- a solve_step with dt <= 0 or NaN is INVALID_ARGUMENT (not the solid's ZeroDivisionError);
- a second client during a session gets BUSY naming the session, its client and since when,
  and the run of the first goes on undisturbed;
- when the session's connection closes (the coupler died) the server forgets its
  configuration and the next client's Hello opens a new session;
- serve()'s exit code: 0 after Stop, 3 after --idle-timeout, 130 after SIGTERM, also when the
  signal arrives during a request (the request is answered first; it used to be answered as
  an INTERNAL error and the server went on serving).

    test_server_sessions.py --source SRC
"""
import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--source", required=True)
a = ap.parse_args()
SRC = Path(a.source).resolve()
sys.path.insert(0, str(SRC / "python"))

import zmq  # noqa: E402

from fsi.v1 import coupling_pb2 as pb  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


SCENE = """
solid: {model: sdof, mass: 1.0, damping: 0.0, stiffness: 10.0}
"""
SLOW_SOLID = """
import sys, time
sys.path.insert(0, sys.argv.pop(1))
import fsi.server as fs

class Slow(fs.Solid):
    def configure(self, section, dt, end_time, interface_damping, output_dir):
        return fs.Interface(coordinates=[0.0, 0.0], lumped_measure=[1.0])

    def solve_step(self, step, time_, dt, iteration, force):
        print("solving", flush=True)
        time.sleep(1.5)
        return fs.zeros(1), fs.zeros(1)

sys.exit(fs.serve(Slow))
"""


class Client:
    """A coupler's side: one DEALER socket, numbered requests."""

    def __init__(self, endpoint, name):
        self.sock = zmq.Context.instance().socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self.name, self.seq = name, 0

    def send(self, **body):
        self.seq += 1
        req = pb.Request(protocol_version=1, sequence=self.seq)
        (key, value), = body.items()
        getattr(req, key).CopyFrom(value)
        self.sock.send_multipart([b"", req.SerializeToString()])

    def recv(self, timeout=10.0):
        if not self.sock.poll(int(timeout * 1000)):
            raise TimeoutError(f"{self.name}: no reply in {timeout} s")
        frames = self.sock.recv_multipart()
        reply = pb.Reply()
        reply.ParseFromString(frames[-1])
        return reply

    def call(self, timeout=10.0, **body):
        self.send(**body)
        return self.recv(timeout)

    def hello(self, session):
        return self.call(hello=pb.Hello(client_name=self.name, session=session))

    def configure(self):
        return self.call(configure=pb.Configure(dt=0.1, end_time=1.0, scene_text=SCENE, section="solid"))

    def solve(self, step, timeout=10.0):
        return self.call(timeout, solve_step=pb.SolveStep(time=0.1 * step, dt=0.1, step=step, iteration=1,
                                                          interface_force=[1.0, 0.0]))

    def close(self):
        self.sock.close(linger=0)


def start(work, argv):
    port = work / f"port{time.monotonic_ns()}"
    p = subprocess.Popen([sys.executable, *argv, "--bind", "tcp://127.0.0.1:*", "--port-file", str(port)],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and not (port.exists() and port.read_text().strip()):
        time.sleep(0.05)
    return p, port.read_text().strip()


def error(reply):
    return (pb.Error.Code.Name(reply.error.code), reply.error.message) if reply.HasField("error") else None


def finish(p, timeout=10):
    try:
        code = p.wait(timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        code = "still running"
    return code, p.stdout.read()


with tempfile.TemporaryDirectory() as tmp:
    work = Path(tmp)
    sdof = [str(SRC / "python" / "sdof_solid.py")]

    # 1. BUSY for a second client; the first one's session goes on; Stop -> exit 0.
    p, endpoint = start(work, sdof)
    first, second = Client(endpoint, "coupler-1"), Client(endpoint, "coupler-2")
    r = first.hello("run-1")
    check(error(r) is None and r.hello.kind == pb.SERVER_KIND_SOLID, f"hello of the first client: {error(r)}")
    check(error(first.configure()) is None, "the first client configures")
    r1 = first.solve(1)
    r = second.hello("run-2")
    e = error(r)
    check(e is not None and e[0] == "BUSY" and "run-1" in e[1] and "coupler-1" in e[1] and "since" in e[1],
          f"a second client's hello gets BUSY naming the session: {e}")
    check(r.sequence == 1, f"the BUSY reply carries the second client's sequence: {r.sequence}")
    e = error(second.configure())
    check(e is not None and e[0] == "BUSY", f"and so does its configure: {e}")
    r2 = first.solve(1)
    check(error(r1) is None and error(r2) is None and
          list(r1.solid_step.interface_displacement) == list(r2.solid_step.interface_displacement),
          "the first client's session is undisturbed (a repeated solve gives the same answer)")
    for dt, what in ((0.0, "dt must be positive, got 0.0"), (float("nan"), "dt must be positive, got nan")):
        e = error(first.call(solve_step=pb.SolveStep(time=0.1, dt=dt, step=1, iteration=1, interface_force=[1.0, 0.0])))
        check(e is not None and e[0] == "INVALID_ARGUMENT" and what in e[1],
              f"solve_step with dt = {dt} is an INVALID_ARGUMENT naming dt, not an INTERNAL error of the solid: {e}")
    r = first.call(stop=pb.Stop(reason="completed"))
    check(error(r) is None and r.HasField("stop"), "stop is answered")
    code, log = finish(p)
    check(code == 0, f"exit code after Stop: {code} (expected 0)")
    first.close(), second.close()

    # 2. The session's connection closes (the coupler died): configuration forgotten, a new
    #    client's Hello opens a new session.
    p, endpoint = start(work, sdof)
    first = Client(endpoint, "coupler-1")
    first.hello("run-1"), first.configure()
    first.close()
    time.sleep(0.3)
    second = Client(endpoint, "coupler-2")
    r = second.hello("run-2")
    check(error(r) is None, f"after the first client's connection closed, a new Hello is served: {error(r)}")
    e = error(second.call(get_interface=pb.GetInterface()))
    check(e is not None and e[0] == "BAD_SEQUENCE" and "before 'configure'" in e[1],
          f"and the old configuration is forgotten: {e}")
    second.call(stop=pb.Stop(reason="completed"))
    code, log = finish(p)
    check(code == 0 and "connection closed" in log, f"exit {code}; the log says the session ended: "
          f"{[line for line in log.splitlines() if 'closed' in line]}")
    second.close()

    # 3. --idle-timeout -> exit 3; SIGTERM while idle -> 130.
    p, endpoint = start(work, sdof + ["--idle-timeout", "0.5"])
    code, log = finish(p)
    check(code == 3, f"exit code after --idle-timeout: {code} (expected 3)")
    p, endpoint = start(work, sdof)
    time.sleep(0.3)
    p.send_signal(signal.SIGTERM)
    code, log = finish(p)
    check(code == 130, f"exit code after SIGTERM while idle: {code} (expected 130)")

    # 4. SIGTERM during a request: answered, then exit 130.
    slow = work / "slow_solid.py"
    slow.write_text(SLOW_SOLID)
    p, endpoint = start(work, [str(slow), str(SRC / "python")])
    c = Client(endpoint, "coupler")
    c.hello("run"), c.configure()
    c.send(solve_step=pb.SolveStep(time=0.1, dt=0.1, step=1, iteration=1, interface_force=[0.0, 0.0]))
    time.sleep(0.5)
    p.send_signal(signal.SIGTERM)
    try:
        r = c.recv(5)
        e = error(r)
    except TimeoutError as ex:
        r, e = None, str(ex)
    check(r is not None and e is None and r.HasField("solid_step"),
          f"SIGTERM during solve_step: the request is answered normally ({e})")
    code, log = finish(p)
    check(code == 130, f"then the server exits 130: {code}")
    c.close()

sys.exit(1 if failures else 0)
