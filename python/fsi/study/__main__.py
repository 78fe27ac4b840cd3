"""`python3 -m fsi.study run STUDY.yaml --out DIR ...` (the same as tools/fsi_study.py)."""
import sys

from .cli import main

sys.exit(main())
