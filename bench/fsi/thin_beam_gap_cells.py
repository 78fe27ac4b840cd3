#!/usr/bin/env python3
"""The thin beam's fluid cells between the leaflet's free end and the channel wall (centroid
y < 0.01, 2.45 < x < 2.75) at saved steps of a run with VTK output (time.output_every): their
smallest height (twice the area over the longest side) and the largest pressure jump within one.

Usage: python3 bench/fsi/thin_beam_gap_cells.py RUN_DIR STEP [STEP ...]
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
from fsi import vtk  # noqa: E402


def main():
    run = sys.argv[1]
    for step in (int(s) for s in sys.argv[2:]):
        m = vtk.read_vtu(f"{run}/vtk/fluid_{step:06d}.vtu")
        points, conn, ends = np.asarray(m.points)[:, :2], np.asarray(m.connectivity), np.asarray(m.offsets)
        pressure = np.asarray(m.point_data["pressure"])
        heights, jumps = [], []
        for begin, end in zip(np.concatenate([[0], ends[:-1]]), ends):
            ids = conn[begin:end][:3]
            x = points[ids]
            c = x.mean(axis=0)
            if 2.45 < c[0] < 2.75 and c[1] < 0.01:
                area = 0.5 * abs(np.cross(x[1] - x[0], x[2] - x[0]))
                heights.append(2 * area / max(np.linalg.norm(x[i] - x[(i + 1) % 3]) for i in range(3)))
                jumps.append(np.ptp(pressure[ids]))
        print(f"step {step}: {len(heights)} cells, smallest height {min(heights):.2e}, "
              f"largest pressure jump in one {max(jumps):.3g}")


if __name__ == "__main__":
    main()
