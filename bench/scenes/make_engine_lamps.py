#!/usr/bin/env python3
"""Writes two variants of scenes/engine_room.json whose ceiling light is many
triangles, for the zone tracer's light tree (more than 16 light parts):

  engine_lamp128.json   the same 100 x 100 lamp cut into 128 triangles by
                        midpoints (the same light, written as a model would);
  engine_panels16.json  16 separate square panels of 20 x 20 (32 triangles)
                        spread over the ceiling, their emission scaled so that
                        they send the lamp's power.

Usage: bench/scenes/make_engine_lamps.py   (from the repository's root)"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
ROOM = os.path.join(HERE, "..", "..", "scenes", "engine_room.json")


def cut(t, levels):
    if levels == 0:
        return [t]
    a, b, c = t
    mid = lambda p, q: [(p[i] + q[i]) / 2 for i in range(3)]
    ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
    return (cut([a, ab, ca], levels - 1) + cut([ab, b, bc], levels - 1) +
            cut([ca, bc, c], levels - 1) + cut([ab, bc, ca], levels - 1))


def write(name, scene):
    with open(os.path.join(HERE, name), "w") as f:
        f.write("{\n\"camera\": " + json.dumps(scene["camera"]) + ",\n\"scene\": [\n")
        f.write(",\n".join(json.dumps(item) for item in scene["scene"]))
        f.write("\n]}\n")


def main():
    with open(ROOM) as f:
        room = json.load(f)
    light = room["scene"][0]["light"]
    tris = [p["lighttriangle"]["points"] for p in light["parts"]]

    lamp = json.loads(json.dumps(room))
    lamp["scene"][0]["light"]["parts"] = [
        {"lighttriangle": {"points": t}} for tri in tris for t in cut(tri, 3)]
    write("engine_lamp128.json", lamp)

    panels = json.loads(json.dumps(room))
    parts, y = [], tris[0][0][1]
    for i in range(4):
        for j in range(4):
            x0, z0 = 50 + 90 * i, 50 + 90 * j
            x1, z1 = x0 + 20, z0 + 20
            parts.append({"lighttriangle": {"points": [[x0, y, z0], [x1, y, z0], [x1, y, z1]]}})
            parts.append({"lighttriangle": {"points": [[x0, y, z0], [x1, y, z1], [x0, y, z1]]}})
    panels["scene"][0]["light"]["parts"] = parts
    panels["scene"][0]["light"]["emission"] = [e * 10000 / 6400 for e in light["emission"]]
    write("engine_panels16.json", panels)


if __name__ == "__main__":
    main()
