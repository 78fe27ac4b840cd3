"""Read the VTK files a run writes (RUN/vtk/*.vtu, *.pvd) with numpy alone.

    from fsi import vtk
    g = vtk.read_vtu("runs/fsi3/vtk/fluid_000100.vtu")
    g.points            # (n, 3) float64
    g.point_data["velocity"], g.cell_data["pressure"], g.cells, g.offsets, g.types
    for time, path in vtk.read_pvd("runs/fsi3/vtk/fluid.pvd"): ...

Reads both encodings the project writes (scene key time.vtk_format): binary (raw appended data,
zlib-compressed blocks, header_type UInt64 or UInt32, ParaView's default) and ascii; also
uncompressed appended data and inline base64 ("binary" format) as VTK writes them. Only
UnstructuredGrid pieces (one per file). ParaView, VTK and meshio read the same files.
"""
import base64
import os
import struct
import xml.etree.ElementTree as ET
import zlib
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Grid", "read_vtu", "read_pvd", "VtkReadError"]

_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt64": "<u8",
          "UInt32": "<u4", "UInt8": "<u1", "Int8": "<i1", "Int16": "<i2", "UInt16": "<u2"}


class VtkReadError(ValueError):
    """A file this reader does not understand."""


@dataclass
class Grid:
    points: np.ndarray                      # (n, 3)
    connectivity: np.ndarray                # node indices of all cells, concatenated
    offsets: np.ndarray                     # end of each cell in connectivity
    types: np.ndarray                       # VTK cell type per cell (1 vertex, 3 line, 5 triangle, 9 quad)
    point_data: dict = field(default_factory=dict)   # name -> (n,) or (n, k)
    cell_data: dict = field(default_factory=dict)    # name -> (cells,) or (cells, k)
    encoding: str = "ascii"                 # "ascii" or "binary" (of the first data array)

    @property
    def cells(self):
        """Node indices per cell, a list of arrays."""
        starts = np.concatenate(([0], self.offsets[:-1]))
        return [self.connectivity[a:b] for a, b in zip(starts, self.offsets)]


def _decode_block(raw, dtype, compressed, header):
    """Decode one binary array from raw bytes (appended) starting at 0; returns (values, used)."""
    hsize = 8 if header == "UInt64" else 4
    hfmt = "<Q" if header == "UInt64" else "<I"
    if not compressed:
        (n,) = struct.unpack_from(hfmt, raw, 0)
        return np.frombuffer(raw[hsize:hsize + n], dtype=dtype).copy(), hsize + n
    (blocks,) = struct.unpack_from(hfmt, raw, 0)
    sizes = struct.unpack_from("<" + hfmt[1] * (blocks + 2), raw, hsize)
    csizes = sizes[2:]
    pos = hsize * (3 + blocks)
    out = []
    for c in csizes:
        out.append(zlib.decompress(raw[pos:pos + c]))
        pos += c
    data = b"".join(out)
    block, last = sizes[0], sizes[1]
    expect = (blocks - 1) * block + (last if last else block) if blocks else 0
    if len(data) != expect:
        raise VtkReadError(f"compressed array: {len(data)} bytes, header says {expect}")
    return np.frombuffer(data, dtype=dtype).copy(), pos


def _decode_base64(text, dtype, compressed, header):
    """Inline format="binary": base64 of the header, then (compressed) base64 of the data."""
    text = "".join(text.split())
    if not compressed:
        raw = base64.b64decode(text)
        return _decode_block(raw, dtype, False, header)[0]
    hsize = 8 if header == "UInt64" else 4
    hfmt = "<Q" if header == "UInt64" else "<I"
    # the header is encoded on its own: decode enough characters for the block count first
    first = base64.b64decode(text[:4 * ((hsize * 3 + 2) // 3)])
    (blocks,) = struct.unpack_from(hfmt, first, 0)
    hlen = 4 * ((hsize * (3 + blocks) + 2) // 3)
    head = base64.b64decode(text[:hlen])
    body = base64.b64decode(text[hlen:])
    return _decode_block(head[:hsize * (3 + blocks)] + body, dtype, True, header)[0]


def read_vtu(path):
    """The grid of a .vtu file (one piece), every array as numpy (components as columns)."""
    with open(path, "rb") as f:
        blob = f.read()
    # The appended section is raw bytes, not XML: cut it off before parsing.
    appended = b""
    mark = blob.find(b"<AppendedData")
    if mark >= 0:
        start = blob.index(b"_", blob.index(b">", mark)) + 1
        end = blob.rfind(b"</AppendedData>")
        appended = blob[start:end]
        blob = blob[:mark] + b"</VTKFile>"
    root = ET.fromstring(blob)
    if root.get("type") != "UnstructuredGrid":
        raise VtkReadError(f"{path}: type {root.get('type')!r}, not UnstructuredGrid")
    if root.get("byte_order", "LittleEndian") != "LittleEndian":
        raise VtkReadError(f"{path}: big-endian files are not read")
    header = root.get("header_type", "UInt32")
    compressed = root.get("compressor") is not None
    if compressed and root.get("compressor") != "vtkZLibDataCompressor":
        raise VtkReadError(f"{path}: compressor {root.get('compressor')!r} (only vtkZLibDataCompressor)")
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise VtkReadError(f"{path}: no Piece")
    encodings = []

    def array(el):
        dtype = _TYPES[el.get("type")]
        fmt = el.get("format", "ascii")
        encodings.append(fmt)
        if fmt == "ascii":
            values = np.array((el.text or "").split(), dtype=dtype)
        elif fmt == "appended":
            values = _decode_block(appended[int(el.get("offset")):], dtype, compressed, header)[0]
        elif fmt == "binary":
            values = _decode_base64(el.text or "", dtype, compressed, header)
        else:
            raise VtkReadError(f"{path}: DataArray format {fmt!r}")
        k = int(el.get("NumberOfComponents", "1"))
        return values.reshape(-1, k) if k > 1 else values

    points = array(piece.find("Points/DataArray"))
    cells = {el.get("Name"): array(el) for el in piece.findall("Cells/DataArray")}
    pd = {el.get("Name"): array(el) for el in piece.findall("PointData/DataArray")}
    cd = {el.get("Name"): array(el) for el in piece.findall("CellData/DataArray")}
    n, m = int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))
    if len(points) != n or len(cells["types"]) != m:
        raise VtkReadError(f"{path}: {len(points)} points / {len(cells['types'])} cells, header says {n} / {m}")
    return Grid(points.reshape(-1, 3), cells["connectivity"], cells["offsets"], cells["types"], pd, cd,
                "ascii" if not encodings or encodings[0] == "ascii" else "binary")


def read_pvd(path):
    """[(time, file path)] of a ParaView collection, in its order."""
    root = ET.parse(path).getroot()
    base = os.path.dirname(os.path.abspath(path))
    return [(float(d.get("timestep")), os.path.join(base, d.get("file"))) for d in root.iter("DataSet")]
