"""Process harness for integration tests: real processes on 127.0.0.1 with free ports,
always stopped (also on failure), every wait bounded by a timeout."""
import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import time


class Env:
    def __init__(self, argv):
        import argparse
        p = argparse.ArgumentParser()
        p.add_argument("--bin", required=True)
        p.add_argument("--proto", required=True)
        p.add_argument("--source", required=True)
        p.add_argument("--case", required=True)
        a = p.parse_args(argv)
        self.bin, self.proto, self.source, self.case = a.bin, a.proto, a.source, a.case
        sys.path.insert(0, self.proto)
        self.tmp = tempfile.mkdtemp(prefix=f"fsi_it_{self.case}_")
        self.procs = []

    def exe(self, name):
        return os.path.join(self.bin, name)

    def config(self, name):
        return os.path.join(self.source, "configs", name)

    def out(self, name):
        return os.path.join(self.tmp, name)

    def spawn(self, args, **kw):
        p = subprocess.Popen(args, start_new_session=True, **kw)
        self.procs.append(p)
        return p

    def start_server(self, kind, extra=()):
        self.counter = getattr(self, "counter", 0) + 1
        port_file = self.out(f"{kind}-{self.counter}.port")
        log = open(self.out(f"{kind}-{self.counter}.log"), "w")
        p = self.spawn([self.exe(f"{kind}_server"), "--bind", "tcp://127.0.0.1:*", "--port-file", port_file, *extra],
                       stdout=log, stderr=subprocess.STDOUT)
        deadline = time.time() + 15
        while time.time() < deadline:
            if os.path.exists(port_file):
                with open(port_file) as f:
                    endpoint = f.read().strip()
                if endpoint:
                    return p, endpoint
            if p.poll() is not None:
                raise AssertionError(f"{kind}_server exited with {p.returncode} before listening")
            time.sleep(0.02)
        raise AssertionError(f"{kind}_server did not report its endpoint within 15 s")

    def run(self, args, timeout=120):
        """Runs a command to completion (killed at the timeout); returns (code, stdout+stderr)."""
        p = self.spawn(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            out, _ = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill(p)
            raise AssertionError(f"timed out after {timeout} s: {' '.join(args)}")
        return p.returncode, out

    def fsi(self, scene, out, *sets, extra=(), timeout=120):
        args = [self.exe("fsi"), "run", self.config(scene), "--out", out, *extra]
        for s in sets:
            args += ["--set", s]
        return self.run(args, timeout)

    @staticmethod
    def kill(p):
        if p.poll() is None:
            try:
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=5)

    def close(self):
        for p in self.procs:
            self.kill(p)


def probes(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in (rows[0].keys() if rows else [])}


def summary(out_dir):
    with open(os.path.join(out_dir, "summary.json")) as f:
        return json.load(f)


def recurrence(gamma, steps, dt=0.02, m=1.0, c=2.5, k=10.0, F=1.282):
    """The seed paper's appendix: m a_{n+1} + (c+g) v_{n+1} + k d_{n+1} = F + g v_n (BDF1)."""
    d = v = 0.0
    out = []
    for _ in range(steps):
        dn = (F + gamma * v + m * (d / (dt * dt) + v / dt) + (c + gamma) * d / dt) / (m / (dt * dt) + (c + gamma) / dt + k)
        v = (dn - d) / dt
        d = dn
        out.append(d)
    return out


def beta_limit(algorithm, gamma, m, c, k, m_a, dt, measure=1.0):
    """Largest relaxation for which Dirichlet-Neumann iterations converge (see README)."""
    m_eff = m + c * dt + k * dt * dt
    return 2 * (m_eff + (gamma * measure * dt if algorithm == 2 else 0.0)) / (m_eff + m_a)


def monolithic_added_mass(steps, dt=0.01, m=1.0, m_a=10.0, c=0.5, k=4.0, F=1.0):
    """The monolithic BDF1 solution of (m + m_a) a + c v + k d = F from rest: what every
    converged coupling of the added-mass problem must give."""
    d = v = 0.0
    out = []
    M = m + m_a
    for _ in range(steps):
        dn = (F + M * (d / (dt * dt) + v / dt) + c * d / dt) / (M / (dt * dt) + c / dt + k)
        v = (dn - d) / dt
        d = dn
        out.append(d)
    return out


def loosely_coupled_added_mass(parallel, m, m_a, G, dt, steps):
    """One iteration per step (beta 1, predictor F_n), c = k = 0, Algorithm 2 with the solid's
    damping G / dt (G = gamma |Gamma| dt; coupling.robin_auto=solid: G = m): the solid's
    displacement step by step, serial (the fluid sees the new velocity) or parallel (the old)."""
    d = v = v_fluid = 0.0
    force = 1.0
    out = []
    for _ in range(steps):
        dn = (force + m * (d / (dt * dt) + v / dt) + G / dt * d / dt) / (m / (dt * dt) + G / dt / dt)
        vn = (dn - d) / dt
        v_in = v if parallel else vn
        force = 1 - m_a * (v_in - v_fluid) / dt + G / dt * v_in
        v_fluid, d, v = v_in, dn, vn
        out.append(d)
    return out


def main(cases):
    env = Env(sys.argv[1:])
    try:
        cases[env.case](env)
    finally:
        env.close()
    print(f"integration case '{env.case}' passed")
