#!/usr/bin/env python3
"""Prints the inline meshes of the grass and fur samples (samples/effects/grass.json, fur.json)
as effect-file mesh domains: `python3 scripts/sample_meshes.py hill|animal`. The built-in
effects are embedded in the tool, so their meshes are inline rather than OBJ files."""
import math
import sys


def hill(n=10, half=4.0, height=0.7, width=2.2):
    """A square patch of ground with a gentle hill in the middle, faces up (+y)."""
    vs, ts = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x = -half + 2 * half * i / n
            z = -half + 2 * half * j / n
            y = height * math.exp(-(x * x + z * z) / (2 * width * width))
            vs.append((x, y, z))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            # counter-clockwise seen from above: the normals point up
            ts += [(a, c, b), (b, c, d)]
    return vs, ts


def icosphere(subdivisions):
    t = (1 + 5 ** 0.5) / 2
    vs = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
          (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    vs = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in vs]
    ts = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
          (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
          (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = [(x + y) / 2 for x, y in zip(vs[a], vs[b])]
                l = math.sqrt(sum(x * x for x in p))
                vs.append(tuple(x / l for x in p))
                mid[key] = len(vs) - 1
            return mid[key]

        nt = []
        for a, b, c in ts:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        ts = nt
    return vs, ts


def add(mesh, part, f):
    vs, ts = mesh
    base = len(vs)
    vs += [f(v) for v in part[0]]
    ts += [(a + base, b + base, c + base) for a, b, c in part[1]]


def animal():
    """A sitting cat-like creature: a body, a head, two ears and a tail, facing +z."""
    mesh = ([], [])
    # body: a squat egg, wider at the bottom
    add(mesh, icosphere(2),
        lambda v: (0.85 * v[0] * (1 - 0.15 * v[1]), 0.95 * v[1] + 0.95, 0.75 * v[2] * (1 - 0.15 * v[1])))
    # head, in front of and above the body
    add(mesh, icosphere(2), lambda v: (0.5 * v[0], 0.45 * v[1] + 2.1, 0.48 * v[2] + 0.3))
    # ears: pyramids on the head, tips outwards
    for s in (-1, 1):
        base = [(s * 0.15, 2.42, 0.2), (s * 0.42, 2.3, 0.22), (s * 0.3, 2.35, 0.45)]
        tip = (s * 0.36, 2.8, 0.3)
        vs = base + [tip]
        ts = [(0, 1, 2), (1, 0, 3), (2, 1, 3), (0, 2, 3)] if s > 0 else [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)]
        add(mesh, (vs, ts), lambda v: v)
    # tail: a tapered tube curling around the body's base
    sides, rings = 6, 10
    vs, ts = [], []
    for r in range(rings + 1):
        u = r / rings
        ang = math.pi * (0.55 + 0.75 * u)
        centre = (1.05 * math.cos(ang), 0.12 + 0.25 * u * u, -1.05 * math.sin(ang) * 0.8)
        rad = 0.14 * (1 - 0.5 * u)
        tangent = (-math.sin(ang), 0.0, -math.cos(ang) * 0.8)
        tl = math.sqrt(sum(x * x for x in tangent))
        tangent = tuple(x / tl for x in tangent)
        up = (0.0, 1.0, 0.0)
        side = (tangent[1] * up[2] - tangent[2] * up[1], tangent[2] * up[0] - tangent[0] * up[2],
                tangent[0] * up[1] - tangent[1] * up[0])
        for k in range(sides):
            a = 2 * math.pi * k / sides
            vs.append(tuple(centre[i] + rad * (math.cos(a) * side[i] + math.sin(a) * up[i]) for i in range(3)))
    for r in range(rings):
        for k in range(sides):
            a, b = r * sides + k, r * sides + (k + 1) % sides
            c, d = a + sides, b + sides
            ts += [(a, c, b), (b, c, d)]
    # close the tip
    vs.append(centre)
    tip = len(vs) - 1
    for k in range(sides):
        a, b = rings * sides + k, rings * sides + (k + 1) % sides
        ts.append((a, tip, b))
    add(mesh, (vs, ts), lambda v: v)
    return mesh


def emit(mesh):
    vs, ts = mesh
    fmt = lambda x: ("%.3f" % x).rstrip("0").rstrip(".").replace("-0", "-0") if x else "0"
    def num(x):
        s = "%.3f" % x
        s = s.rstrip("0").rstrip(".")
        return "0" if s in ("-0", "") else s
    vtxt = ",".join("[%s,%s,%s]" % tuple(num(c) for c in v) for v in vs)
    ttxt = ",".join("[%d,%d,%d]" % t for t in ts)
    print('{"type": "mesh", "vertices": [%s], "triangles": [%s]}' % (vtxt, ttxt))


if __name__ == "__main__":
    emit({"hill": hill, "animal": animal}[sys.argv[1]]())
