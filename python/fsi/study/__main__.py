"""`python3 -m fsi.study run STUDY.yaml --out DIR ...` (the same as tools/fsi_study.py)."""
import sys

from fsi.study.cli import main

if __name__ == "__main__":  # not when a LocalCluster worker (spawn) imports the main module
    sys.exit(main())
