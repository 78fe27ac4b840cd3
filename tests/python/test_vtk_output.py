#!/usr/bin/python3
"""VTK output, binary (the default) against ascii (time.vtk_format): FSI3 for two steps with
output every step (fluid, solid, interface_solid, interface_fluid at steps 0, 1, 2) and CSM1
alone (the standalone runner's solid), once in each encoding. Checks:
  - the default is binary: raw appended data, zlib blocks, header_type UInt64 (ParaView's own);
  - every .vtu of every kind read back with fsi.vtk, with meshio and with VTK's own XML reader
    gives the same arrays (names, shapes, cells), the three readers bit for bit;
  - the binary values equal the ascii ones to the ascii's 10 significant digits (1e-9 of each
    array's largest value), the cells are identical; the .pvd collections are identical;
  - the binary files of FSI3 are at most half the ascii size.

    test_vtk_output.py --bin BUILD/bin --source SRC WORK
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
sys.path.insert(0, str(SRC / "python"))
import numpy as np  # noqa: E402

from fsi import vtk as fvtk  # noqa: E402

from checks import check, failures  # noqa: E402


try:
    import meshio
except ImportError:
    meshio = None
try:
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
except ImportError:
    vtkXMLUnstructuredGridReader = None
check(meshio is not None, "meshio importable (Debian: python3-meshio, scripts/install-deps.sh)")
check(vtkXMLUnstructuredGridReader is not None, "VTK 9 importable (Debian: python3-vtk9, scripts/install-deps.sh)")

work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
fsi_bin = str(Path(a.bin).resolve() / "fsi")


def run(scene, out, sets):
    cmd = [fsi_bin, "run", str(SRC / "configs" / scene), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=240)
    check(p.returncode == 0, f"{scene} {' '.join(sets)}: exit {p.returncode} {p.stderr[-500:]}")


fsi3 = ["time.end=0.005", "time.output_every=1"]
run("fsi3.yaml", work / "fsi3_default", fsi3)
run("fsi3.yaml", work / "fsi3_ascii", fsi3 + ["time.vtk_format=ascii"])
run("csm1.yaml", work / "csm1_default", [])
run("csm1.yaml", work / "csm1_ascii", ["time.vtk_format=ascii"])


def meshio_arrays(path):
    m = meshio.read(path)
    cells = {k: np.asarray(v[0]) for k, v in m.cell_data.items()}
    return m.points, dict(m.point_data), cells


def vtk_arrays(path):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    g = r.GetOutput()
    pd, cd = g.GetPointData(), g.GetCellData()
    return (vtk_to_numpy(g.GetPoints().GetData()),
            {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())},
            {cd.GetArrayName(i): vtk_to_numpy(cd.GetArray(i)) for i in range(cd.GetNumberOfArrays())},
            vtk_to_numpy(g.GetCells().GetConnectivityArray()), vtk_to_numpy(g.GetCellTypesArray()))


def same(x, y):
    x, y = np.asarray(x), np.asarray(y)
    return x.size == y.size and np.array_equal(x.reshape(-1), y.reshape(-1), equal_nan=True)


def compare(binary_dir, ascii_dir, expect_names):
    files = sorted(p.name for p in binary_dir.glob("*.vtu"))
    check(files == sorted(p.name for p in ascii_dir.glob("*.vtu")) and files,
          f"{binary_dir.parent.name}: the same {len(files)} .vtu files in both encodings")
    for pvd in sorted(binary_dir.glob("*.pvd")):
        check(pvd.read_bytes() == (ascii_dir / pvd.name).read_bytes(), f"{pvd.name} identical in both encodings")
    kinds = set()
    for name in files:
        kind = name.rsplit("_", 1)[0]
        kinds.add(kind)
        bpath, apath = binary_dir / name, ascii_dir / name
        head = bpath.read_bytes()[:400]
        check(b'header_type="UInt64"' in head and b'compressor="vtkZLibDataCompressor"' in head
              and b'<AppendedData encoding="raw">' in bpath.read_bytes(), f"{name}: binary, zlib, appended (default)")
        b, asc = fvtk.read_vtu(bpath), fvtk.read_vtu(apath)
        check(b.encoding == "binary" and asc.encoding == "ascii", f"{name}: encodings {b.encoding} / {asc.encoding}")
        ok = (same(b.connectivity, asc.connectivity) and same(b.offsets, asc.offsets) and same(b.types, asc.types)
              and sorted(b.point_data) == sorted(asc.point_data) and sorted(b.cell_data) == sorted(asc.cell_data))
        check(ok, f"{name}: cells identical, arrays {sorted(b.point_data)} / {sorted(b.cell_data)}")
        worst = 0.0
        for arrays_b, arrays_a in ((b.point_data, asc.point_data), (b.cell_data, asc.cell_data)):
            for k, v in arrays_b.items():
                va = arrays_a[k]
                scale = max(float(np.nanmax(np.abs(v))), 1e-300) if v.size else 1.0
                worst = max(worst, float(np.nanmax(np.abs(v - va))) / scale if v.size else 0.0)
        worst = max(worst, float(np.max(np.abs(b.points - asc.points))) / max(float(np.max(np.abs(b.points))), 1e-300))
        check(worst <= 1e-9, f"{name}: binary = ascii to {worst:.1e} of each array's largest value (<= 1e-9)")
        if meshio is not None:
            pts, pd, cd = meshio_arrays(bpath)
            ok = same(pts, b.points) and all(same(pd[k], v) for k, v in b.point_data.items()) and \
                all(same(cd[k], v) for k, v in b.cell_data.items())
            check(ok, f"{name}: meshio reads the same points and arrays bit for bit")
        if vtkXMLUnstructuredGridReader is not None:
            pts, pd, cd, conn, types = vtk_arrays(bpath)
            ok = same(pts, b.points) and same(conn, b.connectivity) and same(types, b.types) and \
                all(same(pd[k], v) for k, v in b.point_data.items()) and \
                all(same(cd[k], v) for k, v in b.cell_data.items()) and \
                len(pd) == len(b.point_data) and len(cd) == len(b.cell_data)
            check(ok, f"{name}: VTK's reader gives the same points, cells and arrays bit for bit")
    check(kinds == expect_names, f"{binary_dir.parent.name}: file kinds {sorted(kinds)}")


compare(work / "fsi3_default" / "vtk", work / "fsi3_ascii" / "vtk",
        {"fluid", "solid", "interface_solid", "interface_fluid"})
compare(work / "csm1_default" / "vtk", work / "csm1_ascii" / "vtk", {"solid"})

size_b = sum(p.stat().st_size for p in (work / "fsi3_default" / "vtk").glob("*_000002.vtu"))
size_a = sum(p.stat().st_size for p in (work / "fsi3_ascii" / "vtk").glob("*_000002.vtu"))
print(f"FSI3 frame of step 2 (fluid + solid + both interfaces): binary {size_b} bytes, ascii {size_a} bytes")
check(0 < size_b <= 0.5 * size_a, f"binary frame {size_b} B <= half the ascii frame {size_a} B")

print("FAILED: " + "; ".join(failures) if failures else "all passed")
sys.exit(1 if failures else 0)
