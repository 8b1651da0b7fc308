#!/usr/bin/env python3
"""Writes a planar grid OBJ for the scale runs (docs/benchmarks.md, "Scale: 1M-face meshes").

    tools/grid.py --nx 708 --ny 707 --triangles out.obj   # 1,001,112 triangles (the issue's mesh)
    tools/grid.py --nx 1000 --ny 1000 out.obj             # 1,000,000 quads

A gentle height field keeps normals varied, so shading differences would show. Large meshes
are generated, never committed. `tests/scale.rs` builds the same grids in memory.
"""
import argparse
import math
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nx", type=int, required=True, help="quads along x")
    ap.add_argument("--ny", type=int, required=True, help="quads along y")
    ap.add_argument("--triangles", action="store_true", help="split each quad into two triangles")
    ap.add_argument("out", help="OBJ path to write")
    a = ap.parse_args()
    if a.nx < 1 or a.ny < 1:
        ap.error("--nx and --ny must be at least 1")
    with open(a.out, "w", encoding="ascii") as f:
        w = f.write
        for j in range(a.ny + 1):
            y = j / a.ny
            for i in range(a.nx + 1):
                x = i / a.nx
                z = 0.05 * math.sin(6.0 * x) * math.cos(5.0 * y)
                w(f"v {x:.7f} {y:.7f} {z:.7f}\n")
        row = a.nx + 1
        for j in range(a.ny):
            for i in range(a.nx):
                v00 = j * row + i + 1
                v10, v01, v11 = v00 + 1, v00 + row, v00 + row + 1
                if a.triangles:
                    w(f"f {v00} {v10} {v11}\nf {v00} {v11} {v01}\n")
                else:
                    w(f"f {v00} {v10} {v11} {v01}\n")
    faces = a.nx * a.ny * (2 if a.triangles else 1)
    print(f"{a.out}: {(a.nx + 1) * (a.ny + 1)} vertices, {faces} {'triangles' if a.triangles else 'quads'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
