#!/usr/bin/python3
"""fsi_study: parameter studies over `fsi run` (the code is the package fsi.study in python/fsi/study).

  fsi_study.py run STUDY.yaml --out DIR [--jobs N] [--fsi PATH] [--set K=V] [--dry-run]
                              [--executor local|dask] [--scheduler tcp://HOST:PORT] [--shared-dir DIR]
  fsi_study.py plot DIR
  fsi_study.py analyse DIR

`fsi study` execs this file. See docs/studies.md.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

from fsi.study import *  # noqa: E402,F401,F403 (the names tests and scripts always imported from here)
from fsi.study.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
