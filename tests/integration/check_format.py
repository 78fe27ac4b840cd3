#!/usr/bin/env python3
"""Every C++ file of the repository is formatted with the committed .clang-format.

Usage: check_format.py SOURCE_DIR. Lists the files clang-format would change (run
`clang-format -i FILE` on them); fails when clang-format is missing (scripts/install-deps.sh
installs it)."""
import pathlib
import shutil
import subprocess
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
exe = shutil.which("clang-format")
if not exe:
    sys.exit("clang-format not found: scripts/install-deps.sh installs it")
files = subprocess.run(["git", "ls-files", "*.cpp", "*.hpp", "*.h"], cwd=root, capture_output=True, text=True,
                       check=True).stdout.split()
files = [f for f in files if not f.startswith("proto/")]
if not files:  # not a git checkout: every C++ file under the source folders
    files = [str(p.relative_to(root)) for p in root.rglob("*") if p.suffix in (".cpp", ".hpp", ".h")
             and not any(part.startswith("build") for part in p.parts)]
bad = []
for f in files:
    p = subprocess.run([exe, "--dry-run", "--Werror", f], cwd=root, capture_output=True, text=True)
    if p.returncode != 0:
        bad.append(f)
if bad:
    print(f"{len(bad)} of {len(files)} files are not formatted (clang-format -i FILE):")
    print("\n".join("  " + f for f in bad))
    sys.exit(1)
print(f"{len(files)} C++ files formatted with {root / '.clang-format'}")
