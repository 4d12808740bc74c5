#!/usr/bin/env python3
"""Checks stations.geojson with real consumers, for field_exports_test: python's json reads it, and
pyproj (Debian's python3-pyproj, PROJ's own Python binding) transforms the expected input-frame
points to WGS 84 longitude/latitude to compare with every coordinate.
Usage: check_geojson.py FILE.geojson EXPECTED.json
EXPECTED.json: {"crs": "EPSG:25832", "metres_per_unit": 1, "stations": [[x, y], ...] (walking order),
"route": [[[x, y], ...], ...] (one list per part), "zones": [[[x, y], ...], ...] (outline vertices)},
all in metres in the input's frame. Prints a JSON summary; exit 1 with one line per problem."""
import json
import sys

import pyproj

TOLERANCE_DEG = 1e-7
problems = []


def near(a, b):
    return len(a) == 2 and abs(a[0] - b[0]) < TOLERANCE_DEG and abs(a[1] - b[1]) < TOLERANCE_DEG


with open(sys.argv[1]) as f:
    doc = json.load(f)
with open(sys.argv[2]) as f:
    expected = json.load(f)
to_wgs84 = pyproj.Transformer.from_crs(expected["crs"], "EPSG:4326", always_xy=True)
scale = expected.get("metres_per_unit", 1)


def lonlat(xy):
    return list(to_wgs84.transform(xy[0] / scale, xy[1] / scale))


if doc.get("type") != "FeatureCollection":
    problems.append("type is %r, not FeatureCollection" % doc.get("type"))
features = doc.get("features", [])
by_kind = {"Point": [], "LineString": [], "Polygon": []}
for k, feature in enumerate(features):
    if feature.get("type") != "Feature" or "properties" not in feature:
        problems.append("feature %d is not a Feature with properties" % k)
    geometry = feature.get("geometry", {})
    by_kind.setdefault(geometry.get("type"), []).append(geometry["coordinates"])

if len(by_kind["Point"]) != len(expected["stations"]):
    problems.append("%d Points for %d stations" % (len(by_kind["Point"]), len(expected["stations"])))
for k, (got, xy) in enumerate(zip(by_kind["Point"], expected["stations"])):
    if not near(got, lonlat(xy)):
        problems.append("station %d at %r, pyproj says %r" % (k + 1, got, lonlat(xy)))

if len(by_kind["LineString"]) != len(expected["route"]):
    problems.append("%d LineStrings for %d route parts" % (len(by_kind["LineString"]), len(expected["route"])))
for k, (got, part) in enumerate(zip(by_kind["LineString"], expected["route"])):
    if len(got) != len(part) or not all(near(g, lonlat(xy)) for g, xy in zip(got, part)):
        problems.append("route part %d is %r, pyproj says %r" % (k + 1, got, [lonlat(xy) for xy in part]))

if len(by_kind["Polygon"]) != len(expected["zones"]):
    problems.append("%d Polygons for %d zones" % (len(by_kind["Polygon"]), len(expected["zones"])))
for k, (rings, outline) in enumerate(zip(by_kind["Polygon"], expected["zones"])):
    ring = rings[0]
    if len(rings) != 1 or len(ring) != len(outline) + 1 or ring[0] != ring[-1]:
        problems.append("zone %d: not one closed ring of %d vertices: %r" % (k + 1, len(outline), rings))
        continue
    twice_area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:]))
    if twice_area <= 0:
        problems.append("zone %d: ring is not counter-clockwise" % (k + 1))
    want = [lonlat(xy) for xy in outline]
    if not any(all(near(g, w) for g, w in zip(ring[:-1], order)) for order in (want, want[::-1])):
        problems.append("zone %d is %r, pyproj says %r" % (k + 1, ring, want))

print(json.dumps({kind: len(v) for kind, v in by_kind.items()}))
for p in problems:
    print(p, file=sys.stderr)
sys.exit(1 if problems else 0)
