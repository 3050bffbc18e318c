"""Renders a zonetrace scene with Blender's Cycles, as an independent reference.

    blender -b -P tools/cycles_reference.py -- SCENE.json OUT.pfm --spp N [--seed S]
            [--bounces B] [--plane-size H] [--threads T]

Writes OUT as linear float RGB (PFM, bottom row first, as zonetrace writes it; an OUT ending in
.exr is written as OpenEXR instead).  Needs Blender 3.4 (scripts/install-reference-tools.sh).

Supported, and nothing else (anything else stops the script with a message naming it):
  top level   "camera", "scene"
  camera      the aimed form only: "position", "lookat", "up" ([0, 1, 0]), "fov" (40, vertical,
              degrees), "gridresolution" ([512, 512]); a pinhole with square pixels
  items       "plane" {"normal", "offset"}: a square of half-size --plane-size (10000) centred
                on the point of the plane nearest the camera's look-at point
              "sphere" {"center", "radius"}: an exact sphere (a Cycles point-cloud point)
              "triangle" {"points"}: flat-shaded
              "thing" {"parts", "material"}: parts are those three primitives and one-key
                {"material": ...} entries; as in zonetrace the last material given wins
              each primitive and thing may carry "material", and "background" / "backculled"
                only when false (Cycles has neither rule)
              "sun" {"direction", "irradiance", "angle" (0.53)}: a sun lamp whose strength is the
                irradiance on a surface facing it (W/m^2, per channel through the lamp colour)
              "sky" {"color"}: the world's background colour (radiance, W/m^2/sr)
              "sky" {"file", "strength" (1), "rotate" (0)}: an equirectangular environment
                texture (OpenEXR, Radiance HDR, or PFM), nearest-texel lookup as zonetrace's
  material    "character" {"diffuse": 1, the other three 0}, "color" (the albedo),
              "refractiveindex" (ignored: it does not affect a diffuse surface); a Diffuse BSDF
              with roughness 0 (Lambertian, as zonetrace's diffuse lobe)
Not supported: lights of any kind, meshes, sky models, a sun by "place", the viewpoint/screen
camera, the legacy non-JSON group syntax.

Frames: zonetrace's +y is Blender's +Z, (x, y, z) -> (x, -z, y).  Render settings: Cycles on the
CPU, box pixel filter 1 pixel wide, no denoising, no adaptive sampling, no clamping, Standard view
transform, caustics on, every bounce limit --bounces (16; Cycles then scatters up to 17 times).
"""
import argparse
import array
import json
import math
import os
import sys
import tempfile
import time

import bpy
from mathutils import Matrix, Vector


class SceneError(Exception):
    pass


def fail(msg):
    raise SceneError(msg)


def to_blender(p):
    return Vector((p[0], -p[2], p[1]))


def triple(v, what):
    if not (isinstance(v, list) and len(v) == 3 and
            all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
        fail("%s must be a triple of numbers, not %r" % (what, v))
    return [float(x) for x in v]


def number(v, what):
    if not isinstance(v, (int, float)) or isinstance(v, bool):
        fail("%s must be a number, not %r" % (what, v))
    return float(v)


def keys_ok(obj, allowed, what):
    if not isinstance(obj, dict):
        fail("%s must be an object" % what)
    for k in obj:
        if k not in allowed:
            fail("%s: key %r is not supported by this script (supported: %s)"
                 % (what, k, ", ".join(sorted(allowed))))


# ---------------------------------------------------------------- materials

def diffuse_material(m, cache):
    keys_ok(m, {"character", "color", "refractiveindex"}, "material")
    ch = m.get("character")
    keys_ok(ch, {"diffuse", "metallic", "reflecting", "refractive"}, "character")
    weights = {k: number(ch.get(k, 0), "character." + k) for k in
               ("diffuse", "metallic", "reflecting", "refractive")}
    if weights["diffuse"] != 1 or any(weights[k] != 0 for k in
                                      ("metallic", "reflecting", "refractive")):
        fail("material %r: only purely diffuse materials (diffuse 1, the rest 0) are "
             "supported" % ch)
    color = triple(m.get("color"), "material color")
    key = tuple(color)
    if key not in cache:
        mat = bpy.data.materials.new("diffuse_%d" % len(cache))
        mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (*color, 1.0)
        bsdf.inputs["Roughness"].default_value = 0.0
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        cache[key] = mat
    return cache[key]


def black_material(cache):
    return diffuse_material({"character": {"diffuse": 1}, "color": [0, 0, 0]}, cache)


# ---------------------------------------------------------------- geometry

def link(obj):
    bpy.context.scene.collection.objects.link(obj)
    obj.cycles.shadow_terminator_geometry_offset = 0.0
    obj.cycles.shadow_terminator_offset = 0.0


def add_mesh(name, verts, faces, mat):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(v) for v in verts], [], faces)
    me.update()
    for poly in me.polygons:
        poly.use_smooth = False
    me.materials.append(mat)
    obj = bpy.data.objects.new(name, me)
    link(obj)


def add_plane(body, mat, centre_hint, half):
    n = Vector(triple(body["normal"], "plane normal"))
    if n.length == 0:
        fail("plane normal is zero")
    offset = number(body["offset"], "plane offset") / n.length
    n.normalize()
    # The point of the plane nearest the hint, and two axes in it with t x b = n.
    c = Vector(centre_hint)
    p0 = c + n * (offset - n.dot(c))
    t = n.cross(Vector((1, 0, 0)) if abs(n.x) < 0.9 else Vector((0, 1, 0))).normalized()
    b = n.cross(t)
    corners = [p0 + half * (sx * t + sy * b) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    add_mesh("plane", [to_blender(v) for v in corners], [(0, 1, 2, 3)], mat)


def add_sphere(body, mat):
    centre = triple(body["center"], "sphere center")
    r = number(body["radius"], "sphere radius")
    if r <= 0:
        fail("sphere radius must be positive")
    # One vertex made a point-cloud point by geometry nodes: Cycles intersects it as a sphere.
    me = bpy.data.meshes.new("sphere_centre")
    me.from_pydata([tuple(to_blender(centre))], [], [])
    obj = bpy.data.objects.new("sphere", me)
    link(obj)
    tree = bpy.data.node_groups.new("sphere_points", "GeometryNodeTree")
    tree.inputs.new("NodeSocketGeometry", "Geometry")
    tree.outputs.new("NodeSocketGeometry", "Geometry")
    gin = tree.nodes.new("NodeGroupInput")
    gout = tree.nodes.new("NodeGroupOutput")
    pts = tree.nodes.new("GeometryNodeMeshToPoints")
    pts.inputs["Radius"].default_value = r
    setm = tree.nodes.new("GeometryNodeSetMaterial")
    setm.inputs["Material"].default_value = mat
    tree.links.new(gin.outputs[0], pts.inputs["Mesh"])
    tree.links.new(pts.outputs["Points"], setm.inputs["Geometry"])
    tree.links.new(setm.outputs["Geometry"], gout.inputs[0])
    obj.modifiers.new("sphere", "NODES").node_group = tree


GEOMETRY_KEYS = {"plane": {"normal", "offset"}, "sphere": {"center", "radius"},
                 "triangle": {"points"}}
SETTINGS = {"material", "background", "backculled"}


def check_settings(body, what):
    for k in ("background", "backculled"):
        if body.get(k, False) is not False:
            fail("%s: %r true is not supported (Cycles has no such rule)" % (what, k))


def add_object(kind, body, ctx):
    """A standalone primitive or a thing group."""
    mat_json = None
    prims = []
    if kind != "thing":
        keys_ok(body, GEOMETRY_KEYS[kind] | SETTINGS, kind)
        check_settings(body, kind)
        mat_json = body.get("material")
        prims.append((kind, body))
    else:
        keys_ok(body, {"parts"} | SETTINGS, "thing")
        check_settings(body, "thing")
        mat_json = body.get("material")
        parts = body.get("parts")
        if not isinstance(parts, list) or not parts:
            fail("thing: parts must be a non-empty list")
        for part in parts:
            if not isinstance(part, dict) or len(part) != 1:
                fail("thing: each part must be a one-key object")
            (k, v), = part.items()
            if k in GEOMETRY_KEYS:
                keys_ok(v, GEOMETRY_KEYS[k] | SETTINGS, "thing part " + k)
                check_settings(v, "thing part " + k)
                if "material" in v:
                    mat_json = v["material"]
                prims.append((k, v))
            elif k == "material":
                mat_json = v
            elif k in ("background", "backculled"):
                check_settings(part, "thing")
            else:
                fail("thing: part %r is not supported" % k)
    mat = (diffuse_material(mat_json, ctx["materials"]) if mat_json is not None
           else black_material(ctx["materials"]))
    tris = []
    for k, v in prims:
        for key in GEOMETRY_KEYS[k]:
            if key not in v:
                fail("%s: missing %r" % (k, key))
        if k == "plane":
            add_plane(v, mat, ctx["lookat"], ctx["plane_size"])
        elif k == "sphere":
            add_sphere(v, mat)
        else:
            pts = v["points"]
            if not isinstance(pts, list) or len(pts) != 3:
                fail("triangle: points must be 3 triples")
            tris.append([to_blender(triple(p, "triangle point")) for p in pts])
    if tris:
        verts = [p for t in tris for p in t]
        add_mesh("triangles", verts, [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(len(tris))],
                 mat)


# ---------------------------------------------------------------- light from far away

def load_pfm_image(path):
    with open(path, "rb") as f:
        magic = f.readline().strip()
        dims = f.readline().split()
        scale = float(f.readline().strip())
        if magic not in (b"PF", b"Pf") or len(dims) != 2:
            fail("%s: not a PFM file this script reads (one header field per line)" % path)
        w, h = int(dims[0]), int(dims[1])
        ch = 3 if magic == b"PF" else 1
        a = array.array("f")
        data = f.read(w * h * ch * 4)
        if len(data) != w * h * ch * 4:
            fail("%s: truncated PFM" % path)
        a.frombytes(data)
    if (scale < 0) != (sys.byteorder == "little"):
        a.byteswap()
    rgba = array.array("f", [1.0]) * (w * h * 4)
    for i in range(w * h):  # PFM and Blender both store the bottom row first
        for c in range(3):
            rgba[4 * i + c] = a[ch * i + (c if ch == 3 else 0)]
    img = bpy.data.images.new(os.path.basename(path), w, h, alpha=False, float_buffer=True)
    img.pixels.foreach_set(rgba)
    img.update()
    img.pack()
    return img


def setup_world(sky, scene_dir):
    world = bpy.data.worlds.new("world")
    bpy.context.scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    if sky is None:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
        bg.inputs["Strength"].default_value = 0.0
        return
    if "color" in sky:
        keys_ok(sky, {"color"}, "sky of one colour")
        c = triple(sky["color"], "sky color")
        bg.inputs["Color"].default_value = (*c, 1.0)
        bg.inputs["Strength"].default_value = 1.0
        return
    if "file" not in sky:
        fail("sky: only \"color\" and \"file\" skies are supported (no sky models)")
    keys_ok(sky, {"file", "strength", "rotate"}, "sky from a file")
    path = sky["file"]
    if not os.path.isabs(path):
        path = os.path.join(scene_dir, path)
    if path.lower().endswith(".pfm"):
        img = load_pfm_image(path)
    else:
        img = bpy.data.images.load(path)
        img.colorspace_settings.name = "Linear"
    tex = nt.nodes.new("ShaderNodeTexEnvironment")
    tex.image = img
    tex.projection = "EQUIRECTANGULAR"
    tex.interpolation = "Closest"  # zonetrace: each texel constant over its solid angle
    # Blender's equirectangular lookup has its centre column along +X, a quarter from the left
    # along +Y; ours (in Blender's frame) has the centre along +Y (our -z), a quarter along -X
    # (our -x).  So the lookup direction is the world direction turned by -90 degrees about +Z,
    # and our "rotate" (the map turned counter-clockwise seen from above, i.e. the lookup turned
    # by -rotate about +y = +Z) adds to it.
    rotate = math.radians(number(sky.get("rotate", 0), "sky rotate"))
    coord = nt.nodes.new("ShaderNodeTexCoord")
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, -math.pi / 2 - rotate)
    nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = number(sky.get("strength", 1), "sky strength")


def add_sun(body):
    keys_ok(body, {"direction", "irradiance", "angle"}, "sun")
    if "direction" not in body:
        fail("sun: only a sun given by \"direction\" is supported (not \"place\")")
    d = to_blender(triple(body["direction"], "sun direction"))
    if d.length == 0:
        fail("sun direction is zero")
    e = triple(body.get("irradiance"), "sun irradiance")
    angle = number(body.get("angle", 0.53), "sun angle")
    lamp = bpy.data.lights.new("sun", "SUN")
    # Cycles' sun: strength x colour is the irradiance on a surface facing it (W/m^2).
    peak = max(e)
    lamp.energy = peak
    lamp.color = [x / peak for x in e] if peak > 0 else [1, 1, 1]
    lamp.angle = math.radians(angle)  # the angular diameter, as ours
    lamp.cycles.cast_shadow = True
    lamp.cycles.max_bounces = 1024
    obj = bpy.data.objects.new("sun", lamp)
    # The lamp shines along its local -Z; its +Z points toward the sun.
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = d.normalized().to_track_quat("Z", "Y")
    link(obj)


# ---------------------------------------------------------------- camera and render

def setup_camera(cam_json):
    keys_ok(cam_json, {"position", "lookat", "up", "fov", "gridresolution"},
            "camera (only the aimed form is supported)")
    for k in ("position", "lookat"):
        if k not in cam_json:
            fail("camera: missing %r" % k)
    pos = to_blender(triple(cam_json["position"], "camera position"))
    at = to_blender(triple(cam_json["lookat"], "camera lookat"))
    up = to_blender(triple(cam_json.get("up", [0, 1, 0]), "camera up"))
    fov = number(cam_json.get("fov", 40), "camera fov")
    res = cam_json.get("gridresolution", [512, 512])
    if not (isinstance(res, list) and len(res) == 2 and all(isinstance(x, int) for x in res)):
        fail("camera gridresolution must be [W, H]")
    w, h = res
    f = at - pos
    dist = f.length
    f.normalize()
    r = f.cross(up).normalized()
    u = r.cross(f)
    cam = bpy.data.cameras.new("camera")
    cam.type = "PERSP"
    cam.sensor_fit = "VERTICAL"  # fov is the vertical angle, as ours
    cam.sensor_height = 24.0
    cam.lens = cam.sensor_height / 2 / math.tan(math.radians(fov) / 2)
    cam.shift_x = cam.shift_y = 0.0
    cam.clip_start = 1e-3 * dist  # zonetrace's near plane
    cam.clip_end = 1e8
    obj = bpy.data.objects.new("camera", cam)
    obj.matrix_world = Matrix(((r.x, u.x, -f.x, pos.x), (r.y, u.y, -f.y, pos.y),
                               (r.z, u.z, -f.z, pos.z), (0, 0, 0, 1)))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return w, h, triple(cam_json["lookat"], "camera lookat")


def render_settings(s, w, h, args):
    s.render.engine = "CYCLES"
    s.render.resolution_x, s.render.resolution_y = w, h
    s.render.resolution_percentage = 100
    s.render.pixel_aspect_x = s.render.pixel_aspect_y = 1.0
    s.render.use_border = False
    s.render.use_motion_blur = False
    s.render.film_transparent = False
    if args.threads > 0:
        s.render.threads_mode = "FIXED"
        s.render.threads = args.threads
    c = s.cycles
    c.device = "CPU"
    c.samples = args.spp
    c.seed = args.seed
    c.use_animated_seed = False
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"  # the film filter; 3.4 names it pixel_filter_type
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.blur_glossy = 0.0
    c.film_exposure = 1.0
    b = args.bounces
    c.max_bounces = b
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = b
    c.volume_bounces = c.transparent_max_bounces = b
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    s.view_settings.view_transform = "Standard"
    s.view_settings.look = "None"
    s.view_settings.exposure = 0.0
    s.view_settings.gamma = 1.0
    im = s.render.image_settings
    im.file_format = "OPEN_EXR"
    im.color_mode = "RGB"
    im.color_depth = "32"
    im.exr_codec = "ZIP"


def write_pfm(path, w, h, rgba):
    rgb = array.array("f", [0.0]) * (w * h * 3)
    for i in range(w * h):
        rgb[3 * i:3 * i + 3] = rgba[4 * i:4 * i + 3]
    if sys.byteorder != "little":
        rgb.byteswap()
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(rgb.tobytes())  # Blender's rows run bottom to top, as PFM's


def main(argv):
    ap = argparse.ArgumentParser(prog="blender -b -P tools/cycles_reference.py --")
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--bounces", type=int, default=16, help="Cycles max bounces (all kinds)")
    ap.add_argument("--plane-size", type=float, default=10000.0, help="planes' half-size")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: all)")
    args = ap.parse_args(argv)

    with open(args.scene) as f:
        try:
            doc = json.load(f)
        except ValueError as e:
            fail("%s: not JSON this script reads (%s)" % (args.scene, e))
    keys_ok(doc, {"camera", "scene"}, "top level")
    if "camera" not in doc or "scene" not in doc:
        fail("top level: needs \"camera\" and \"scene\"")

    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    w, h, lookat = setup_camera(doc["camera"])
    ctx = {"materials": {}, "lookat": lookat, "plane_size": args.plane_size}
    sky = None
    have_sun = False
    for item in doc["scene"]:
        if not isinstance(item, dict) or len(item) != 1:
            fail("each scene item must be a one-key object, not %r" % (item,))
        (kind, body), = item.items()
        if kind in GEOMETRY_KEYS or kind == "thing":
            add_object(kind, body, ctx)
        elif kind == "sun":
            if have_sun:
                fail("a second sun")
            add_sun(body)
            have_sun = True
        elif kind == "sky":
            if sky is not None:
                fail("a second sky")
            if not isinstance(body, dict):
                fail("sky must be an object")
            sky = body
        else:
            fail("scene item %r is not supported by this script" % kind)
    setup_world(sky, os.path.dirname(os.path.abspath(args.scene)))
    render_settings(s, w, h, args)

    exr_out = args.out.lower().endswith(".exr")
    tmp = None
    if exr_out:
        s.render.filepath = os.path.abspath(args.out)
    else:
        fd, tmp = tempfile.mkstemp(suffix=".exr")
        os.close(fd)
        s.render.filepath = tmp
    t0 = time.time()
    bpy.ops.render.render(write_still=True)
    print("cycles_reference: %dx%d, %d spp, seed %d, %d bounces: %.1f s"
          % (w, h, args.spp, args.seed, args.bounces, time.time() - t0))
    if not exr_out:
        img = bpy.data.images.load(tmp)
        img.colorspace_settings.name = "Linear"
        rgba = array.array("f", [0.0]) * (w * h * 4)
        img.pixels.foreach_get(rgba)
        write_pfm(args.out, w, h, rgba)
        os.remove(tmp)
    print("cycles_reference: wrote", args.out)


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(argv)
    except (SceneError, OSError, ValueError, KeyError) as e:
        print("cycles_reference: error: %s" % e, file=sys.stderr)
        sys.exit(2)
