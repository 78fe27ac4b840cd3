#!/usr/bin/env python3
"""A misbehaving external solid for the launcher's tests: --mode silent (binds, writes the
port file, never answers), noport (never writes its port file), wrongkind (answers Hello as
a fluid), oldversion (HelloReply.protocol_version 7)."""
import argparse, os, sys, time
import zmq
p = argparse.ArgumentParser()
p.add_argument("--mode", required=True)
p.add_argument("--proto-dir", required=True)
p.add_argument("--bind", default="tcp://127.0.0.1:*")
p.add_argument("--port-file", default="")
a = p.parse_args()
sys.path.insert(0, a.proto_dir)
from fsi.v1 import coupling_pb2 as pb
sock = zmq.Context().socket(zmq.REP)
sock.bind(a.bind)
if a.mode == "noport":
    time.sleep(3600)
with open(a.port_file + ".tmp", "w") as f:
    f.write(sock.getsockopt(zmq.LAST_ENDPOINT).decode() + "\n")
os.replace(a.port_file + ".tmp", a.port_file)
if a.mode == "silent":
    time.sleep(3600)
req = pb.Request()
req.ParseFromString(sock.recv())
rep = pb.Reply(protocol_version=1, sequence=req.sequence)
rep.hello.server_name = "fake"
rep.hello.protocol_version = 7 if a.mode == "oldversion" else 1
rep.hello.kind = pb.SERVER_KIND_FLUID if a.mode == "wrongkind" else pb.SERVER_KIND_SOLID
sock.send(rep.SerializeToString())
time.sleep(3600)
