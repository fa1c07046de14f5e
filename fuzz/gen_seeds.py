#!/usr/bin/env python3
"""Writes the committed seed corpora of the fuzz targets into fuzz/seeds/<target>/.

Generated inputs (tiny valid files of each format and flavour, plus near-misses) and a few
small files derived from the shared corpus (../shared/meshes, or $PLEAT_MESHES): the first
vertices and the faces among them. Deterministic; rerun after changing a target's input
layout:  python3 fuzz/gen_seeds.py
"""
import base64, json, math, os, struct, sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "seeds")
MESHES = os.environ.get("PLEAT_MESHES") or os.path.join(HERE, "..", "..", "shared", "meshes")
if not os.path.isdir(MESHES):
    MESHES = "/work/shared/meshes"

TET_P = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TET_T = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
# octahedron of pleat_fuzz::octahedron()
OCT_P = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
OCT_T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


def put(target, name, data):
    d = os.path.join(OUT, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


def shared_subset(path, max_v):
    """(positions, triangles) of the first max_v vertices of a shared mesh and its faces among them."""
    full = os.path.join(MESHES, path)
    if not os.path.exists(full):
        print(f"note: {full} missing, derived seed skipped", file=sys.stderr)
        return None
    pts, tris = [], []
    if path.endswith(".obj"):
        for line in open(full, errors="replace"):
            f = line.split()
            if f[:1] == ["v"] and len(pts) < max_v:
                pts.append(tuple(float(x) for x in f[1:4]))
            elif f[:1] == ["f"]:
                idx = [int(x.split("/")[0]) - 1 for x in f[1:]]
                if all(0 <= i < max_v for i in idx):
                    tris.extend((idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1))
    elif path.endswith(".off"):
        tok = open(full).read().split()
        nv, nf = int(tok[1]), int(tok[2])
        at = 4
        for i in range(nv):
            if i < max_v:
                pts.append(tuple(float(x) for x in tok[at:at + 3]))
            at += 3
        for _ in range(nf):
            k = int(tok[at])
            idx = [int(x) for x in tok[at + 1:at + 1 + k]]
            at += 1 + k
            if all(i < max_v for i in idx):
                tris.append(tuple(idx[:3]))
    elif path.endswith(".ply"):
        raw = open(full, "rb").read()
        end = raw.index(b"end_header\n") + len(b"end_header\n")
        head = raw[:end].decode()
        nv = int(head.split("element vertex ")[1].split()[0])
        nf = int(head.split("element face ")[1].split()[0])
        for i in range(min(nv, max_v)):
            pts.append(struct.unpack_from("<3f", raw, end + 12 * i))
        at = end + 12 * nv
        for _ in range(min(nf, 4 * max_v)):
            k = raw[at]
            idx = struct.unpack_from(f"<{k}i", raw, at + 1)
            at += 1 + 4 * k
            if all(i < max_v for i in idx):
                tris.append(tuple(idx[:3]))
    return (pts, tris) if tris else None


def obj(p, t):
    return "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in p) + "".join(
        f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in t)


def off(p, t):
    return f"OFF\n{len(p)} {len(t)} 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in p) + "".join(
        f"3 {a} {b} {c}\n" for a, b, c in t)


def ply_ascii(p, t):
    return ("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list uchar int vertex_indices\n"
            "end_header\n" % (len(p), len(t)) + "".join(f"{x} {y} {z}\n" for x, y, z in p)
            + "".join(f"3 {a} {b} {c}\n" for a, b, c in t))


def ply_binary(p, t, endian="<", coord="double", idx="uint"):
    name = "little" if endian == "<" else "big"
    head = ("ply\nformat binary_%s_endian 1.0\nelement vertex %d\nproperty %s x\nproperty %s y\n"
            "property %s z\nelement face %d\nproperty list uchar %s vertex_indices\nend_header\n"
            % (name, len(p), coord, coord, coord, len(t), idx)).encode()
    cf = {"double": "d", "float": "f"}[coord]
    inf = {"uint": "I", "int": "i", "ushort": "H", "uchar": "B"}[idx]
    body = b"".join(struct.pack(endian + "3" + cf, *v) for v in p)
    body += b"".join(struct.pack(endian + "B3" + inf, 3, *f) for f in t)
    return head + body


def stl_ascii(p, t):
    s = "solid seed\n"
    for f in t:
        s += " facet normal 0 0 0\n  outer loop\n"
        s += "".join("   vertex %r %r %r\n" % p[i] for i in f)
        s += "  endloop\n endfacet\n"
    return s + "endsolid seed\n"


def stl_binary(p, t):
    b = b"binary seed".ljust(80, b" ") + struct.pack("<I", len(t))
    for f in t:
        b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *p[i]) for i in f) + b"\0\0"
    return b


def gltf_parts(p, t, nested=0):
    pos = b"".join(struct.pack("<3f", *v) for v in p)
    ind = b"".join(struct.pack("<3H", *f) for f in t)
    ind += b"\0" * (-len(ind) % 4)
    buf = pos + ind
    lo = [min(v[i] for v in p) for i in range(3)]
    hi = [max(v[i] for v in p) for i in range(3)]
    nodes = [{"mesh": 0}] if nested == 0 else \
        [{"children": [i + 1], "translation": [0.5, 0, 0]} for i in range(nested)] + [{"mesh": 0}]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(p), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(t), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": 6 * len(t)},
        ],
        "buffers": [{"byteLength": len(buf)}],
    }
    return doc, buf


def gltf_json(p, t, nested=0):
    doc, buf = gltf_parts(p, t, nested)
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
    return json.dumps(doc, separators=(",", ":"))


def glb(p, t, nested=0):
    doc, buf = gltf_parts(p, t, nested)
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(buf), 0x004E4942) + buf
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def fnv_hash(p, t):
    h = 0xcbf29ce484222325
    data = struct.pack("<QQ", len(p), len(t)) + b"".join(struct.pack("<3I", *f) for f in t)
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def edges(t):
    return sorted({(min(a, b), max(a, b)) for f in t for a, b in zip(f, f[1:] + f[:1])})


def cwf_text(omega, amp, zeta):
    e = edges(OCT_T)
    s = "pleat-cwf 1\nvertices %d\nedges %d\nfaces %d\nconnectivity %016x\nomega\n" % (
        len(OCT_P), len(e), len(OCT_T), fnv_hash(OCT_P, OCT_T))
    s += "".join(f"{a} {b} {w!r}\n" for (a, b), w in zip(e, omega))
    s += "vertex\n" + "".join(f"{a!r} {z[0]!r} {z[1]!r}\n" for a, z in zip(amp, zeta))
    return s + "end\n"


def cwfa_text(intervals, substeps):
    e = edges(OCT_T)
    s = ("pleat-cwf-animation 1\nvertices %d\nedges %d\nfaces %d\nconnectivity %016x\n"
         "guide-frames %d\nsubsteps %d\namplitude\n" % (len(OCT_P), len(e), len(OCT_T),
                                                       fnv_hash(OCT_P, OCT_T), intervals, substeps))
    s += "0.1 0.2\n" * len(OCT_P)
    for n in range(intervals + 1):
        s += f"frame {n}\nomega\n" + "".join(f"{0.25 * (n + 1) * (1 if a % 2 else -1)}\n" for a, _ in e)
        s += "zeta\n" + "1 0\n" * len(OCT_P)
    return s + "end\n"


def main():
    p, t = TET_P, TET_T
    # OBJ
    put("obj", "tet.obj", obj(p, t))
    put("obj", "quad_slashes_neg.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\no a\ng b\nf 1/1/1 2/1/1 3//1 4\n"
        "f -4 -2 -1\nl 1 2\n# comment\n")
    put("obj", "bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    # OFF
    put("off", "tet.off", off(p, t))
    put("off", "noff_comments.off", "OFF # c\n\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 1 0 0\n3 0 2 3\n")
    put("off", "huge_counts.off", "OFF\n4000000000 9000000000 0\n0 0 0\n")
    # PLY
    put("ply", "tet_ascii.ply", ply_ascii(p, t))
    put("ply", "tet_binle_double.ply", ply_binary(p, t))
    put("ply", "tet_binbe_float_ushort.ply", ply_binary(p, t, ">", "float", "ushort"))
    put("ply", "huge_counts.ply", ply_binary(p, t).replace(b"vertex 4", b"vertex 4000000000"))
    # STL
    put("stl", "tet_ascii.stl", stl_ascii(p, t))
    put("stl", "tet_binary.stl", stl_binary(p, t))
    put("stl", "huge_count.stl", stl_binary(p, t)[:80] + struct.pack("<I", 100_000_000) + stl_binary(p, t)[84:])
    # glTF (first byte: 0 = JSON, 1 = GLB)
    put("gltf", "tet.gltf", b"\0" + gltf_json(p, t).encode())
    put("gltf", "tet.glb", b"\1" + glb(p, t))
    put("gltf", "nested.glb", b"\1" + glb(p, t, nested=6))
    # derived from the shared corpus
    for src, fmt, n in [("dirty_suzanne.obj", "obj", 40), ("coarse_decimated-knight.off", "off", 30),
                        ("large_armadillo_loopA.ply", "ply", 30)]:
        sub = shared_subset(src, n)
        if sub:
            sp, st = sub
            if fmt == "obj":
                put("obj", "shared_suzanne40.obj", obj(sp, st))
                put("stl", "shared_suzanne40.stl", stl_binary(sp, st))
                put("gltf", "shared_suzanne40.glb", b"\1" + glb(sp, st))
            elif fmt == "off":
                put("off", "shared_knight30.off", off(sp, st))
            else:
                put("ply", "shared_armadillo30.ply", ply_binary(sp, st, "<", "float", "int"))
    # .cwf / .cwfa on the octahedron
    ne = len(edges(OCT_T))
    put("cwf", "octa.cwf", cwf_text([0.5 * (i % 3 - 1) for i in range(ne)], [0.1] * 6,
                                    [(1.0, 0.0), (0.0, 1.0)] * 3))
    put("cwf", "octa_comments.cwf", "# c\n\n" + cwf_text([0.0] * ne, [0.0] * 6, [(1.0, 0.0)] * 6))
    put("cwfa", "octa_1x2.cwfa", cwfa_text(1, 2))
    put("cwfa", "octa_3x1.cwfa", cwfa_text(3, 1))
    # binary-layout targets: a few hand-made inputs (see each target's byte layout)
    put("mesh_create", "tet_f64", bytes([1, 4, 0, 12]) + bytes(range(64)))
    put("mesh_create", "tet_f32_stride", bytes([0, 4, 2, 12]) + bytes(range(1, 80)))
    put("lod_bake", "small_soup", bytes([0, 5, 6]) + bytes(range(3, 120)))
    put("lod_bake", "cage", bytes([1, 4, 4]) + bytes(range(7, 130)))
    put("wrinkle_eval", "octa_levels", bytes([0]) + bytes([3]) * 60)
    put("wrinkle_eval", "octa_knoppel", bytes([8]) + bytes(range(2, 70)))
    # inputs whose evaluation succeeds (the two above are refused by pleat_cwf_evaluate's
    # parameter checks), so blind mutation (tests/fuzz_smoke.rs) starts next to the deep paths:
    # per value `small()` reads a selector byte (< 250: a small value) and an i8 / 16
    omega = [0, 8, 0, 248] * 6  # 12 edges: ±0.5
    amp = [0, 16] * 6  # 6 vertices: 1/8
    zeta = [0, 16, 0, 0] * 6  # z̃ = (1, 0)
    tail = [2, 63, 0, 0, 1]  # levels 2, every field, fixed boundary, no angle, cap 2^14
    put("wrinkle_eval", "octa_eval_ok", bytes([0] + omega + amp + zeta + tail))
    put("wrinkle_eval", "octa_knoppel_eval_ok", bytes([8] + omega + amp + zeta + tail))  # z̃ read, not passed

    # TFW scene JSON: the small shipped examples (shrunk meshes, so an input meshes in
    # milliseconds), the others' features on tiny panels, and an explicit-array scene
    ex = os.path.join(HERE, "..", "examples", "tfw")
    for name in ["sheared_rectangle.json", "twisted_cylinder.json"]:
        path = os.path.join(ex, name)
        if os.path.exists(path):
            doc = json.load(open(path))
            for panel in doc["panels"]:
                panel["target_vertices"] = 24
            put("tfw_scene", name, json.dumps(doc, separators=(",", ":")))
    disk = [[round(0.1 * math.cos(2 * math.pi * k / 12), 6), round(0.1 * math.sin(2 * math.pi * k / 12), 6)]
            for k in range(12)]
    balloon = {"name": "disk balloon", "material": {"young": 1e6, "poisson": 0.4, "thickness": 1e-4},
               "loads": {"pressure": 100}, "panels": [
                   {"polygon": disk, "target_vertices": 16, "seed": 2, "lens": 0.01},
                   {"polygon": disk, "target_vertices": 16, "seed": 2, "lens": -0.01}],
               "dirichlet": [{"panel": 0, "rest_box": [[-0.2, -0.2], [0.2, -0.09]]}]}
    put("tfw_scene", "disk_balloon_tiny.json", json.dumps(balloon, separators=(",", ":")))
    holed = {"material": {"young": 1e6, "poisson": 0.3, "thickness": 1e-3, "density": 10},
             "loads": {"gravity": [0, 0, -9.81]},
             "panels": [{"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]],
                         "holes": [[[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]],
                         "target_vertices": 20}],
             "obstacles": [{"type": "sphere", "centre": [0.5, 0.5, -0.3], "radius": 0.2},
                           {"type": "plane", "point": [0, 0, -1], "normal": [0, 0, 1],
                            "stiffness": 1e9, "margin": 0}],
             "dirichlet": [{"panel": 0, "rest_box": [[0, 0], [0, 1]]}]}
    put("tfw_scene", "holed_obstacles.json", json.dumps(holed, separators=(",", ":")))
    sheet = {"name": "two triangles", "material": {"young": 1e6, "poisson": 0.3, "thickness": 1e-3},
             "seam_tolerance": 1e-6,
             "panels": [{"rest": [[0, 0], [1, 0], [1, 1], [0, 1]], "triangles": [[0, 1, 2], [0, 2, 3]],
                         "positions": [[0, 0, 0], [1.1, 0, 0], [1.1, 1, 0], [0, 1, 0]]}],
             "dirichlet": [{"panel": 0, "vertices": [0, 3]},
                           {"panel": 0, "vertices": [1, 2], "translation": [0.05, 0, 0]}]}
    put("tfw_scene", "explicit_sheet.json", json.dumps(sheet, separators=(",", ":")))
    put("tfw_scene", "bad_key.json", '{"material":{"yung":1},"panels":[]}')


main()
