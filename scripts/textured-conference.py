#!/usr/bin/env python3
"""A textured copy of the shared conference room, for the texture benchmark.

    scripts/textured-conference.py SHARED_SCENES_CONFERENCE OUTDIR [--size N]

Writes into OUTDIR:
  conference-textured.obj   the room with texture coordinates: each face projected
                            on the plane of its normal's largest axis, one texture
                            period per 100 model units (box mapping)
  conference-textured.mtl   the room's materials, each with `map_Kd` of its own
                            N x N texture (default 1024) and Kd = 2 * its Kd, so
                            that its texture (mean about 0.5 linear) keeps its albedo
  tex-MATERIAL.png          the textures: per-texel noise over a checker of 8 x 8
                            texel cells, sRGB, no alpha
  textured.toml             the scene (camera, film and lights of scene.toml)
  averaged.toml             the same with every texture averaged ([materials.NAME]
                            texture = false): what the texture lookups cost is the
                            difference of the two frames

Needs only Python's standard library. The output is large (the OBJ is about 20 MB):
write it to an ignored folder (.bench/), never into git.
"""

import argparse
import os
import random
import struct
import sys
import zlib


def write_png(path, size, texel):
    """An 8-bit RGB PNG of size x size whose texel (x, y) is texel(x, y)."""
    rows = bytearray()
    for y in range(size):
        rows.append(0)
        for x in range(size):
            rows.extend(texel(x, y))

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(rows), 6))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("conference", help="the shared conference folder (conference.obj, .mtl, scene.toml)")
    ap.add_argument("out", help="output folder")
    ap.add_argument("--size", type=int, default=1024, help="texture side in texels (default 1024)")
    ap.add_argument("--period", type=float, default=100.0, help="model units per texture period")
    args = ap.parse_args()
    src = args.conference
    for name in ("conference.obj", "conference.mtl", "scene.toml"):
        if not os.path.isfile(os.path.join(src, name)):
            sys.exit(f"textured-conference: {src} has no {name}")
    os.makedirs(args.out, exist_ok=True)

    # Materials: Kd doubled (the textures' mean is about 0.5 linear), capped so that
    # Kd + Ks stays an albedo, and map_Kd added.
    materials = []
    mtl_out = []
    with open(os.path.join(src, "conference.mtl")) as f:
        for line in f:
            words = line.split()
            if words[:1] == ["newmtl"]:
                materials.append(words[1])
                mtl_out.append(line.rstrip("\n"))
                mtl_out.append(f"map_Kd tex-{words[1]}.png")
            elif words[:1] == ["Kd"]:
                kd = [min(2.0 * float(v), 0.74) for v in words[1:4]]
                mtl_out.append("Kd " + " ".join(f"{v:.6f}" for v in kd))
            else:
                mtl_out.append(line.rstrip("\n"))
    with open(os.path.join(args.out, "conference-textured.mtl"), "w") as f:
        f.write("\n".join(mtl_out) + "\n")

    rng = random.Random(1)
    for m in materials:
        seed = rng.randrange(1 << 30)

        def texel(x, y, seed=seed):
            h = (x * 73856093 ^ y * 19349663 ^ seed) & 0xFFFFFFFF
            h = (h * 2654435761) & 0xFFFFFFFF
            cell = ((x >> 3) + (y >> 3)) & 1
            base = 150 if cell else 230
            return bytes(max(0, min(255, base - ((h >> s) & 63))) for s in (0, 8, 16))

        write_png(os.path.join(args.out, f"tex-{m}.png"), args.size, texel)

    # Geometry: the OBJ's vertices, then one vt per face corner by box mapping.
    verts = []
    out = []
    vt_count = 0
    with open(os.path.join(src, "conference.obj")) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(tuple(float(v) for v in line.split()[1:4]))
                out.append(line.rstrip("\n"))
            elif line.startswith("f "):
                idx = [int(w.split("/")[0]) for w in line.split()[1:]]
                p = [verts[i - 1 if i > 0 else len(verts) + i] for i in idx]
                e1 = [p[1][k] - p[0][k] for k in range(3)]
                e2 = [p[2][k] - p[0][k] for k in range(3)]
                n = [
                    abs(e1[1] * e2[2] - e1[2] * e2[1]),
                    abs(e1[2] * e2[0] - e1[0] * e2[2]),
                    abs(e1[0] * e2[1] - e1[1] * e2[0]),
                ]
                axis = n.index(max(n))
                a, b = [(1, 2), (0, 2), (0, 1)][axis]
                corners = []
                for i, q in zip(idx, p):
                    vt_count += 1
                    out.append(f"vt {q[a] / args.period:.5f} {q[b] / args.period:.5f}")
                    corners.append(f"{i}/{vt_count}")
                out.append("f " + " ".join(corners))
            elif line.startswith("mtllib"):
                out.append("mtllib conference-textured.mtl")
            else:
                out.append(line.rstrip("\n"))
    with open(os.path.join(args.out, "conference-textured.obj"), "w") as f:
        f.write("\n".join(out) + "\n")

    with open(os.path.join(src, "scene.toml")) as f:
        scene = f.read().replace('path = "conference.obj"', 'path = "conference-textured.obj"')
    header = "# Written by scripts/textured-conference.py from the shared conference room.\n"
    with open(os.path.join(args.out, "textured.toml"), "w") as f:
        f.write(header + scene)
    with open(os.path.join(args.out, "averaged.toml"), "w") as f:
        f.write(header + "# Every texture replaced by its mean colour.\n" + scene)
        for m in materials:
            f.write(f"\n[materials.{m}]\ntexture = false\n")
    print(f"textured-conference: {len(materials)} materials, {args.size}^2 textures, in {args.out}")


if __name__ == "__main__":
    main()
