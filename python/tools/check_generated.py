#!/usr/bin/env python3
"""Check that the committed python/fsi/v1/coupling_pb2.py is current.

    python3 python/tools/check_generated.py            # exit 0: current, 1: stale (says why)
    python3 python/tools/check_generated.py --update   # regenerate it in place

Regenerates proto/fsi/v1/coupling.proto with protoc into a temporary folder and compares
it with the committed file. Identical bytes pass. If only the text differs (another protoc
release formats the generated code differently) but the embedded descriptor, i.e. the
protocol itself, is the same, it passes and says so. protoc is --protoc, $PROTOC or the
one on PATH (Debian: protobuf-compiler).
"""
import argparse
import ast
import difflib
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.normpath(os.path.join(HERE, "..", ".."))
RELATIVE = os.path.join("fsi", "v1", "coupling_pb2.py")


def descriptor_bytes(text):
    """The serialized FileDescriptorProto passed to AddSerializedFile(b'...')."""
    key = "AddSerializedFile("
    start = text.find(key)
    if start < 0:
        return None
    start += len(key)
    end = text.find(")\n", start)
    try:
        return ast.literal_eval(text[start:end])
    except (SyntaxError, ValueError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--protoc", default=os.environ.get("PROTOC") or shutil.which("protoc"))
    ap.add_argument("--proto-root", default=os.path.join(SOURCE, "proto"), help="the folder holding fsi/v1/coupling.proto")
    ap.add_argument("--committed", default=os.path.join(SOURCE, "python", RELATIVE))
    ap.add_argument("--update", action="store_true", help="write the regenerated file over the committed one")
    a = ap.parse_args()
    if not a.protoc:
        sys.exit("check_generated: no protoc (install Debian's protobuf-compiler, or pass --protoc / set $PROTOC)")
    version = subprocess.run([a.protoc, "--version"], capture_output=True, text=True).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        p = subprocess.run([a.protoc, f"--python_out={tmp}", "-I", a.proto_root,
                            os.path.join(a.proto_root, "fsi", "v1", "coupling.proto")], capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"check_generated: {a.protoc} failed ({version}):\n{p.stderr}")
        with open(os.path.join(tmp, RELATIVE)) as f:
            fresh = f.read()
    if a.update:
        with open(a.committed, "w") as f:
            f.write(fresh)
        print(f"check_generated: wrote {a.committed} ({version})")
        return 0
    try:
        with open(a.committed) as f:
            committed = f.read()
    except OSError as e:
        print(f"check_generated: cannot read the committed module: {e}")
        return 1
    if committed == fresh:
        print(f"check_generated: {a.committed} is current ({version})")
        return 0
    if descriptor_bytes(committed) is not None and descriptor_bytes(committed) == descriptor_bytes(fresh):
        print(f"check_generated: {a.committed} describes the same protocol; only the generated text differs "
              f"({version} formats it differently from the committed file's protoc)")
        return 0
    diff = difflib.unified_diff(committed.splitlines(), fresh.splitlines(), "committed", f"regenerated ({version})",
                                lineterm="", n=1)
    print(f"check_generated: {a.committed} is STALE: proto/fsi/v1/coupling.proto changed since it was generated.\n"
          f"Regenerate it with\n    python3 python/tools/check_generated.py --update\nand commit it. Difference "
          f"(first lines):")
    for i, line in enumerate(diff):
        if i >= 20:
            print("...")
            break
        print(line[:200])
    return 1


if __name__ == "__main__":
    sys.exit(main())
