#!/usr/bin/env python3
"""Writes a deterministic corpus of malformed and odd mesh files for the reader and CLI harness.

usage: make_hostile_inputs.py OUTPUT_DIR [--seed N] [--copies K]

Classes (the file name starts with the class): truncated PLY/OFF/STL at random offsets, headers that
lie about counts (negative, huge, off by one), wrong property types, face lists of 0-1000 entries,
out-of-range and negative indices, NaN/Inf/1e38 coordinates, degenerate and non-manifold geometry,
OBJ polygons and odd index forms, OFF comments and header variants, ascii/binary STL with wrong counts
or missing keywords, VRML 2.0 files (truncated, bad indices, transforms, VRML 1.0, unbalanced
braces), soups of large overlapping polygons, empty and whitespace-only files, and random byte flips
and token swaps of valid files. Every file is under 1 MB; the same seed gives the same bytes. Nothing
is written outside OUTPUT_DIR, which must not be inside the repository.
"""
import argparse
import math
import os
import random
import struct
import sys


def icosphere(subdivisions):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                p = [(v[a][k] + v[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                cache[key] = len(v) - 1
            return cache[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return [tuple(10 * x for x in p) for p in v], f


# --- writers -------------------------------------------------------------------------------------

def fmt(x):
    return repr(float(x)) if isinstance(x, float) else str(x)


def ply_ascii(v, f, vcount=None, fcount=None, xyz_type="float", list_types=("uchar", "int"), extra_header=""):
    vc = len(v) if vcount is None else vcount
    fc = len(f) if fcount is None else fcount
    h = ["ply", "format ascii 1.0", "comment hostile", "element vertex %s" % vc]
    h += ["property %s %s" % (xyz_type, c) for c in "xyz"]
    h += ["element face %s" % fc, "property list %s %s vertex_indices" % list_types]
    if extra_header:
        h.append(extra_header)
    h.append("end_header")
    body = [" ".join(fmt(c) for c in p) for p in v] + [" ".join(map(str, [len(t)] + list(t))) for t in f]
    return ("\n".join(h + body) + "\n").encode()


PACK = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I", "float": "f",
        "double": "d", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H", "int32": "i", "uint32": "I",
        "float32": "f", "float64": "d"}


def ply_binary(v, f, big=False, vcount=None, fcount=None, xyz_type="float", list_types=("uchar", "int")):
    e = ">" if big else "<"
    vc = len(v) if vcount is None else vcount
    fc = len(f) if fcount is None else fcount
    h = "ply\nformat binary_%s_endian 1.0\nelement vertex %s\n" % ("big" if big else "little", vc)
    h += "".join("property %s %s\n" % (xyz_type, c) for c in "xyz")
    h += "element face %s\nproperty list %s %s vertex_indices\nend_header\n" % (fc, list_types[0], list_types[1])
    out = bytearray(h.encode())
    for p in v:
        out += struct.pack(e + PACK[xyz_type] * 3, *p)
    for t in f:
        n = len(t)
        cmax = {"B": 255, "b": 127, "H": 65535, "h": 32767}.get(PACK[list_types[0]], 2 ** 31 - 1)
        out += struct.pack(e + PACK[list_types[0]], min(n, cmax))
        for i in t:
            try:
                out += struct.pack(e + PACK[list_types[1]], i)
            except struct.error:
                out += struct.pack(e + "I", i & 0xFFFFFFFF)
    return bytes(out)


def off_text(v, f, vcount=None, fcount=None, header="OFF", comments=False, same_line=False):
    vc = len(v) if vcount is None else vcount
    fc = len(f) if fcount is None else fcount
    lines = [header + (" %s %s 0" % (vc, fc) if same_line else "")]
    if comments:
        lines.insert(0, "# generated")
        lines.append("# counts next")
    if not same_line:
        lines.append("%s %s 0" % (vc, fc))
    for i, p in enumerate(v):
        lines.append(" ".join(fmt(c) for c in p))
        if comments and i % 7 == 0:
            lines.append("# a comment line")
            lines.append("")
    for t in f:
        lines.append(" ".join(map(str, [len(t)] + list(t))))
    return ("\n".join(lines) + "\n").encode()


def obj_text(v, f, corner=lambda i: str(i + 1)):
    lines = ["# hostile"] + ["v %s" % " ".join(fmt(c) for c in p) for p in v]
    lines += ["f " + " ".join(corner(i) for i in t) for t in f]
    return ("\n".join(lines) + "\n").encode()


def stl_ascii(v, f, drop=None, newline_at_end=True):
    out = ["solid hostile"]
    for t in f:
        facet = [" facet normal 0 0 1", "  outer loop"] + ["   vertex %s" % " ".join(fmt(c) for c in v[i]) for i in t]
        facet += ["  endloop", " endfacet"]
        out += [line for line in facet if drop is None or line.strip() != drop]
    if drop != "endsolid":
        out.append("endsolid hostile")
    text = "\n".join(out)
    return (text + ("\n" if newline_at_end else "")).encode()


def wrl_text(v, f, indices=None, header="#VRML V2.0 utf8", wrap=("", "")):
    """A VRML 2.0 IndexedFaceSet as PyMOL writes it (one Shape, commas after each point and polygon)."""
    points = ",\n".join(" ".join(fmt(c) for c in p) for p in v)
    polygons = indices if indices is not None else ",\n".join(" ".join(map(str, t)) + " -1" for t in f)
    return ("%s\n%sShape {\n geometry IndexedFaceSet {\n  coord Coordinate {\n   point [\n%s\n   ]\n  }\n"
            "  coordIndex [\n%s\n  ]\n }\n}\n%s" % (header, wrap[0], points, polygons, wrap[1])).encode()


def stl_binary(v, f, count=None):
    out = bytearray(b"binary hostile".ljust(80, b" "))
    out += struct.pack("<I", len(f) if count is None else count & 0xFFFFFFFF)
    for t in f:
        out += struct.pack("<3f", 0, 0, 1)
        for i in t:
            out += struct.pack("<3f", *v[i])
        out += b"\0\0"
    return bytes(out)


# --- the corpus ----------------------------------------------------------------------------------

class Corpus:
    def __init__(self, out, seed):
        self.out, self.rng, self.count = out, random.Random(seed), 0

    def add(self, name, data):
        assert len(data) < 1_000_000, name
        self.count += 1
        with open(os.path.join(self.out, "%04d_%s" % (self.count, name)), "wb") as fh:
            fh.write(data)


def make(c, copies):
    rng = c.rng
    v, f = icosphere(2)           # 162 vertices, 320 faces
    sv, sf = icosphere(1)         # 42 vertices, 80 faces
    tet_v = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
    tet_f = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
    valid = {
        "ply_ascii.ply": ply_ascii(v, f), "ply_le.ply": ply_binary(v, f), "ply_be.ply": ply_binary(v, f, big=True),
        "off.off": off_text(v, f), "obj.obj": obj_text(v, f), "stl_ascii.stl": stl_ascii(sv, sf),
        "stl_binary.stl": stl_binary(v, f),
    }
    for name, data in valid.items():
        c.add("valid_" + name, data)

    # Truncated at random offsets.
    for name in ["ply_ascii.ply", "ply_le.ply", "ply_be.ply", "off.off", "stl_binary.stl", "stl_ascii.stl"]:
        data = valid[name]
        for _ in range(25 * copies):
            c.add("truncated_" + name, data[:rng.randrange(1, len(data))])

    # Headers that lie about counts.
    lies = [0, 1, -1, -5, 2 ** 31 - 1, 2 ** 31, 2 ** 32, 2 ** 32 + 3, 10 ** 12, 10 ** 19, 10 ** 30, "", "12abc", "1e3",
            "0x10", "+7"]
    for lie in lies:
        for delta in ([0] if isinstance(lie, str) else [0, 1]):
            value = lie if isinstance(lie, str) else lie + delta
            c.add("lying_vcount.ply", ply_ascii(tet_v, tet_f, vcount=value))
            c.add("lying_fcount.ply", ply_ascii(tet_v, tet_f, fcount=value))
            c.add("lying_vcount_bin.ply", ply_binary(tet_v, tet_f, vcount=value))
            c.add("lying_fcount_bin.ply", ply_binary(tet_v, tet_f, fcount=value))
            c.add("lying_vcount.off", off_text(tet_v, tet_f, vcount=value))
            c.add("lying_fcount.off", off_text(tet_v, tet_f, fcount=value))
    for n in [len(tet_v) + 1, len(tet_v) - 1, len(tet_f) + 1, len(tet_f) - 1]:
        c.add("lying_near.ply", ply_ascii(tet_v, tet_f, vcount=n))
        c.add("lying_near_bin.ply", ply_binary(tet_v, tet_f, fcount=n))
        c.add("lying_near.off", off_text(tet_v, tet_f, fcount=n))
    c.add("lying_nocount.ply", b"ply\nformat ascii 1.0\nelement vertex\nproperty float x\nproperty float y\n"
                               b"property float z\nend_header\n0 0 0\n")

    # Wrong property types.
    for xyz in ["char", "uchar", "int", "uint", "short", "double", "float64", "float32", "int8", "list", "bogus"]:
        header = xyz if xyz != "list" else "list uchar float"
        c.add("types_xyz_%s.ply" % xyz, ply_ascii(tet_v, tet_f, xyz_type=header))
        if xyz in PACK:
            c.add("types_xyz_%s_bin.ply" % xyz, ply_binary([tuple(int(x) for x in p) if PACK[xyz] not in "fd" else p
                                                            for p in tet_v], tet_f, xyz_type=xyz))
    for lt in [("float", "int"), ("double", "int"), ("uchar", "float"), ("int", "double"), ("uint", "uint"),
               ("short", "short"), ("char", "uchar"), ("int8", "int64"), ("ushort", "int"), ("list", "int")]:
        c.add("types_list_%s_%s.ply" % lt, ply_ascii(tet_v, tet_f, list_types=lt))
        if lt[0] in PACK and lt[1] in PACK:
            c.add("types_list_%s_%s_bin.ply" % lt, ply_binary(tet_v, tet_f, list_types=lt))
    c.add("types_extra_element.ply", ply_ascii(tet_v, tet_f, extra_header="element material 3\n"
                                               "property list uchar float junk\nproperty uchar red"))
    c.add("types_tristrips.ply", b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                 b"property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
                                 b"end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n6 0 1 2 3 -1 9\n")
    for bad in [-2, 4, 99, 2 ** 31 - 1]:
        c.add("types_tristrips_bad.ply", ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                          "property float y\nproperty float z\nelement tristrips 1\n"
                                          "property list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
                                          "0 1 0\n1 1 0\n5 0 1 2 3 %d\n" % bad).encode())

    # Face lists of 0..1000 entries.
    for n in [0, 1, 2, 3, 4, 5, 7, 100, 255, 256, 257, 300, 511, 512, 513, 600, 999, 1000]:
        face = [i % len(v) for i in range(n)]
        c.add("facelist_%d.ply" % n, ply_ascii(v, [face], list_types=("int", "int")))
        c.add("facelist_%d_bin.ply" % n, ply_binary(v, [face] + f[:10], list_types=("int", "int")))
        c.add("facelist_%d_uchar_bin.ply" % n, ply_binary(v, [face], list_types=("uchar", "int")))
        c.add("facelist_%d.off" % n, off_text(v, [face]))
        if n:
            c.add("facelist_%d.obj" % n, obj_text(v, [face]))

    # Out-of-range and negative indices, first, middle or last corner.
    for bad in [-1, -2, -(2 ** 31), len(v), len(v) + 1, 2 ** 31 - 1, 2 ** 32 + 1]:
        for slot in [0, 1, 2, 3]:
            faces = [list(t) for t in f]
            target = faces[rng.randrange(len(faces))]
            if slot == 3:
                target.append(bad)  # a quad whose last index is bad
            else:
                target[slot] = bad
            c.add("index_%d_%d.ply" % (slot, bad), ply_ascii(v, faces, list_types=("uchar", "int")))
            c.add("index_%d_%d_bin.ply" % (slot, bad), ply_binary(v, faces, list_types=("uchar", "int")))
            c.add("index_%d_%d.off" % (slot, bad), off_text(v, faces))
            c.add("index_%d_%d.obj" % (slot, bad), obj_text(v, faces, corner=lambda i: str(i + 1 if i >= 0 else i)))

    # NaN / Inf / 1e38 coordinates.
    for value in ["nan", "-nan", "inf", "-inf", "1e38", "-1e38", "3.5e38", "1e39", "1e308", "1e400", "NaN", "Infinity",
                  "1e-45", "1e-50"]:
        vv = [list(map(repr, p)) for p in tet_v]
        vv[rng.randrange(4)][rng.randrange(3)] = value
        vt = [tuple(p) for p in vv]
        c.add("coord_%s.ply" % value, ply_ascii(vt, tet_f))
        c.add("coord_%s.off" % value, off_text(vt, tet_f))
        c.add("coord_%s.obj" % value, obj_text(vt, tet_f))
        c.add("coord_%s.stl" % value, stl_ascii(vt, tet_f))
    for value in [float("nan"), float("inf"), -float("inf"), 1e38, 3.4e38]:
        vv = [list(p) for p in v]
        for _ in range(3):
            vv[rng.randrange(len(vv))][rng.randrange(3)] = value
        c.add("coord_bin_%r.ply" % value, ply_binary(vv, f))
        c.add("coord_bin_%r.stl" % value, stl_binary(vv, f))
        c.add("coord_bin_%r_double.ply" % value, ply_binary(vv, f, xyz_type="double"))

    # Degenerate and non-manifold geometry.
    geometry = {
        "zero_area": (tet_v + [(2.0, 0.0, 0.0)], tet_f + [(0, 1, 4)]),
        "repeated_corner": (tet_v, tet_f + [(0, 0, 1), (2, 2, 2)]),
        "duplicate_faces": (tet_v, tet_f + tet_f),
        "flipped_face": (tet_v, tet_f[:3] + [(0, 2, 3)]),
        "fin": (tet_v + [(1.0, 1.0, 1.0)], tet_f + [(1, 2, 4)]),
        "edge_of_three": (tet_v + [(-1.0, -1.0, 0.5)], tet_f + [(0, 1, 4)]),
        "bowtie": ([(0.0, 0, 0), (1.0, 0, 0), (0, 1.0, 0), (-1.0, 0, 0), (0, -1.0, 0)], [(0, 1, 2), (0, 3, 4)]),
        "unreferenced": (v + [(100.0, 100.0, 100.0)] * 5, f),
        "single_triangle": (tet_v[:3], [(0, 1, 2)]),
        "point_cloud": (v, []),
        "all_same_point": ([(1.0, 1.0, 1.0)] * 4, tet_f),
        "collinear": ([(0.0, 0, 0), (1.0, 0, 0), (2.0, 0, 0), (3.0, 0, 0)], tet_f),
        "tiny": ([tuple(x * 1e-30 for x in p) for p in v], f),
        "huge": ([tuple(x * 1e30 for x in p) for p in v], f),
        "two_spheres": (v + [(p[0] + 5, p[1], p[2]) for p in v], f + [tuple(i + len(v) for i in t) for t in f]),
        "holed": (v, f[:-7]),
    }
    for name, (gv, gf) in geometry.items():
        c.add("geometry_%s.ply" % name, ply_binary(gv, gf))
        c.add("geometry_%s.off" % name, off_text(gv, gf))
        if gf:
            c.add("geometry_%s.stl" % name, stl_binary(gv, gf))
            c.add("geometry_%s.obj" % name, obj_text(gv, gf))

    # OBJ polygons and odd index forms.
    quads = [(0, 1, 2, 3)]
    sq = [(0.0, 0, 0), (1.0, 0, 0), (1.0, 1, 0), (0.0, 1, 0)]
    forms = ["{i}", "{i}/{i}", "{i}//{i}", "{i}/{i}/{i}", "{r}", "{i}/", "{i}//", "/{i}", "{i}.0", "{i}.9", "{i}abc",
             "{big}", "0", "{i}e0", "+{i}", "{i}/x", " {i}", "{i}/{i}/{i}/{i}", "0x{i}", "-0"]
    for form in forms:
        def corner(i, form=form):
            return form.format(i=i + 1, r=i - 4, big=4294967296 + i + 1)
        c.add("objform_%d.obj" % forms.index(form), obj_text(sq, quads, corner))
    for n in [3, 4, 5, 6, 20, 100, 256, 257, 1000, 5000]:
        ring = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), 0.0) for k in range(n)]
        c.add("objpolygon_%d.obj" % n, obj_text(ring, [tuple(range(n))]))
        c.add("offpolygon_%d.off" % n, off_text(ring, [tuple(range(n))]))
    # Soups of large overlapping polygons: every face near every other (quadratic pair searches).
    cloud = [(rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-10, 10)) for _ in range(2000)]
    for sides, count in [(255, 320), (100, 400), (30, 2000)]:
        polygons = [tuple(rng.sample(range(len(cloud)), sides)) for _ in range(count)]
        c.add("polygonsoup_%dx%d_bin.ply" % (count, sides), ply_binary(cloud, polygons, list_types=("uchar", "int")))
    c.add("polygonsoup_obj_100x100.obj", obj_text(cloud, [tuple(rng.sample(range(len(cloud)), 100))
                                                          for _ in range(100)]))
    star = [((1 + (k % 2)) * math.cos(k * math.pi / 5), (1 + (k % 2)) * math.sin(k * math.pi / 5), 0.0)
            for k in range(10)]
    c.add("objpolygon_concave.obj", obj_text(star, [tuple(range(10))]))
    c.add("obj_vertices_only.obj", obj_text(v, []))
    c.add("obj_garbage_vertex.obj", b"v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    c.add("obj_short_vertex.obj", b"v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    c.add("obj_crlf.obj", obj_text(v, f).replace(b"\n", b"\r\n"))
    c.add("obj_forward_ref.obj", b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
    c.add("obj_two_corners.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n")

    # OFF comments and header variants.
    for header in ["OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCNOFF", "4OFF", "nOFF", "OFFX", "off", "OF", "XOFF"]:
        vv = tet_v
        if "N" in header:
            vv = [p + (0.0, 0.0, 1.0) for p in tet_v]
        if "C" in header:
            vv = [p + (255, 0, 0) for p in vv]
        if "ST" in header:
            vv = [p + (0.5, 0.5) for p in vv]
        c.add("offheader_%s.off" % header, off_text(vv, tet_f, header=header))
        c.add("offheader_%s_sameline.off" % header, off_text(vv, tet_f, header=header, same_line=True))
    c.add("offcomments.off", off_text(v, f, comments=True))
    c.add("offcomments_inline.off", off_text(tet_v, tet_f).replace(b"\n3 ", b" # trailing\n3 "))
    c.add("off_xyz.off", b"OFF\n4 4 0\n0 0 0\nx y z\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n")
    c.add("off_split_lines.off", b"OFF\n4 4 0\n0 0\n0 1 0\n0 0 1 0\n0 0 1\n3 0 2 1\n3 0 1\n3\n3 1 2 3\n3 0 3 2\n")
    c.add("off_face_colors.off", off_text(tet_v, tet_f).replace(b"3 0 2 1", b"3 0 2 1 255 0 0"))
    c.add("off_crlf.off", off_text(v, f).replace(b"\n", b"\r\n"))
    c.add("off_no_counts.off", b"OFF\n")
    c.add("off_vertex_garbage.off", off_text(tet_v, tet_f).replace(b"1.0 0.0 0.0", b"1.0 0.0 0.0abc"))

    # STL: wrong counts and missing keywords.
    for delta in [-100, -2, -1, 1, 2, 100, 2 ** 31, 2 ** 32 - 1]:
        c.add("stl_count_%d.stl" % delta, stl_binary(v, f, count=len(f) + delta))
    c.add("stl_count_zero.stl", stl_binary(v, f, count=0))
    c.add("stl_empty_binary.stl", stl_binary([], []))
    c.add("stl_header_only.stl", b"x" * 80)
    c.add("stl_binary_solid_header.stl", b"solid " + stl_binary(v, f)[6:])
    c.add("stl_binary_solid_header_wrong_count.stl", b"solid " + stl_binary(v, f, count=len(f) + 3)[6:])
    for drop in ["endloop", "endfacet", "endsolid", "outer loop", "facet normal 0 0 1"]:
        c.add("stl_no_%s.stl" % drop.split()[0], stl_ascii(sv, sf, drop=drop))
    c.add("stl_no_newline.stl", stl_ascii(sv, sf, newline_at_end=False))
    c.add("stl_two_solids.stl", stl_ascii(sv, sf) + stl_ascii(tet_v, tet_f))
    c.add("stl_solid_only.stl", b"solid x\n")
    c.add("stl_solid_endsolid.stl", b"solid x\nendsolid x")
    c.add("stl_ascii_garbage.stl", stl_ascii(tet_v, tet_f).replace(b"vertex 1.0", b"vertex 1.0x", 1))
    c.add("stl_ascii_crlf.stl", stl_ascii(sv, sf).replace(b"\n", b"\r\n"))
    c.add("stl_ascii_upper.stl", stl_ascii(tet_v, tet_f).upper())

    # Empty and nearly empty files.
    for ext in ["ply", "off", "obj", "stl"]:
        c.add("empty." + ext, b"")
        c.add("whitespace." + ext, b" \n\t\n")
        c.add("nul." + ext, b"\0" * 200)
        c.add("one_byte." + ext, b"p")
        c.add("random_bytes." + ext, bytes(rng.randrange(256) for _ in range(rng.randrange(1, 3000))))
    c.add("ply_header_only.ply", b"ply\nformat ascii 1.0\nend_header\n")
    c.add("ply_magic_only.ply", b"ply\n")
    c.add("ply_long_line.ply", b"ply\nformat ascii 1.0\ncomment " + b"x" * 500000 + b"\nend_header\n")
    c.add("ply_crlf.ply", ply_ascii(v, f).replace(b"\n", b"\r\n"))
    c.add("ply_bom.ply", b"\xef\xbb\xbf" + ply_ascii(tet_v, tet_f))
    c.add("ply_wrong_format.ply", ply_ascii(tet_v, tet_f).replace(b"ascii", b"binary_middle_endian"))
    c.add("ply_ascii_said_binary.ply", ply_ascii(tet_v, tet_f).replace(b"ascii", b"binary_little_endian"))
    c.add("ply_binary_said_ascii.ply", ply_binary(v, f).replace(b"binary_little_endian", b"ascii", 1))
    c.add("wrong_ext_ply_as.off", valid["ply_le.ply"])
    c.add("wrong_ext_off_as.ply", valid["off.off"])
    c.add("wrong_ext_stl_as.obj", valid["stl_binary.stl"])
    c.add("wrong_ext_obj_as.stl", valid["obj.obj"])

    # Random byte flips of valid binary files, token swaps of valid text files.
    for name in ["ply_le.ply", "ply_be.ply", "stl_binary.stl"]:
        data = valid[name]
        for _ in range(60 * copies):
            b = bytearray(data)
            for _ in range(rng.choice([1, 2, 4, 16])):
                b[rng.randrange(len(b))] = rng.randrange(256)
            c.add("flip_" + name, bytes(b))
    junk = ["-1", "0", "nan", "1e38", "x", "4294967296", "-2147483648", "", "3 3", "#", "1.5", "end_header", "OFF",
            "facet", "endloop", "999999999999"]
    for name in ["ply_ascii.ply", "off.off", "obj.obj", "stl_ascii.stl"]:
        tokens = valid[name].split(b" ")
        for _ in range(40 * copies):
            t = list(tokens)
            for _ in range(rng.choice([1, 2, 3])):
                t[rng.randrange(len(t))] = rng.choice(junk).encode()
            c.add("swap_" + name, b" ".join(t))
    make_wrl(c, copies, v, f, tet_v, tet_f)


def make_wrl(c, copies, v, f, tet_v, tet_f):
    """VRML 2.0 files: valid, truncated, token swaps, and the shapes the reader refuses."""
    rng = c.rng
    valid = wrl_text(v, f)
    c.add("valid_wrl.wrl", valid)
    for data in [b"", b" \n", b"\0" * 200, b"#VRML V2.0 utf8\n", bytes(rng.randrange(256) for _ in range(2000))]:
        c.add("wrl_nearly_empty.wrl", data)
    for _ in range(25 * copies):
        c.add("truncated_wrl.wrl", valid[:rng.randrange(1, len(valid))])
    tokens = valid.split(b" ")
    junk = ["-1", "-2", "nan", "1e38", "[", "]", "{", "}", "#", "USE", "DEF", "4294967296", "1.5", '"', "point"]
    for _ in range(40 * copies):
        t = list(tokens)
        for _ in range(rng.choice([1, 2, 3])):
            t[rng.randrange(len(t))] = rng.choice(junk).encode()
        c.add("swap_wrl.wrl", b" ".join(t))
    for bad in ["0 1 4 -1", "0 1 -2 -1", "0 1 -1", "0 1 2.5", "0 1 99999999999999", "-1 -1 -1", " ".join(["0"] * 300)]:
        c.add("wrl_index.wrl", wrl_text(tet_v, tet_f, indices=bad))
    c.add("wrl_v1.wrl", wrl_text(tet_v, tet_f, header="#VRML V1.0 ascii"))
    c.add("wrl_transform.wrl", wrl_text(tet_v, tet_f, wrap=("Transform { scale 2 2 2 children [\n", "] }\n")))
    c.add("wrl_unclosed.wrl", wrl_text(tet_v, tet_f, wrap=("Group { children [\n", "")))
    c.add("wrl_string.wrl", wrl_text(tet_v, tet_f, wrap=('WorldInfo { info [ "a \\" ] {" ] }\n', "")))
    c.add("wrl_deep.wrl", wrl_text(tet_v, tet_f, wrap=("Group { children [ " * 2000, "] } " * 2000)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output_dir")
    parser.add_argument("--seed", type=int, default=29)
    parser.add_argument("--copies", type=int, default=1, help="multiplies the random classes")
    args = parser.parse_args()
    out = os.path.abspath(args.output_dir)
    repo = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
    if out == repo or out.startswith(repo + os.sep):
        sys.exit("make_hostile_inputs: write the corpus outside the repository, not into " + out)
    os.makedirs(out, exist_ok=True)
    if os.listdir(out):
        sys.exit("make_hostile_inputs: %s is not empty" % out)
    corpus = Corpus(out, args.seed)
    make(corpus, args.copies)
    print("make_hostile_inputs: %d files in %s (seed %d)" % (corpus.count, out, args.seed))


if __name__ == "__main__":
    main()
