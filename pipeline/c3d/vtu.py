"""The data arrays of a VTK XML UnstructuredGrid file as contact3d writes it (output.vtu): ASCII
(numbers inside each <DataArray>) or binary (raw little-endian values after the XML, in one
<AppendedData encoding="raw"> section, each array a byte count then its values).

    arrays = read_arrays("body.vtu")   # {"Points": (n, 3), "displacement": (n, 3), "von_mises": (m,), ...}
"""
import xml.etree.ElementTree as ET

import numpy as np

_DTYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1", "UInt64": "<u8",
           "UInt32": "<u4"}


def read_arrays(path):
    """{Name: values} of every <DataArray>, shaped (tuples, components), or (tuples,) for one component."""
    with open(path, "rb") as f:
        raw = f.read()
    start = raw.find(b"<AppendedData")
    if start < 0:
        root, appended = ET.fromstring(raw), None
    else:
        root = ET.fromstring(raw[:start] + b"</VTKFile>")
        underscore = raw.index(b"_", raw.index(b">", start))
        appended = memoryview(raw)[underscore + 1:]
    header = _DTYPES[root.get("header_type", "UInt32")]
    out = {}
    for node in root.iter("DataArray"):
        name, components = node.get("Name"), int(node.get("NumberOfComponents", "1"))
        dtype = _DTYPES[node.get("type")]
        encoding = node.get("format", "ascii")
        if encoding == "ascii":
            values = np.array((node.text or "").split(), dtype=dtype)
        elif encoding == "appended" and appended is not None:
            offset = int(node.get("offset"))
            size = np.dtype(header).itemsize
            nbytes = int(np.frombuffer(appended[offset:offset + size], dtype=header)[0])
            values = np.frombuffer(appended[offset + size:offset + size + nbytes], dtype=dtype).copy()
        else:
            raise ValueError(f"{path}: DataArray {name!r} in format {encoding!r}, which this reader does not read")
        out[name] = values.reshape(-1, components) if components > 1 else values
    return out
