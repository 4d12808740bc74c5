#!/usr/bin/env python3
"""Reads a DXF file with ezdxf (Debian's python3-ezdxf), the consumer field_exports_test checks
stations.dxf against, and prints what it holds as JSON: the version, the extents, the layer table,
the audit's errors, and every POINT, TEXT and POLYLINE of the model space with its layer and
coordinates.
Usage: read_dxf.py FILE.dxf   (exit 1 when ezdxf cannot read the file)"""
import json
import sys

import ezdxf

doc = ezdxf.readfile(sys.argv[1])
auditor = doc.audit()
out = {
    "dxfversion": doc.dxfversion,
    "extents": [list(doc.header.get("$EXTMIN", (0, 0, 0))), list(doc.header.get("$EXTMAX", (0, 0, 0)))],
    "layers": sorted(layer.dxf.name for layer in doc.layers),
    "styles": sorted(style.dxf.name for style in doc.styles),
    "audit_errors": [str(e.message) for e in auditor.errors],
    "points": [],
    "texts": [],
    "polylines": [],
}
for e in doc.modelspace():
    kind = e.dxftype()
    if kind == "POINT":
        out["points"].append({"layer": e.dxf.layer, "xyz": list(e.dxf.location)})
    elif kind == "TEXT":
        out["texts"].append({"layer": e.dxf.layer, "text": e.dxf.text, "xyz": list(e.dxf.insert)})
    elif kind == "POLYLINE":
        out["polylines"].append({"layer": e.dxf.layer, "closed": e.is_closed,
                                 "vertices": [list(v.dxf.location) for v in e.vertices]})
    else:
        out.setdefault("other", []).append(kind)
print(json.dumps(out))
