#!/usr/bin/env python3
"""Checks the layering of the tree from its #include lines, and draws it.

Layers, lowest first: base, scene, raycast, visibility, plan, report (core/<layer>/), synth (a
side branch on base), then wire (proto/), server/, client/. A file may include its own layer's
headers and those of the layers it builds on (DEPENDS below), never a higher one; the CMake targets
enforce the same (a layer's target links only what it builds on), this script makes the rule
visible and checks what CMake cannot see:
  - no tests/ or bench/ file includes a private path (a `src/` directory or `../`);
  - vc-server's code includes neither vc/synth nor vc/report;
  - no core layer includes gRPC or protobuf.
Usage: scripts/check-layers.py [--mermaid]   (--mermaid: print the layer graph with the include
counts, the drawing in docs/ARCHITECTURE.md). Exit 1 with one line per violation.
"""
import collections
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
# Each layer and the layers it may include (transitively closed below).
DEPENDS = {
    "base": [],
    "scene": ["base"],
    "raycast": ["scene"],
    "visibility": ["raycast"],
    "plan": ["visibility"],
    "report": ["plan"],
    "synth": ["base"],
    "wire": ["plan"],
    "server": ["wire"],
    "client": ["wire", "report"],
}
HEADER_LAYER = {"vc/" + l + "/": l for l in DEPENDS if l not in ("wire",)}
HEADER_LAYER["vc/wire/"] = "wire"
HEADER_LAYER["vc/v1/"] = "wire"


def closure(layer):
    seen, todo = set(), [layer]
    while todo:
        for d in DEPENDS[todo.pop()]:
            if d not in seen:
                seen.add(d)
                todo.append(d)
    return seen


def layer_of(path):
    parts = path.relative_to(ROOT).parts
    if parts[0] == "core":
        return parts[1]
    return {"proto": "wire", "server": "server", "client": "client"}.get(parts[0])


INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]([^">]+)[">]', re.M)


def main():
    problems = []
    edges = collections.Counter()
    for path in sorted(ROOT.glob("**/*")):
        if path.suffix not in (".h", ".cc") or "build" in path.relative_to(ROOT).parts[:1]:
            continue
        top = path.relative_to(ROOT).parts[0]
        if top not in ("core", "proto", "server", "client", "tests", "bench", "fuzz"):
            continue
        text = path.read_text(errors="replace")
        rel = path.relative_to(ROOT)
        layer = layer_of(path)
        for inc in INCLUDE.findall(text):
            if top in ("tests", "bench", "fuzz") and ("../" in inc or "/src/" in inc or inc.startswith("src/")):
                problems.append(f"{rel}: includes a private path {inc}")
            if layer is None:
                continue
            if layer not in ("wire", "server", "client") and (inc.startswith("grpc") or inc.startswith("google/protobuf")):
                problems.append(f"{rel}: core layer {layer} includes {inc}")
            target = next((l for p, l in HEADER_LAYER.items() if inc.startswith(p)), None)
            if target is None or target == layer:
                continue
            edges[(layer, target)] += 1
            if target not in closure(layer):
                problems.append(f"{rel}: layer {layer} includes {inc} from layer {target}, which it does not build on")
            if layer == "server" and target in ("synth", "report"):
                problems.append(f"{rel}: vc-server code includes {inc}")
    if "--mermaid" in sys.argv:
        print("```mermaid\nflowchart BT")
        for (a, b), n in sorted(edges.items()):
            print(f"  {a} -->|{n}| {b}")
        print("```")
    for p in problems:
        print(p)
    if problems:
        return 1
    if "--mermaid" not in sys.argv:
        print(f"check-layers: {sum(edges.values())} cross-layer includes, all downward; no private includes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
