#!/usr/bin/env python3
"""A misbehaving external solid for the launcher's and the coupler's tests.

Start-up faults: --mode silent (binds, writes the port file, never answers), noport (never
writes its port file), wrongkind (answers Hello as a fluid), oldversion (HelloReply
protocol_version 7). Reply faults, on top of the real Python SDOF solid
(python/sdof_solid.py): negmeasure, nancoord, dupids, nodecount, shortdisp, nandisp,
commaprobe, nancompute, emptystate, badversion (a Reply of version 2 at step 3)."""
import argparse
import os
import sys
import time

import zmq

p = argparse.ArgumentParser()
p.add_argument("--mode", required=True)
p.add_argument("--proto-dir", required=True)
p.add_argument("--source", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
p.add_argument("--bind", default="tcp://127.0.0.1:*")
p.add_argument("--port-file", default="")
a = p.parse_args()
sys.path.insert(0, a.proto_dir)
sys.path.insert(0, os.path.join(a.source, "python"))
from fsi.v1 import coupling_pb2 as pb  # noqa: E402
import sdof_solid  # noqa: E402

sock = zmq.Context().socket(zmq.REP)
sock.bind(a.bind)
if a.mode == "noport":
    time.sleep(3600)
with open(a.port_file + ".tmp", "w") as f:
    f.write(sock.getsockopt(zmq.LAST_ENDPOINT).decode() + "\n")
os.replace(a.port_file + ".tmp", a.port_file)
if a.mode == "silent":
    time.sleep(3600)

solid = sdof_solid.SdofSolid()
while True:
    req = pb.Request()
    req.ParseFromString(sock.recv())
    rep, stop = sdof_solid.handle(pb, solid, req)
    body, m = req.WhichOneof("body"), a.mode
    if body == "hello":
        if m == "oldversion":
            rep.hello.protocol_version = 7
        if m == "wrongkind":
            rep.hello.kind = pb.SERVER_KIND_FLUID
    elif body == "configure" and m == "nodecount":
        rep.configure.interface_nodes = 3
    elif body == "get_interface":
        if m == "negmeasure":
            rep.interface.lumped_measure[0] = -1.0
        if m == "nancoord":
            rep.interface.coordinates[1] = float("nan")
        if m == "dupids":
            rep.interface.node_ids.append(rep.interface.node_ids[0])
            rep.interface.coordinates.extend([1.0, 0.0])
            rep.interface.lumped_measure.append(1.0)
    elif body == "solve_step" and req.solve_step.step == 3:
        if m == "shortdisp":
            del rep.solid_step.interface_displacement[1:]
        if m == "nandisp":
            rep.solid_step.interface_displacement[0] = float("nan")
        if m == "nancompute":
            rep.compute_seconds = float("nan")
        if m == "badversion":
            rep.protocol_version = 2
    elif body == "accept_step" and m == "commaprobe":
        rep.accept.probes["d_x,d_y"] = 0.0
    elif body == "save_checkpoint" and m == "emptystate":
        rep.checkpoint.state = b""
    sock.send(rep.SerializeToString())
    if stop:
        break
