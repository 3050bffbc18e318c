#!/usr/bin/env python3
"""Writes a small glTF 2.0 model with a metallic-roughness texture and a normal texture, in plain
Python (json, struct, zlib): a test model for model files' materials.

    python3 tools/make_pbr_gltf.py OUT.gltf [--rough R] [--metal M] [--tilt DEG] [--scale S]
                                   [--size N] [--tangents] [--base-size N] [--color R G B]
                                   [--no-normal] [--no-mr] [--metal-right M]
                                   [--alpha-mode MODE] [--alpha A] [--alpha-cutoff C]
                                   [--stripes] [--specular F]

The model is one square of side 2 in the plane y = 0, centred on the origin, its front face (and
normal) up, +x along the texture's u and -z along its v (so the image's left half is x < 0 and
its top row is z = -1).  Next to OUT go OUT's stem + ".bin" (the buffer), "_mr.png" (the
metallic-roughness texture) and "_n.png" (the normal texture), all named relative to the .gltf.
The textures are N x N texels (--size, default 4), in halves along u:

  metallic-roughness (linear, glTF's channels: G roughness, B metallic)
      left half   G = round(255 R), B = round(255 M)      (--rough, default 1; --metal, default 1)
      right half  G = 0,            B = round(255 M)      (a smooth metal beside a rough one;
                                                          --metal-right sets the right half's M)
  normal (linear, tangent space: x along +u, y along +v, z out of the surface)
      left half   the normal tilted by DEG degrees toward +u (--tilt, default 0):
                  (sin, 0, cos) coded as round(255 (c + 1) / 2)
      right half  (0, 0, 1) coded the same way: (128, 128, 255)

The material: baseColorFactor --color (default 1 1 1), metallicFactor and roughnessFactor 1
(the texture holds the values), normalTexture.scale --scale (default 1).  With --base-size N a
white base-colour texture of N x N texels is written too ("_base.png"), to try a base texture
whose size differs from the maps'.  With --tangents the vertices carry TANGENT (+x, w = +1);
without, the reader makes its own.  --no-normal leaves the normal texture out, --no-mr the
metallic-roughness one (the factors then give metallic --metal and roughness --rough).

--specular F writes KHR_materials_specular with specularFactor F (0: no layer over the
non-metal's base, so that its light is the Lambertian formula's).
--alpha-mode writes the material's alphaMode (OPAQUE, MASK or BLEND), --alpha the base colour
factor's alpha (default 1), --alpha-cutoff its alphaCutoff as given (even outside [0, 1], or nan,
which json writes as the non-standard NaN: for tests of bad input).  --stripes writes a white
base-colour texture of N x N texels ("_base.png", RGBA) whose alpha alternates along u, column by
column: 255 in the even columns (the first at x = -1), 0 in the odd ones, so that the square's
N stripes of width 2/N alternate between covered and not.

Texel codes are exact: a test computes what it expects from the same rounding.

"make_pbr_gltf.py emissive OUT.gltf ..." writes a square lamp with an emissive texture, and
"make_pbr_gltf.py alpha-emissive OUT.gltf ..." an alpha-masked textured panel beside such a lamp
(their usage: run them without OUT).
"""
import json
import math
import os
import struct
import sys
import zlib


def png(path, width, height, rows):
    """An 8-bit RGB (or RGBA, for texels of four values) PNG without colour-space chunks (glTF's
    maps are linear)."""

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xffffffff)

    raw = b"".join(b"\x00" + bytes(v for texel in row for v in texel) for row in rows)
    colour_type = 6 if len(rows[0][0]) == 4 else 2
    data = (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


def code(c):
    return int(round(255 * (c + 1) / 2))


def halves(n, left, right):
    return [[left if i < n // 2 else right for i in range(n)] for _ in range(n)]


def main(argv):
    args = {"rough": 1.0, "metal": 1.0, "tilt": 0.0, "scale": 1.0, "size": 4, "tangents": False,
            "base_size": 0, "color": [1.0, 1.0, 1.0], "normal": True, "mr": True,
            "alpha_mode": None, "alpha": 1.0, "alpha_cutoff": None, "stripes": False,
            "specular": None}
    out = None
    i = 0
    try:
        while i < len(argv):
            a = argv[i]
            if a in ("--rough", "--metal", "--tilt", "--scale", "--metal-right", "--alpha",
                     "--alpha-cutoff", "--specular"):
                args[a[2:].replace("-", "_")] = float(argv[i + 1])
                i += 2
            elif a in ("--size", "--base-size"):
                args[a[2:].replace("-", "_")] = int(argv[i + 1])
                i += 2
            elif a == "--color":
                args["color"] = [float(v) for v in argv[i + 1:i + 4]]
                i += 4
            elif a == "--alpha-mode":
                if argv[i + 1] not in ("OPAQUE", "MASK", "BLEND"):
                    raise ValueError(argv[i + 1])
                args["alpha_mode"] = argv[i + 1]
                i += 2
            elif a in ("--tangents", "--stripes"):
                args[a[2:]] = True
                i += 1
            elif a in ("--no-normal", "--no-mr"):
                args[a[5:]] = False
                i += 1
            elif a.startswith("-") or out:
                raise ValueError(a)
            else:
                out = a
                i += 1
    except (ValueError, IndexError):
        out = None
    if not out or not out.endswith(".gltf") or args["size"] < 2 or args["size"] % 2:
        sys.stderr.write(__doc__)
        return 1
    folder, name = os.path.split(out)
    stem = name[:-len(".gltf")]
    n = args["size"]
    r = max(0, min(255, int(round(255 * args["rough"]))))
    m = max(0, min(255, int(round(255 * args["metal"]))))
    mr = max(0, min(255, int(round(255 * args.get("metal_right", args["metal"])))))
    if args["mr"]:
        png(os.path.join(folder, stem + "_mr.png"), n, n, halves(n, (0, r, m), (0, 0, mr)))
    t = math.radians(args["tilt"])
    if args["normal"]:
        png(os.path.join(folder, stem + "_n.png"), n, n,
            halves(n, (code(math.sin(t)), code(0), code(math.cos(t))), (code(0), code(0), code(1))))

    # Two triangles, counter-clockwise seen from +y.
    pos = [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]  # glTF: v down the image, so z = -1 is the top row
    nrm = [(0, 1, 0)] * 4
    tan = [(1, 0, 0, 1)] * 4
    idx = [0, 1, 2, 0, 2, 3]
    blobs = [b"".join(struct.pack("<3f", *p) for p in pos), b"".join(struct.pack("<3f", *p) for p in nrm),
             b"".join(struct.pack("<2f", *p) for p in uv), struct.pack("<6H", *idx) + b"\x00\x00"]
    if args["tangents"]:
        blobs.append(b"".join(struct.pack("<4f", *p) for p in tan))
    views, offset = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b)})
        offset += len(b)
    buffer = b"".join(blobs)
    with open(os.path.join(folder, stem + ".bin"), "wb") as f:
        f.write(buffer)
    views[3]["byteLength"] = 12
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1],
         "max": [1, 0, 1]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ]
    attributes = {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}
    if args["tangents"]:
        accessors.append({"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"})
        attributes["TANGENT"] = 4
    images = []
    pbr = {"baseColorFactor": args["color"] + [args["alpha"]], "metallicFactor": 1.0,
           "roughnessFactor": 1.0}
    if args["mr"]:
        pbr["metallicRoughnessTexture"] = {"index": len(images)}
        images.append({"uri": stem + "_mr.png"})
    else:
        pbr["metallicFactor"], pbr["roughnessFactor"] = args["metal"], args["rough"]
    material = {"name": "pbr", "pbrMetallicRoughness": pbr}
    if args["specular"] is not None:
        material["extensions"] = {"KHR_materials_specular": {"specularFactor": args["specular"]}}
    if args["normal"]:
        material["normalTexture"] = {"index": len(images), "scale": args["scale"]}
        images.append({"uri": stem + "_n.png"})
    if args["alpha_mode"]:
        material["alphaMode"] = args["alpha_mode"]
    if args["alpha_cutoff"] is not None:
        material["alphaCutoff"] = args["alpha_cutoff"]
    if args["stripes"]:
        png(os.path.join(folder, stem + "_base.png"), n, n,
            [[(255, 255, 255, 0 if i % 2 else 255) for i in range(n)]] * n)
        pbr["baseColorTexture"] = {"index": len(images)}
        images.append({"uri": stem + "_base.png"})
    elif args["base_size"] > 0:
        b = args["base_size"]
        png(os.path.join(folder, stem + "_base.png"), b, b, [[(255, 255, 255)] * b] * b)
        pbr["baseColorTexture"] = {"index": len(images)}
        images.append({"uri": stem + "_base.png"})
    doc = {
        "asset": {"version": "2.0", "generator": "zonetrace tools/make_pbr_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0}]}],
        "materials": [material],
        # Nearest filtering is not asked for: the renderer filters bilinearly anyway, and the
        # halves are wide enough to be read away from their border.
        "samplers": [{"wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": k, "sampler": 0} for k in range(len(images))],
        "images": images,
        "buffers": [{"uri": stem + ".bin", "byteLength": len(buffer)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    if args["specular"] is not None:
        doc["extensionsUsed"] = ["KHR_materials_specular"]
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    return 0


EMISSIVE_USAGE = """Writes a square lamp: make_pbr_gltf.py's square (side 2 in y = 0, front face up, +x along u,
-z along v) whose material emits through an emissive texture of N x N texels (--size, default 8),
sRGB, in halves along u: the left half (x < 0) LEFT (--left R G B, codes 0-255, default 255 255
255), the right half black.

    python3 tools/make_pbr_gltf.py emissive OUT.gltf [--size N] [--left R G B] [--factor R G B]
                                   [--strength S] [--no-factor]

The material: baseColorFactor white, metallic 0, emissiveFactor --factor (default 1 1 1; with
--no-factor none, which glTF reads as black), KHR_materials_emissive_strength --strength (left out
when 1).  Next to OUT go OUT's stem + ".bin" and "_e.png".
"""


def emissive_main(argv):
    """A square lamp with an emissive texture (EMISSIVE_USAGE)."""
    opt = {"size": 8, "left": [255, 255, 255], "factor": [1.0, 1.0, 1.0], "strength": 1.0}
    out = None
    i = 0
    try:
        while i < len(argv):
            a = argv[i]
            if a == "--size":
                opt["size"] = int(argv[i + 1])
                i += 2
            elif a == "--strength":
                opt["strength"] = float(argv[i + 1])
                i += 2
            elif a in ("--left", "--factor"):
                opt[a[2:]] = [(int if a == "--left" else float)(v) for v in argv[i + 1:i + 4]]
                if len(opt[a[2:]]) != 3:
                    raise ValueError(a)
                i += 4
            elif a == "--no-factor":
                opt["factor"] = None
                i += 1
            elif a.startswith("-") or out:
                raise ValueError(a)
            else:
                out = a
                i += 1
    except (ValueError, IndexError):
        out = None
    if not out or not out.endswith(".gltf") or opt["size"] < 2 or opt["size"] % 2:
        sys.stderr.write(EMISSIVE_USAGE)
        return 1
    folder, name = os.path.split(out)
    stem = name[:-len(".gltf")]
    n = opt["size"]
    uri = stem + "_e.png"
    png(os.path.join(folder, uri), n, n, halves(n, tuple(opt["left"]), (0, 0, 0)))
    pos = [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    nrm = [(0, 1, 0)] * 4
    idx = [0, 1, 2, 0, 2, 3]
    blobs = [b"".join(struct.pack("<3f", *p) for p in pos), b"".join(struct.pack("<3f", *p) for p in nrm),
             b"".join(struct.pack("<2f", *p) for p in uv), struct.pack("<6H", *idx) + b"\x00\x00"]
    views, offset = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(b)})
        offset += len(b)
    views[3]["byteLength"] = 12
    buffer = b"".join(blobs)
    with open(os.path.join(folder, stem + ".bin"), "wb") as f:
        f.write(buffer)
    material = {"name": "lamp",
                "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0},
                "emissiveTexture": {"index": 0}}
    if opt["factor"] is not None:
        material["emissiveFactor"] = opt["factor"]
    doc = {
        "asset": {"version": "2.0", "generator": "zonetrace tools/make_pbr_gltf.py emissive"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                    "indices": 3, "material": 0}]}],
        "materials": [material],
        "samplers": [{"wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": 0, "sampler": 0}],
        "images": [{"uri": uri}],
        "buffers": [{"uri": stem + ".bin", "byteLength": len(buffer)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1],
             "max": [1, 0, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    if opt["strength"] != 1.0:
        material["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": opt["strength"]}}
        doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    return 0


ALPHA_EMISSIVE_USAGE = """Writes a model of two parts in one mesh (two primitives, two materials) in the plane y = 0,
front faces up, +x along u and -z along v as make_pbr_gltf.py's square:

    python3 tools/make_pbr_gltf.py alpha-emissive OUT.gltf [--size N] [--cutoff C]
                                   [--strength S] [--factor R G B] [--lamp-grid M]
                                   [--color R G B]

panel  a square of side 2 centred on (-1.2, 0, 0), alphaMode MASK with alphaCutoff --cutoff
       (default 0.5).  Its textures have N x N texels (--size, a multiple of 4, default 16):
       base colour (sRGB, RGBA) white, its alpha 0 in square holes of 2 x 2 texels on a pitch of
       4 (texels i, j with i mod 4 and j mod 4 both 1 or 2), 255 elsewhere: (N/4)^2 holes of
       side 4/N with bars of the same width between them, and a border half as wide;
       baseColorFactor --color (default 0.8 0.6 0.4), alpha 1; metallic-roughness (linear) in halves along u: the left
       half metal (B 255), roughness 128/255, the right half metallic 0, roughness 153/255;
       normal (linear): the left half tilted 30 degrees toward +u, the right half (0, 0, 1).
       Light, the background and the part's shadow go through the holes.
lamp   a square of side 1.2 centred on (1.0, 0, 0), cut into M x M squares of two triangles
       each (--lamp-grid, default 8; small light triangles, which Cycles samples exactly), opaque,
       baseColorFactor 0 0 0 1, metallic 0, roughness 1 (so that it reflects nothing but, in
       glTF, the dielectric specular layer: zonetrace's emissive triangles are lights, which
       reflect nothing), an emissive texture of 8 x 8 texels (sRGB) in a checker of 2 x 2 texel
       squares, white and orange (255 140 0), the top-left one white; emissiveFactor --factor
       (default 1 0.9 0.8), KHR_materials_emissive_strength --strength (default 8).

Next to OUT go OUT's stem + ".bin", "_base.png", "_mr.png", "_n.png" and "_e.png".
"""


def alpha_emissive_main(argv):
    """A masked, textured panel beside a lamp with an emissive texture (ALPHA_EMISSIVE_USAGE)."""
    opt = {"size": 16, "cutoff": 0.5, "strength": 8.0, "factor": [1.0, 0.9, 0.8], "lamp_grid": 8,
           "color": [0.8, 0.6, 0.4]}
    out = None
    i = 0
    try:
        while i < len(argv):
            a = argv[i]
            if a in ("--size", "--lamp-grid"):
                opt[a[2:].replace("-", "_")] = int(argv[i + 1])
                i += 2
            elif a in ("--cutoff", "--strength"):
                opt[a[2:]] = float(argv[i + 1])
                i += 2
            elif a in ("--factor", "--color"):
                opt[a[2:]] = [float(v) for v in argv[i + 1:i + 4]]
                if len(opt[a[2:]]) != 3:
                    raise ValueError(a)
                i += 4
            elif a.startswith("-") or out:
                raise ValueError(a)
            else:
                out = a
                i += 1
    except (ValueError, IndexError):
        out = None
    if (not out or not out.endswith(".gltf") or opt["size"] < 4 or opt["size"] % 4
            or opt["lamp_grid"] < 1):
        sys.stderr.write(ALPHA_EMISSIVE_USAGE)
        return 1
    folder, name = os.path.split(out)
    stem = name[:-len(".gltf")]
    n = opt["size"]

    def hole(k):
        return k % 4 in (1, 2)

    png(os.path.join(folder, stem + "_base.png"), n, n,
        [[(255, 255, 255, 0 if hole(i) and hole(j) else 255) for i in range(n)] for j in range(n)])
    png(os.path.join(folder, stem + "_mr.png"), n, n, halves(n, (0, 128, 255), (0, 153, 0)))
    t = math.radians(30)
    png(os.path.join(folder, stem + "_n.png"), n, n,
        halves(n, (code(math.sin(t)), code(0), code(math.cos(t))), (code(0), code(0), code(1))))
    png(os.path.join(folder, stem + "_e.png"), 8, 8,
        [[(255, 255, 255) if (i // 2 + j // 2) % 2 == 0 else (255, 140, 0) for i in range(8)]
         for j in range(8)])

    # The panel: two triangles, counter-clockwise seen from +y.
    cx = -1.2
    pos = [(cx - 1, 0, 1), (cx + 1, 0, 1), (cx + 1, 0, -1), (cx - 1, 0, -1)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    idx = [0, 1, 2, 0, 2, 3]
    # The lamp: an M x M grid, vertex (i, j) at u = i / M, v = j / M.
    m, side, lx = opt["lamp_grid"], 1.2, 1.0
    lpos, luv, lidx = [], [], []
    for j in range(m + 1):
        for i in range(m + 1):
            u, v = i / m, j / m
            lpos.append((lx + side * (u - 0.5), 0, side * (v - 0.5)))
            luv.append((u, v))
    for j in range(m):
        for i in range(m):
            a, b = j * (m + 1) + i, j * (m + 1) + i + 1
            c, d = a + m + 1, b + m + 1  # v grows toward +z: (a, c, d, b) turns counter-clockwise
            lidx += [a, c, d, a, d, b]

    def f3(ps):
        return b"".join(struct.pack("<3f", *p) for p in ps)

    def f2(ps):
        return b"".join(struct.pack("<2f", *p) for p in ps)

    def u16(ix):
        b = struct.pack("<%dH" % len(ix), *ix)
        return b + b"\x00" * (-len(b) % 4)

    blobs = [f3(pos), f3([(0, 1, 0)] * 4), f2(uv), u16(idx),
             f3(lpos), f3([(0, 1, 0)] * len(lpos)), f2(luv), u16(lidx)]
    lengths = [len(b) for b in blobs]
    lengths[3], lengths[7] = 2 * len(idx), 2 * len(lidx)
    views, offset = [], 0
    for b, length in zip(blobs, lengths):
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": length})
        offset += len(b)
    buffer = b"".join(blobs)
    with open(os.path.join(folder, stem + ".bin"), "wb") as f:
        f.write(buffer)
    half = side / 2
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [cx - 1, 0, -1], "max": [cx + 1, 0, 1]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": len(idx), "type": "SCALAR"},
        {"bufferView": 4, "componentType": 5126, "count": len(lpos), "type": "VEC3",
         "min": [lx - half, 0, -half], "max": [lx + half, 0, half]},
        {"bufferView": 5, "componentType": 5126, "count": len(lpos), "type": "VEC3"},
        {"bufferView": 6, "componentType": 5126, "count": len(lpos), "type": "VEC2"},
        {"bufferView": 7, "componentType": 5123, "count": len(lidx), "type": "SCALAR"},
    ]
    images = [{"uri": stem + s} for s in ("_base.png", "_mr.png", "_n.png", "_e.png")]
    panel = {"name": "panel",
             "pbrMetallicRoughness": {"baseColorFactor": opt["color"] + [1.0],
                                      "baseColorTexture": {"index": 0},
                                      "metallicFactor": 1.0, "roughnessFactor": 1.0,
                                      "metallicRoughnessTexture": {"index": 1}},
             "normalTexture": {"index": 2, "scale": 1.0},
             "alphaMode": "MASK", "alphaCutoff": opt["cutoff"]}
    lamp = {"name": "lamp",
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0,
                                     "roughnessFactor": 1.0},
            "emissiveTexture": {"index": 3}, "emissiveFactor": opt["factor"]}
    doc = {
        "asset": {"version": "2.0", "generator": "zonetrace tools/make_pbr_gltf.py alpha-emissive"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
             "material": 0},
            {"attributes": {"POSITION": 4, "NORMAL": 5, "TEXCOORD_0": 6}, "indices": 7,
             "material": 1}]}],
        "materials": [panel, lamp],
        "samplers": [{"wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": k, "sampler": 0} for k in range(len(images))],
        "images": images,
        "buffers": [{"uri": stem + ".bin", "byteLength": len(buffer)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    if opt["strength"] != 1.0:
        lamp["extensions"] = {"KHR_materials_emissive_strength":
                              {"emissiveStrength": opt["strength"]}}
        doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    return 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["emissive"]:
        sys.exit(emissive_main(sys.argv[2:]))
    if sys.argv[1:2] == ["alpha-emissive"]:
        sys.exit(alpha_emissive_main(sys.argv[2:]))
    sys.exit(main(sys.argv[1:]))
