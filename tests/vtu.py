"""Read the .vtu files rotorfit writes (deal.II's XML writer: binary
DataArrays, zlib-compressed in blocks) without VTK: points and the
named point or cell data as lists of tuples."""

import base64
import re
import struct
import zlib

_TYPES = {"Float32": "f", "Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B"}


def _decode(text, kind):
    text = text.strip()
    # header: uint32 blocks, block size, last block size, then the compressed
    # size of each block, as its own base64 string; then the blocks
    blocks = struct.unpack("<I", base64.b64decode(text[:8])[:4])[0]
    length = 4 * ((4 * (3 + blocks) + 2) // 3)
    header = struct.unpack("<%dI" % (3 + blocks), base64.b64decode(text[:length]))
    data = base64.b64decode(text[length:])
    raw, start = b"", 0
    for size in header[3:]:
        raw += zlib.decompress(data[start:start + size])
        start += size
    fmt = _TYPES[kind]
    return struct.unpack("<%d%s" % (len(raw) // struct.calcsize(fmt), fmt), raw)


def read(path):
    """{'points': [(x, y, z)], 'point': {name: [tuple]}, 'cell': {name: [tuple]},
    'connectivity': [...], 'offsets': [...]}"""
    text = open(path).read()
    out = {"points": [], "point": {}, "cell": {}}
    section = None
    for m in re.finditer(r"<(PointData|CellData|Points)\b|<DataArray([^>]*)>(.*?)</DataArray>",
                         text, re.S):
        if m.group(1):
            section = m.group(1)
            continue
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', m.group(2)))
        values = _decode(m.group(3), attrs["type"])
        n = int(attrs.get("NumberOfComponents", "1"))
        rows = [tuple(values[i:i + n]) for i in range(0, len(values), n)]
        name = attrs.get("Name")
        if section == "Points" and name is None:
            out["points"] = rows
        elif name in ("connectivity", "offsets", "types"):
            out[name] = values
        elif section == "PointData":
            out["point"][name] = rows
        elif section == "CellData":
            out["cell"][name] = rows
    return out
