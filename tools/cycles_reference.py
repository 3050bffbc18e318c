"""Renders a zonetrace scene with Blender's Cycles, as an independent reference.

    blender -b -P tools/cycles_reference.py -- SCENE.json OUT.pfm --spp N [--seed S]
            [--size WxH] [--bounces B] [--plane-size H] [--light-offset D]
            [--sphere-subdivisions K] [--light-subdivisions K] [--scale U] [--ggx multi|single]
            [--threads T] [--no-dielectric-specular] [--linear-filtering]

Writes OUT as linear float RGB (PFM, bottom row first, as zonetrace writes it; an OUT ending in
.exr is written as OpenEXR instead).  Needs Blender 3.4, and numpy for its glTF importer
(scripts/install-reference-tools.sh).

Supported, and nothing else (anything else stops the script with a message naming it):
  top level   "camera", "scene"
  camera      the four-corner form: "viewpoint", "screen" (TL, TR, BL, BR; BR unused, as in
                zonetrace), "gridresolution": a pinhole exactly through the viewpoint and the
                screen's corners, the screen being the near plane.  The screen must be a
                rectangle, seen from the side that does not mirror the image; non-square pixels
                become Blender's pixel aspect, a screen centre off the eye's axis a lens shift
              the aimed form: "position", "lookat", "up" ([0, 1, 0]), "fov" (40, vertical,
                degrees), "gridresolution" ([512, 512]), made into four corners as zonetrace does
                (the screen a thousandth of the distance to "lookat" in front of the eye)
              --size WxH replaces the grid and keeps the screen, as zonetrace's --size
  things      "plane" {"normal", "offset"}: a square of half-size --plane-size (10000) centred
                on the point of the plane nearest the view's centre (the look-at point, or the
                screen's centre)
              "sphere" {"center", "radius"}: an exact sphere (a Cycles point-cloud point) when
                backculled, or when opaque (no refractive weight) with the camera outside it:
                Cycles never shows a point from inside.  Otherwise (glass; a camera inside) a
                geodesic sphere of 20 x 4^K flat triangles (K = --sphere-subdivisions, 6) with
                the radial direction as smooth shading normal
              "triangle" {"points"}: flat-shaded
              "thing" {"parts", "material", "background", "backculled"}: a group of those; as in
                zonetrace a setting may stand on the group, in a part's body or as a one-key
                part, and the last one in the file wins
  lights      "lighttriangle" {"points"}, "lightplane" {"normal", "offset"} (a square, as planes),
                "lightsphere" {"center", "radius"} (always the geodesic sphere), alone or as parts
                of a "light" group {"parts", "emission", "background", "backculled"}: an Emission
                shader of radiance "emission" (W/m^2/sr per channel), the same seen by the camera;
                Cycles samples them as mesh lights.  Lights reflect nothing and block light.
                Cycles 3.4 samples a mesh light's triangle by solid angle, with approximate
                arithmetic that loses light of triangles seen small or edge-on (2% on the
                Cornell box's back wall), from points nearer its plane than a distance that
                grows as the cube of the triangle's size, and by area, exactly, from farther.
                So the scene is scaled by a power of 2 (--scale, default: light triangles at
                most 1 unit long) and each light triangle is cut into 4^K equal pieces
                (--light-subdivisions, default: the least K bringing that distance below
                1/1000 of the triangle; the script prints it).  With --scale 1
                --light-subdivisions 0 the light is sampled as Cycles does by itself
  settings    "backculled": the back face is a Transparent BSDF, so rays cross it from behind and
                a light emits from its front only.  Fronts as zonetrace's: a plane's normal side,
                a triangle's counter-clockwise side ((p1 - p0) x (p2 - p0)), a sphere's outside
              "background": planes only, and only where it changes nothing: every foreground
                part and the camera must lie on the plane's front side (checked), so that the
                nearest hit is zonetrace's.  A foreground triangle lying in a background plane
                (the Cornell box's light in its ceiling; zonetrace gives the tie to the
                foreground) is moved --light-offset (0.01) off it along the plane's normal
  material    "character" {"diffuse", "metallic", "reflecting", "refractive"}, "color",
                "refractiveindex" (1), "roughness" (0), "thin" (false only): the sum of the lobes
                of zonetrace's docs/light-transport.md, each a Cycles BSDF whose colour is its
                weight times "color":
                diffuse     Diffuse BSDF, roughness 0 (Lambertian)
                reflecting  Glossy BSDF (no Fresnel, like zonetrace's mirror lobe)
                refractive  Glass BSDF of index "refractiveindex" (the exact dielectric Fresnel;
                            reflection and transmission tinted by "color")
                metallic    smooth only: a Sharp Glossy BSDF whose colour is further multiplied by
                            Schlick's Fresnel, R0 = ((1 - n) / (1 + n))^2, at the shading normal
                            (Layer Weight's Facing), which is zonetrace's smooth metal exactly
              Roughness 0 gives Sharp lobes, above 0 Multiscatter GGX lobes with Cycles'
                roughness = ours (alpha = roughness^2; zonetrace's floor of 0.01 is applied).
                Both put back the light single scattering loses, but not in the same way:
                Cycles follows its random walk among the microfacets (Heitz 2016), which
                spreads that light into a wide tail, zonetrace scales the single-scattering
                lobe (Turquin 2019), which keeps its shape.  A white rough mirror returns all
                its light in both; at roughness 0.2 a white glass sphere in a white furnace
                returns 0.999 in Cycles and 0.996 in zonetrace (0.98 near its outline).
                --ggx single takes single-scattering GGX lobes instead (to compare with a
                zonetrace built without compensation): the mirrors then agree exactly, the
                glasses not quite (the furnace: Cycles 0.968, zonetrace 0.985)
  models      "mesh" {"file", "transform", "material", "backculled", "smooth"} for glTF files
                (.gltf, .glb) only: imported by Blender's own glTF importer (+Y up converted
                to Blender's +Z up, which is the script's own (x, y, z) -> (x, -z, y)), then
                placed by zonetrace's transform exactly as src/scene/load_mesh.c builds it:
                p -> A p + t, A = R_n ... R_1 S ("scale" first, then each "rotate" in order,
                right-handed about the axis through the origin, then "translate"), applied to
                the file's node transforms.  The materials are Blender's as imported: a
                Principled BSDF reading the base colour, the metallic-roughness texture and
                the normal texture (Normal Map node, tangent space, MikkTSpace tangents from
                the UVs) by itself, so Cycles' image checks how zonetrace reads them.  The
                only changes: the Principled distribution is --ggx's (Multiscatter GGX by
                default, as zonetrace compensates its single-scattering lobes; the importer
                leaves GGX), and with "backculled" a Transparent BSDF on the back.  "material"
                replaces every imported material by the script's own (as for other things);
                "smooth": false shades flat facets.
              alphaMode MASK: the importer sets the blend method CLIP (alpha_threshold the
                cutoff), which only EEVEE reads: Cycles would take the alpha as a fraction.
                The Principled Alpha is made 1 - (alpha < cutoff), the cutoff clamped into
                [0, 1] as zonetrace does: a hole below it, which every Cycles ray, shadow
                rays too, passes untinted, as zonetrace's rays do.
              Emission (emissiveFactor x emissiveTexture x KHR_materials_emissive_strength,
                the one extension accepted): the importer's Principled Emission colour x
                Emission Strength, a radiance as zonetrace's; Cycles samples the triangles
                as mesh lights (the script says within what distance of their planes it
                samples their solid angle, inexactly: a model's emissive triangles are not
                cut, give it small ones).  Blender 3.4.1's importer links the float Result of
                the Mix node that multiplies the texture by a non-grey factor (0: no light);
                the script links the colour Result.  zonetrace's emissive triangles are
                lights: they reflect nothing and ignore alpha, so an emissive material must
                be OPAQUE with a black base colour and no base texture (then glTF reflects
                only its dielectric specular layer, see --no-dielectric-specular).
                --linear-filtering (a diagnostic) makes the imported 8-bit sRGB textures
                without alpha linear before Cycles filters them: Cycles filters the sRGB
                codes, zonetrace (as glTF asks) the linear values, which differ between
                texels (halfway between white and orange 255 140 0, Cycles' blue is 0.21 of
                white's, zonetrace's 0.5).
              Refused (with the reason): other formats, "emission" and "background" on a
                mesh, a mirroring transform, glTF extensions but
                KHR_materials_emissive_strength, more than one scene, skins, animations,
                morph targets, vertex colours, triangles without a material or (with
                "smooth") without normals, alphaMode BLEND (not compared yet), an emissive
                material with alpha or a base colour, textures on a texCoord other than 0,
                NEAREST magnification or
                MIRRORED_REPEAT samplers, a normal texture's scale other than 1 (Blender's
                Normal Map strength blends the unmapped and the mapped normal, glTF scales
                x and y before normalising: they agree at 1 only), lights in the file;
                cameras in the file are left out.  Tangents given in the file are not used
                by Blender (MikkTSpace always); zonetrace uses them (or Assimp's own when
                the file has none), which agree with MikkTSpace on flat, evenly mapped
                faces.
              Known differences that remain (the script keeps Blender's materials):
                glTF's specular layer over non-metals (Principled's Specular 0.5, F0 0.04)
                is not rendered by zonetrace: --no-dielectric-specular sets the imported
                Principled BSDFs' Specular to 0, a diagnostic to tell that layer from
                everything else; Blender 3.4's Principled diffuse is Burley's (Disney)
                diffuse, which depends on the roughness and darkens at grazing angles,
                zonetrace's is Lambert's; Cycles multiplies diffuse light by a shadowing
                term where the shading normal leaves the geometric one (bump_shadowing_term,
                after Chiang et al. 2019, "Taming the Shadow Terminator"), which darkens a
                normal-mapped diffuse surface under light from near its geometric horizon
                (a sky), where zonetrace shades with the mapped normal alone, as glTF
                does; a glTF metal's Fresnel is Principled's, F0 the base colour (1 for
                white), zonetrace's is Schlick's with an index of 0.01 (F0 0.961), whose
                multiple-scattering compensation then differs too
  far light   "sun" {"direction", "irradiance", "angle" (0.53)}: a sun lamp whose strength is the
                irradiance on a surface facing it (W/m^2, per channel through the lamp colour)
              "sky" {"color"}: the world's background colour (radiance, W/m^2/sr)
              "sky" {"file", "strength" (1), "rotate" (0)}: an equirectangular environment
                texture (OpenEXR, Radiance HDR, or PFM), nearest-texel lookup as zonetrace's
Not supported: "lightpoint", a rough "metallic" lobe (zonetrace takes Schlick's Fresnel at each
microfacet, which no Cycles 3.4 node can), "thin" panes, "background" on anything but planes or
where a foreground part or the camera stands behind the plane, meshes other than glTF
(and what "models" above lists), sky models, a sun by
"place", a skewed or mirroring screen, the legacy non-JSON group syntax.

Frames: zonetrace's +y is Blender's +Z, (x, y, z) -> (x, -z, y), times --scale.  Render
settings: Cycles on the CPU, box pixel filter 1 pixel wide, no denoising, no adaptive sampling, no
clamping, Standard view transform, caustics on, every bounce limit --bounces (16; Cycles then
scatters up to 17 times) but the transparent one, at least 64 (a hole or a backculled back is no
scattering in zonetrace).
"""
import argparse
import array
import json
import math
import os
import struct
import sys
import tempfile
import time

import bpy
from mathutils import Matrix, Vector


class SceneError(Exception):
    pass


def fail(msg):
    raise SceneError(msg)


UNIT = [1.0]  # Blender units per scene unit (--scale)
GGX_KIND = ["MULTI_GGX"]  # the rough lobes' distribution (--ggx)
MASKED = [0]  # imported MASK materials whose alpha was made a step
LINEARISED = [0]  # textures made linear before filtering (--linear-filtering)
FIXED_EMISSION = [0]  # imported emissive factors relinked (fix_emissive_factor)


def to_blender(p):
    """A point: ours (x, y, z) is Blender's (x, -z, y), times the scale."""
    u = UNIT[0]
    return Vector((p[0] * u, -p[2] * u, p[1] * u))


def to_blender_dir(d):
    return Vector((d[0], -d[2], d[1]))


def triple(v, what):
    if not (isinstance(v, list) and len(v) == 3 and
            all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
        fail("%s must be a triple of numbers, not %r" % (what, v))
    return [float(x) for x in v]


def number(v, what):
    if not isinstance(v, (int, float)) or isinstance(v, bool):
        fail("%s must be a number, not %r" % (what, v))
    return float(v)


def boolean(v, what):
    if not isinstance(v, bool):
        fail("%s must be true or false, not %r" % (what, v))
    return v


def keys_ok(obj, allowed, what):
    if not isinstance(obj, dict):
        fail("%s must be an object" % what)
    for k in obj:
        if k not in allowed:
            fail("%s: key %r is not supported by this script (supported: %s)"
                 % (what, k, ", ".join(sorted(allowed))))


# ---------------------------------------------------------------- the scene's objects

THING_PRIMS = {"plane": {"normal", "offset"}, "sphere": {"center", "radius"},
               "triangle": {"points"}}
LIGHT_PRIMS = {"lightplane": {"normal", "offset"}, "lightsphere": {"center", "radius"},
               "lighttriangle": {"points"}}
SETTINGS = {"thing": {"material", "background", "backculled"},
            "light": {"emission", "background", "backculled"}}


class Obj:
    """One zonetrace object (a thing or a light) and its parts, geometry as given."""

    def __init__(self, cls, where):
        self.cls = cls  # "thing" or "light"
        self.where = where
        self.parts = []  # (primitive without "light", geometry dict)
        self.material = None
        self.emission = [0.0, 0.0, 0.0]
        self.background = False
        self.backculled = False

    def setting(self, key, value):
        what = "%s: %s" % (self.where, key)
        if key == "material":
            self.material = value  # checked when it is built
        elif key == "emission":
            self.emission = triple(value, what)
            if min(self.emission) < 0:
                fail("%s must not be negative" % what)
        else:
            setattr(self, key, boolean(value, what))


def parse_part(obj, prim, body):
    """A primitive's body: its geometry, and settings that apply to its object."""
    cls_prims = THING_PRIMS if obj.cls == "thing" else LIGHT_PRIMS
    if prim == "lightpoint":
        fail("%s: lightpoint is not supported by this script" % obj.where)
    if prim not in cls_prims:
        fail("%s: part %r is not supported in a %s (supported: %s)"
             % (obj.where, prim, obj.cls, ", ".join(sorted(cls_prims))))
    geo_keys = cls_prims[prim]
    keys_ok(body, geo_keys | SETTINGS[obj.cls], "%s: %s" % (obj.where, prim))
    kind = prim[5:] if prim.startswith("light") else prim
    geo = {}
    for k in sorted(geo_keys):
        if k not in body:
            fail("%s: %s: missing %r" % (obj.where, prim, k))
    for k, v in body.items():  # in the file's order
        if k in geo_keys:
            geo[k] = v
        else:
            obj.setting(k, v)
    what = "%s: %s" % (obj.where, prim)
    if kind == "plane":
        n = Vector(triple(geo["normal"], what + " normal"))
        if n.length == 0:
            fail("%s normal is zero" % what)
        d = number(geo["offset"], what + " offset") / n.length
        geo = {"normal": n.normalized(), "offset": d}
    elif kind == "sphere":
        r = number(geo["radius"], what + " radius")
        if r <= 0:
            fail("%s radius must be positive" % what)
        geo = {"center": Vector(triple(geo["center"], what + " center")), "radius": r}
    else:
        pts = geo["points"]
        if not isinstance(pts, list) or len(pts) != 3:
            fail("%s: points must be 3 triples" % what)
        geo = {"points": [Vector(triple(p, what + " point")) for p in pts]}
    obj.parts.append((kind, geo))


def parse_item(kind, body, index):
    where = "scene item %d (%s)" % (index, kind)
    if kind in THING_PRIMS or kind in LIGHT_PRIMS or kind == "lightpoint":
        obj = Obj("light" if kind.startswith("light") else "thing", where)
        if not isinstance(body, dict):
            fail("%s must be an object" % where)
        parse_part(obj, kind, body)
        return obj
    obj = Obj(kind, where)  # a "thing" or "light" group
    if not isinstance(body, dict):
        fail("%s must be an object (the legacy non-JSON group syntax is not supported)" % where)
    keys_ok(body, {"parts"} | SETTINGS[kind], where)
    if "parts" not in body:
        fail("%s: missing \"parts\"" % where)
    for k, v in body.items():  # settings and parts in the file's order: the last one wins
        if k != "parts":
            obj.setting(k, v)
            continue
        if not isinstance(v, list) or not v:
            fail("%s: parts must be a non-empty list" % where)
        for part in v:
            if not isinstance(part, dict) or len(part) != 1:
                fail("%s: each part must be a one-key object" % where)
            (pk, pv), = part.items()
            if pk in SETTINGS[kind]:
                obj.setting(pk, pv)
            else:
                if not isinstance(pv, dict):
                    fail("%s: part %r must be an object" % (where, pk))
                parse_part(obj, pk, pv)
    return obj


def tolerance(*values):
    return 1e-6 * max([1.0] + [abs(float(x)) for v in values
                               for x in (v if hasattr(v, "__len__") else [v])])


def check_background(objs, cam_points, offset):
    """Cycles has no background rule: it is kept only where the nearest hit gives the same.

    A background plane whose front half-space (closed) holds the camera and every foreground
    part is never seen through a foreground part nor hides one, and no ray reaches its back.
    A foreground triangle lying in the plane would tie with it; zonetrace gives the tie to
    the foreground, so the triangle is moved `offset` to the plane's front."""
    planes = []
    for o in objs:
        if not o.background:
            continue
        for kind, g in o.parts:
            if kind != "plane":
                fail("%s: \"background\" is supported on planes only, not on a %s "
                     "(Cycles has no background rule)" % (o.where, kind))
            planes.append((o, g["normal"], g["offset"]))
    for bo, n, d in planes:
        def front(p, margin=0.0):
            return n.dot(p) - margin >= d - tolerance(d, p)
        for p in cam_points:
            if not front(p):
                fail("%s: background plane with the camera behind it (Cycles has no "
                     "background rule)" % bo.where)
        for o in objs:
            if o.background:
                continue
            for i, (kind, g) in enumerate(o.parts):
                if kind == "triangle":
                    pts = g["points"]
                    if offset > 0 and all(abs(n.dot(p) - d) <= tolerance(d, p) for p in pts):
                        pts = [p + offset * n for p in pts]
                        o.parts[i] = (kind, {"points": pts, "moved": True})
                    ok = all(front(p) for p in pts)
                elif kind == "sphere":
                    ok = front(g["center"], g["radius"])
                else:
                    ok = abs(abs(n.dot(g["normal"])) - 1) < 1e-12 and g["offset"] * n.dot(
                        g["normal"]) >= d - tolerance(d)
                if not ok:
                    fail("%s: a foreground %s stands behind the background plane of %s "
                         "(Cycles has no background rule)" % (o.where, kind, bo.where))
    return len(planes)


def check_models_background(objs, points):
    """Imported models must lie on every background plane's front side, as other parts."""
    for o in objs:
        if not o.background:
            continue
        for kind, g in o.parts:
            n, d = g["normal"], g["offset"]
            for p in points:
                if n.dot(p) < d - 1e-6 * max(1.0, abs(d), *[abs(x) for x in p]):
                    fail("a model stands behind the background plane of %s (Cycles has no "
                         "background rule)" % o.where)


# ---------------------------------------------------------------- materials

def node_material(name):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    return mat, nt


def finish_material(mat, nt, shader_out, backculled):
    """Connects the surface shader; a culled surface's back is transparent (rays cross it)."""
    if backculled:
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        clear = nt.nodes.new("ShaderNodeBsdfTransparent")
        clear.inputs["Color"].default_value = (1, 1, 1, 1)
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
        nt.links.new(shader_out, mix.inputs[1])
        nt.links.new(clear.outputs["BSDF"], mix.inputs[2])
        shader_out = mix.outputs["Shader"]
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    nt.links.new(shader_out, out.inputs["Surface"])
    return mat


def lobe_weights(m, what):
    ch = m.get("character")
    keys_ok(ch, {"diffuse", "metallic", "reflecting", "refractive"}, what + " character")
    w = {}
    for k in ("diffuse", "metallic", "reflecting", "refractive"):
        if k not in ch:
            fail("%s: character needs %r" % (what, k))
        w[k] = number(ch[k], "%s character.%s" % (what, k))
        if not 0 <= w[k] <= 1:
            fail("%s: character.%s must be in [0, 1]" % (what, k))
    if abs(sum(w.values()) - 1) > 1e-6:
        fail("%s: the character's weights must add up to 1" % what)
    return w


def thing_material(m, backculled, cache, what):
    """zonetrace's lobe mixture (docs/light-transport.md) as a sum of weighted Cycles BSDFs."""
    key = (json.dumps(m, sort_keys=True), backculled)
    if key in cache:
        return cache[key]
    keys_ok(m, {"character", "color", "refractiveindex", "roughness", "thin"}, what)
    w = lobe_weights(m, what)
    color = triple(m.get("color"), what + " color")
    if not all(0 <= c <= 1 for c in color):
        fail("%s: color must be in [0, 1]" % what)
    ior = number(m.get("refractiveindex", 1), what + " refractiveindex")
    if ior <= 0:
        fail("%s: refractiveindex must be positive" % what)
    rough = number(m.get("roughness", 0), what + " roughness")
    if not 0 <= rough <= 1:
        fail("%s: roughness must be in [0, 1]" % what)
    if rough > 0:
        rough = max(rough, 0.01)  # zonetrace's floor: alpha at least 1e-4
    if boolean(m.get("thin", False), what + " thin") and w["refractive"] > 0:
        fail("%s: thin panes are not supported by this script" % what)
    if w["metallic"] > 0 and rough > 0:
        fail("%s: a rough metallic lobe is not supported: zonetrace takes Schlick's Fresnel "
             "at each microfacet normal, which Cycles 3.4's nodes cannot express" % what)
    mat, nt = node_material("material_%d" % len(cache))

    def tinted(weight):
        return (*[weight * c for c in color], 1.0)

    def distribution(node):
        if rough > 0:
            node.distribution = GGX_KIND[0]
            node.inputs["Roughness"].default_value = rough
        else:
            node.distribution = "SHARP"
            node.inputs["Roughness"].default_value = 0.0

    lobes = []
    if w["diffuse"] > 0:
        n = nt.nodes.new("ShaderNodeBsdfDiffuse")
        n.inputs["Color"].default_value = tinted(w["diffuse"])
        n.inputs["Roughness"].default_value = 0.0  # Lambertian
        lobes.append(n.outputs["BSDF"])
    if w["metallic"] > 0:
        # colour x Schlick(cos at the shading normal): Facing = 1 - |I.N| at blend 0.5.
        r0 = ((1 - ior) / (1 + ior)) ** 2
        lw = nt.nodes.new("ShaderNodeLayerWeight")
        lw.inputs["Blend"].default_value = 0.5
        p5 = nt.nodes.new("ShaderNodeMath")
        p5.operation = "POWER"
        p5.use_clamp = False
        nt.links.new(lw.outputs["Facing"], p5.inputs[0])
        p5.inputs[1].default_value = 5.0
        fr = nt.nodes.new("ShaderNodeMath")
        fr.operation = "MULTIPLY_ADD"
        fr.use_clamp = False
        nt.links.new(p5.outputs[0], fr.inputs[0])
        fr.inputs[1].default_value = 1 - r0
        fr.inputs[2].default_value = r0
        sc = nt.nodes.new("ShaderNodeVectorMath")
        sc.operation = "SCALE"
        sc.inputs[0].default_value = tinted(w["metallic"])[:3]
        nt.links.new(fr.outputs[0], sc.inputs["Scale"])
        n = nt.nodes.new("ShaderNodeBsdfGlossy")
        distribution(n)
        nt.links.new(sc.outputs["Vector"], n.inputs["Color"])
        lobes.append(n.outputs["BSDF"])
    if w["reflecting"] > 0:
        n = nt.nodes.new("ShaderNodeBsdfGlossy")
        distribution(n)
        n.inputs["Color"].default_value = tinted(w["reflecting"])
        lobes.append(n.outputs["BSDF"])
    if w["refractive"] > 0:
        n = nt.nodes.new("ShaderNodeBsdfGlass")
        distribution(n)
        n.inputs["Color"].default_value = tinted(w["refractive"])
        n.inputs["IOR"].default_value = ior
        lobes.append(n.outputs["BSDF"])
    out = lobes[0]
    for s in lobes[1:]:
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(out, add.inputs[0])
        nt.links.new(s, add.inputs[1])
        out = add.outputs["Shader"]
    cache[key] = finish_material(mat, nt, out, backculled)
    return cache[key]


def light_material(emission, backculled, cache):
    key = ("light", tuple(emission), backculled)
    if key not in cache:
        mat, nt = node_material("light_%d" % len(cache))
        peak = max(emission)
        if peak > 0:
            n = nt.nodes.new("ShaderNodeEmission")  # strength 1 x colour = the radiance
            n.inputs["Color"].default_value = (*[e / peak for e in emission], 1.0)
            n.inputs["Strength"].default_value = peak
            out = n.outputs["Emission"]
        else:  # a black light: an opaque black surface
            n = nt.nodes.new("ShaderNodeBsdfDiffuse")
            n.inputs["Color"].default_value = (0, 0, 0, 1)
            out = n.outputs["BSDF"]
        cache[key] = finish_material(mat, nt, out, backculled)
    return cache[key]


# ---------------------------------------------------------------- geometry

def link(obj):
    bpy.context.scene.collection.objects.link(obj)
    obj.cycles.shadow_terminator_geometry_offset = 0.0
    obj.cycles.shadow_terminator_offset = 0.0


def add_mesh(name, verts, faces, mat, normals=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(v) for v in verts], [], faces)
    me.update()
    for poly in me.polygons:
        poly.use_smooth = normals is not None
    if normals is not None:
        # The radial directions as shading normals (custom normals need auto smooth).
        me.use_auto_smooth = True
        me.auto_smooth_angle = math.pi
        me.normals_split_custom_set_from_vertices([tuple(n) for n in normals])
    me.materials.append(mat)
    obj = bpy.data.objects.new(name, me)
    link(obj)


def plane_corners(g, centre_hint, half):
    n, offset = g["normal"], g["offset"]
    # The point of the plane nearest the hint, and two axes in it with t x b = n.
    c = Vector(centre_hint)
    p0 = c + n * (offset - n.dot(c))
    t = n.cross(Vector((1, 0, 0)) if abs(n.x) < 0.9 else Vector((0, 1, 0))).normalized()
    b = n.cross(t)
    return [p0 + half * (sx * t + sy * b) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]


def add_point_sphere(g, mat):
    # One vertex made a point-cloud point by geometry nodes: Cycles intersects it as a sphere
    # (from outside only).
    me = bpy.data.meshes.new("sphere_centre")
    me.from_pydata([tuple(to_blender(g["center"]))], [], [])
    obj = bpy.data.objects.new("sphere", me)
    link(obj)
    tree = bpy.data.node_groups.new("sphere_points", "GeometryNodeTree")
    tree.inputs.new("NodeSocketGeometry", "Geometry")
    tree.outputs.new("NodeSocketGeometry", "Geometry")
    gin = tree.nodes.new("NodeGroupInput")
    gout = tree.nodes.new("NodeGroupOutput")
    pts = tree.nodes.new("GeometryNodeMeshToPoints")
    pts.inputs["Radius"].default_value = g["radius"] * UNIT[0]
    setm = tree.nodes.new("GeometryNodeSetMaterial")
    setm.inputs["Material"].default_value = mat
    tree.links.new(gin.outputs[0], pts.inputs["Mesh"])
    tree.links.new(pts.outputs["Points"], setm.inputs["Geometry"])
    tree.links.new(setm.outputs["Geometry"], gout.inputs[0])
    obj.modifiers.new("sphere", "NODES").node_group = tree


def geodesic_unit_sphere(k):
    """The icosahedron split k times, its vertices pushed onto the unit sphere; faces run
    counter-clockwise seen from outside."""
    t = (1 + 5 ** 0.5) / 2
    verts = [Vector(v).normalized() for v in
             ((-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
              (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1))]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(k):
        mids = {}

        def mid(a, b):
            key = (a, b) if a < b else (b, a)
            if key not in mids:
                mids[key] = len(verts)
                verts.append((verts[a] + verts[b]).normalized())
            return mids[key]
        split = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = split
    for f in faces:
        a, b, c = (verts[i] for i in f)
        if (b - a).cross(c - a).dot(a + b + c) <= 0:
            fail("internal: the geodesic sphere has an inward face")
    return verts, faces


def add_mesh_sphere(g, mat, k, cache):
    if k not in cache:
        cache[k] = geodesic_unit_sphere(k)
    unit, faces = cache[k]
    c, r = g["center"], g["radius"]
    add_mesh("sphere_mesh", [to_blender(c + r * u) for u in unit], faces, mat,
             normals=[to_blender_dir(u) for u in unit])


def split_triangle(pts, k):
    """A triangle cut k times into four by its edges' midpoints (4^k triangles of the same
    orientation, covering it exactly)."""
    tris = [pts]
    for _ in range(k):
        nxt = []
        for a, b, c in tris:
            ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
            nxt += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        tris = nxt
    return tris


def camera_inside(g, cam_points):
    return any((p - g["center"]).length < g["radius"] for p in cam_points)


def build_object(o, ctx):
    if o.cls == "light":
        mat = light_material(o.emission, o.backculled, ctx["materials"])
    else:
        m = o.material if o.material is not None else \
            {"character": {"diffuse": 1, "metallic": 0, "reflecting": 0, "refractive": 0},
             "color": [0, 0, 0]}
        mat = thing_material(m, o.backculled, ctx["materials"], o.where + ": material")
        opaque = lobe_weights(m, o.where)["refractive"] == 0
    tris = []
    for kind, g in o.parts:
        if kind == "plane":
            corners = plane_corners(g, ctx["view_centre"], ctx["plane_size"])
            add_mesh("plane", [to_blender(v) for v in corners], [(0, 1, 2, 3)], mat)
        elif kind == "sphere":
            if o.cls == "thing" and (o.backculled or
                                     (opaque and not camera_inside(g, ctx["cam_points"]))):
                add_point_sphere(g, mat)
            else:
                add_mesh_sphere(g, mat, ctx["sphere_k"], ctx["spheres"])
                ctx["mesh_spheres"] += 1
        elif o.cls == "light":
            # Cycles 3.4 samples a triangle light by its solid angle, computed with approximate
            # arithmetic (fast_acosf), which loses light of triangles seen small or edge-on:
            # -2% on the Cornell box's back wall, nearly all of it for small pieces seen
            # edge-on.  It does so from points whose distance to the triangle's plane is below
            # its longest edge times twice its area, in Blender units (kernel/light/light.h:
            # distance_to_plane divides by |N|^2, not |N|), and samples its area, exactly,
            # from farther.  That distance goes as the cube of the size: the scene is scaled
            # (--scale) to make light triangles at most 1 long, and each is cut into 4^K
            # pieces a 2^K-th of its size, K the least (at most 8) that brings the distance
            # below 1/1000 of the triangle's longest edge.  (Many pieces instead would bias
            # the light by float rounding in Cycles' table of cumulative areas: -0.15% with
            # 131,072.)
            p0, p1, p2 = (UNIT[0] * p for p in g["points"])
            edge = max((p1 - p0).length, (p2 - p1).length, (p0 - p2).length)
            twice_area = (p1 - p0).cross(p2 - p0).length
            k = ctx["light_k"]
            if k < 0:
                k = 0
                while k < 8 and edge * twice_area / 8 ** k > 1e-3 * edge:
                    k += 1
            ctx["light_pieces"] += 4 ** k
            ctx["solid_angle_within"] = max(ctx["solid_angle_within"],
                                            edge * twice_area / 8 ** k / UNIT[0])
            tris += [[to_blender(p) for p in t] for t in split_triangle(g["points"], k)]
        else:
            tris.append([to_blender(p) for p in g["points"]])
    if tris:
        verts = [p for t in tris for p in t]
        add_mesh("triangles", verts, [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(len(tris))],
                 mat)


# ---------------------------------------------------------------- model files (glTF)

MESH_KEYS = {"file", "transform", "material", "backculled", "smooth"}
GLTF_EXTENSIONS = {"KHR_materials_emissive_strength"}
GLTF_MAX_JSON = 64 << 20


def mat3_rotation(axis, degrees):
    """zonetrace's load_mesh.c: the right-handed rotation about a unit axis, in degrees."""
    x, y, z = axis
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    k = 1 - c
    return Matrix(((c + x * x * k, x * y * k - z * s, x * z * k + y * s),
                   (y * x * k + z * s, c + y * y * k, y * z * k - x * s),
                   (z * x * k - y * s, z * y * k + x * s, c + z * z * k)))


def mesh_transform(tr, what):
    """zonetrace's load_transform: p -> A p + t, A = R_n ... R_1 S (scale first, then each
    rotation in order, then the translation), in the scene's frame."""
    a = Matrix.Identity(3)
    t = Vector((0, 0, 0))
    if tr is None:
        return a, t
    keys_ok(tr, {"scale", "rotate", "translate"}, what)
    if "scale" in tr:
        s = tr["scale"]
        s = triple(s, what + " scale") if isinstance(s, list) else [number(s, what + " scale")] * 3
        if 0 in s:
            fail("%s: a scale factor of 0 flattens the model" % what)
        a = Matrix.Diagonal(Vector(s))
    if "rotate" in tr:
        rot = tr["rotate"]
        if not isinstance(rot, list):
            fail("%s: rotate must be a list of [ax, ay, az, degrees]" % what)
        for r in rot:
            if not isinstance(r, list) or len(r) != 4:
                fail("%s: a rotation is [ax, ay, az, degrees]" % what)
            axis = Vector(triple(r[:3], what + " rotation axis"))
            if not axis.length > 0:
                fail("%s: a rotation's axis is zero" % what)
            a = mat3_rotation(axis.normalized(), number(r[3], what + " rotation angle")) @ a
    if "translate" in tr:
        t = Vector(triple(tr["translate"], what + " translate"))
    if a.determinant() < 0:
        fail("%s: a mirroring transform is not supported (zonetrace turns the winding and the "
             "tangents' side; not checked against Blender's handling)" % what)
    return a, t


def read_gltf_json(path):
    """The glTF's JSON: the whole .gltf, or a .glb's first (JSON) chunk."""
    with open(path, "rb") as f:
        head = f.read(12)
        if head[:4] == b"glTF":
            if len(head) < 12:
                fail("%s: truncated .glb" % path)
            length, kind = struct.unpack("<II", f.read(8))
            if kind != 0x4E4F534A or length > GLTF_MAX_JSON:
                fail("%s: a .glb whose first chunk is not JSON" % path)
            text = f.read(length)
        else:
            text = head + f.read(GLTF_MAX_JSON)
    try:
        return json.loads(text.decode("utf-8"))
    except (ValueError, UnicodeDecodeError) as e:
        fail("%s: not glTF JSON: %s" % (path, e))


def check_gltf(doc, path, override, smooth):
    """Refuses what Blender's importer and zonetrace's Assimp reading would not render alike."""
    def no(msg):
        fail("%s: %s" % (path, msg))
    if not isinstance(doc, dict) or not str(doc.get("asset", {}).get("version", "")).startswith("2"):
        no("not a glTF 2 file")
    ext = sorted((set(doc.get("extensionsUsed", [])) | set(doc.get("extensionsRequired", [])))
                 - GLTF_EXTENSIONS)
    if ext:
        no("glTF extensions are not supported by this script (%s): zonetrace reads some "
           "(KHR_materials_ior, transmission, volume), not all as Blender does; only %s is"
           % (", ".join(ext), ", ".join(sorted(GLTF_EXTENSIONS))))
    if len(doc.get("scenes", [])) > 1:
        no("more than one scene (zonetrace flattens every node, Blender imports one scene)")
    if doc.get("skins") or doc.get("animations"):
        no("skins and animations are not supported (which pose each reader takes differs)")
    for sampler in doc.get("samplers", []):
        if sampler.get("magFilter") == 9728:
            no("a sampler with NEAREST magnification: Blender would read it nearest, zonetrace "
               "always bilinearly")
        if 33648 in (sampler.get("wrapS"), sampler.get("wrapT")):
            no("a MIRRORED_REPEAT sampler (zonetrace repeats or clamps)")
    for mesh in doc.get("meshes", []):
        for prim in mesh.get("primitives", []):
            attrs = prim.get("attributes", {})
            if prim.get("targets"):
                no("morph targets are not supported")
            if any(k.startswith("COLOR_") for k in attrs):
                no("vertex colours are not supported (Blender's importer multiplies the base "
                   "colour by them, zonetrace does not)")
            if smooth and "NORMAL" not in attrs and prim.get("mode", 4) in (4, 5, 6):
                no("triangles without NORMAL with \"smooth\": zonetrace makes smooth normals "
                   "(60 degrees), Blender's importer flat ones; give \"smooth\": false")
            if override is None and "material" not in prim and prim.get("mode", 4) in (4, 5, 6):
                no("triangles without a material (the two readers' default materials differ); "
                   "give the mesh a \"material\"")
    if override is not None:
        return
    for i, m in enumerate(doc.get("materials", [])):
        what = "material %d (%s)" % (i, m.get("name", "unnamed"))
        mode = m.get("alphaMode", "OPAQUE")
        if mode not in ("OPAQUE", "MASK"):
            no("%s: alphaMode %s is not supported by this script (zonetrace's BLEND is "
               "coverage; not compared with Cycles' Principled alpha yet)" % (what, mode))
        if mode == "MASK":
            cutoff = m.get("alphaCutoff", 0.5)
            if not isinstance(cutoff, (int, float)) or isinstance(cutoff, bool) or \
                    not -1e30 < cutoff < 1e30:
                no("%s: alphaCutoff %r is not a number zonetrace reads" % (what, cutoff))
        pbr = m.get("pbrMetallicRoughness", {})
        exts = m.get("extensions", {})
        for k in exts:
            if k not in GLTF_EXTENSIONS:
                no("%s: the material extension %s is not supported by this script" % (what, k))
        strength = exts.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        if not isinstance(strength, (int, float)) or isinstance(strength, bool) or \
                not 0 <= strength < 1e30:
            no("%s: emissiveStrength %r is not a number >= 0" % (what, strength))
        if any(m.get("emissiveFactor", [0, 0, 0])) and strength > 0:
            # zonetrace's emissive triangles are lights: they ignore alpha and reflect nothing
            # (docs/scene-format.md), where glTF (and Blender's Principled BSDF) adds the
            # emission to the surface's reflection.  They agree when nothing is reflected but
            # the dielectric specular layer (--no-dielectric-specular takes it off).
            if mode != "OPAQUE":
                no("%s: an emissive material with alphaMode %s (zonetrace's lights ignore "
                   "alpha, Blender's does not)" % (what, mode))
            base = pbr.get("baseColorFactor", [1, 1, 1, 1])
            if any(base[:3]) or pbr.get("baseColorTexture"):
                no("%s: an emissive material whose base colour is not black (zonetrace's "
                   "emissive triangles are lights, which reflect nothing; glTF's reflect "
                   "their base colour too): give it baseColorFactor 0 0 0 and no base "
                   "texture" % what)
        infos = [pbr.get("baseColorTexture"), pbr.get("metallicRoughnessTexture"),
                 m.get("normalTexture"), m.get("emissiveTexture")]
        for info in infos:
            if info and info.get("texCoord", 0) != 0:
                no("%s: a texture on texCoord %d (only TEXCOORD_0 is supported)"
                   % (what, info["texCoord"]))
        nt = m.get("normalTexture")
        if nt and nt.get("scale", 1.0) != 1.0:
            # glTF scales x and y before normalising; Blender's Normal Map strength blends
            # the unmapped and the mapped normal.  They agree at 1 only.
            no("%s: a normal texture's scale of %g (Blender's Normal Map strength is not "
               "glTF's scale but at 1)" % (what, nt["scale"]))


def import_gltf(path):
    """Blender's own importer, +Y up converted to +Z up: glTF's (x, y, z) is Blender's
    (x, -z, y), the script's own mapping (to_blender) without the scale."""
    # Blender 3.4's importer uses numpy.bool, an alias numpy 1.24 removed (it was bool).
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
    before = set(bpy.data.objects)
    res = bpy.ops.import_scene.gltf(filepath=path, import_shading="NORMALS",
                                    bone_heuristic="TEMPERANCE", guess_original_bind_pose=True)
    if "FINISHED" not in res:
        fail("%s: Blender's glTF importer failed" % path)
    return [o for o in bpy.data.objects if o not in before]


def backface_transparent(mat):
    """An imported material's surface with a Transparent BSDF on its back (backculled)."""
    nt = mat.node_tree
    outs = [n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"]
    if not outs or not outs[0].inputs["Surface"].is_linked:
        fail("material %s has no surface output" % mat.name)
    out = outs[0]
    src = out.inputs["Surface"].links[0].from_socket
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    clear = nt.nodes.new("ShaderNodeBsdfTransparent")
    clear.inputs["Color"].default_value = (1, 1, 1, 1)
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(src, mix.inputs[1])
    nt.links.new(clear.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])


def linear_textures(mat):
    """--linear-filtering: each 8-bit sRGB texture without alpha of an imported material
    replaced by a float image of its texels made linear (the sRGB curve), which Cycles then
    filters as it is.  Cycles filters an 8-bit sRGB texture's codes and makes the result
    linear; zonetrace makes the texels linear and filters them (as glTF asks): between a white
    and an orange (255 140 0) texel, halfway, Cycles' blue is 0.21 of white's, zonetrace's
    0.5.  Textures with alpha are left as they are (their colour's alpha handling differs in
    float images)."""
    for n in mat.node_tree.nodes:
        im = n.image if n.type == "TEX_IMAGE" else None
        if im is None or im.is_float or im.colorspace_settings.name != "sRGB":
            continue
        w, h = im.size
        px = array.array("f", [0.0]) * (w * h * 4)
        im.pixels.foreach_get(px)
        if any(px[i] < 1.0 for i in range(3, len(px), 4)):
            continue
        for i in range(len(px)):
            if i % 4 != 3:
                c = px[i]
                px[i] = c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
        lin = bpy.data.images.new(im.name + " (linear)", w, h, alpha=True, float_buffer=True)
        lin.colorspace_settings.name = "Linear"
        lin.pixels.foreach_set(px)
        n.image = lin
        LINEARISED[0] += 1


def fix_emissive_factor(mat, p):
    """Blender 3.4.1's importer multiplies an emissive texture by a non-grey emissiveFactor in a
    Mix node (RGBA, MULTIPLY) but links the node's first output, its float Result, which the
    RGBA mode leaves unused (0): the emission came out black.  Its colour Result is linked
    instead (the base colour's Color Factor node is linked that way by the importer itself)."""
    e = p.inputs["Emission"]
    if not e.is_linked:
        return
    link = e.links[0]
    node = link.from_node
    if node.type == "MIX" and node.data_type == "RGBA" and \
            link.from_socket.identifier != "Result_Color":
        colour = [o for o in node.outputs if o.identifier == "Result_Color"]
        if len(colour) != 1:
            fail("imported material %s: its emissive factor's Mix node has no colour Result"
                 % mat.name)
        mat.node_tree.links.new(colour[0], e)
        FIXED_EMISSION[0] += 1


def mask_alpha(mat, p):
    """glTF's MASK, which Blender 3.4's importer leaves as the blend method CLIP with the cutoff
    as alpha_threshold, both EEVEE's only: Cycles would read the Principled Alpha as a
    fraction.  Here Alpha becomes 1 where the imported alpha (the base-colour texture's alpha,
    times the factor's) is at or above the cutoff, 0 below it: a hole, which every Cycles ray
    (shadow rays too) passes, as zonetrace's.  The cutoff is clamped into [0, 1], as
    zonetrace does."""
    nt = mat.node_tree
    cutoff = min(1.0, max(0.0, mat.alpha_threshold))
    alpha = p.inputs["Alpha"]
    if not alpha.is_linked:
        alpha.default_value = 1.0 if alpha.default_value >= cutoff else 0.0
        return
    src = alpha.links[0].from_socket
    below = nt.nodes.new("ShaderNodeMath")
    below.operation = "LESS_THAN"
    below.label = "alpha below the cutoff"
    below.inputs[1].default_value = cutoff
    step = nt.nodes.new("ShaderNodeMath")
    step.operation = "SUBTRACT"
    step.label = "MASK: 1 at or above the cutoff"
    step.inputs[0].default_value = 1.0
    nt.links.new(src, below.inputs[0])
    nt.links.new(below.outputs[0], step.inputs[1])
    nt.links.new(step.outputs[0], alpha)
    MASKED[0] += 1


def imported_emission(mat):
    """Whether an imported material emits (its Principled Emission times Strength)."""
    p = [n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"][0]
    e, k = p.inputs["Emission"], p.inputs["Emission Strength"]
    return (k.is_linked or k.default_value > 0) and (e.is_linked or any(e.default_value[:3]))


def prepare_imported_material(mat, args):
    """Keeps Blender's Principled BSDF as imported; sets the distribution (--ggx) and, as a
    diagnostic, the dielectric specular layer off (--no-dielectric-specular)."""
    if not mat.use_nodes:
        fail("imported material %s has no nodes" % mat.name)
    bsdfs = [n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"]
    if len(bsdfs) != 1:
        fail("imported material %s: %d Principled BSDFs (one expected)" % (mat.name, len(bsdfs)))
    p = bsdfs[0]
    p.distribution = GGX_KIND[0]
    fix_emissive_factor(mat, p)
    if mat.blend_method == "CLIP":
        mask_alpha(mat, p)
    elif mat.blend_method != "OPAQUE":
        fail("imported material %s: blend method %s (only OPAQUE and MASK are supported)"
             % (mat.name, mat.blend_method))
    if args.linear_filtering:
        linear_textures(mat)
    if args.no_dielectric_specular:
        spec = p.inputs["Specular"]
        if spec.is_linked:
            fail("imported material %s: its Specular is a texture" % mat.name)
        spec.default_value = 0.0


def add_model(item, index, scene_dir, ctx, args):
    """A "mesh" item: a glTF file imported by Blender, placed by zonetrace's transform."""
    where = "scene item %d (mesh)" % index
    keys_ok(item, MESH_KEYS | {"emission", "background"}, where)
    for k in ("emission", "background"):
        if k in item:
            fail("%s: %r on a mesh is not supported by this script" % (where, k))
    if "file" not in item or not isinstance(item["file"], str) or not item["file"]:
        fail("%s: \"file\" must be a non-empty string" % where)
    path = item["file"]
    if not os.path.isabs(path):
        path = os.path.join(scene_dir, path)
    if not path.lower().endswith((".gltf", ".glb")):
        fail("%s: %s: only glTF models (.gltf, .glb) are supported: other formats go through "
             "importers that differ from Assimp's" % (where, item["file"]))
    backculled = boolean(item.get("backculled", False), where + " backculled")
    smooth = boolean(item.get("smooth", True), where + " smooth")
    a, t = mesh_transform(item.get("transform"), where + " transform")
    override = item.get("material")
    check_gltf(read_gltf_json(path), item["file"], override, smooth)
    objs = import_gltf(path)
    for o in objs:
        if o.type == "LIGHT":
            fail("%s: the file has lights (this script leaves them out)" % where)
    for o in [o for o in objs if o.type not in ("MESH", "EMPTY")]:
        bpy.data.objects.remove(o)  # cameras: zonetrace's mesh item leaves them out
    objs = [o for o in objs if o.name in bpy.data.objects]
    # Our p -> A p + t in Blender's frame: C (A (C^-1 v) + t) x the scale, C = to_blender's.
    c = Matrix(((1, 0, 0), (0, 0, -1), (0, 1, 0)))
    m = (c @ a @ c.transposed()).to_4x4() * UNIT[0]
    m.translation = to_blender(t)
    m[3][3] = 1.0
    meshes = 0
    own = {}
    for o in objs:
        if o.parent is None or o.parent not in objs:
            o.matrix_world = m @ o.matrix_world
    bpy.context.view_layer.update()
    mat = None
    if override is not None:
        mat = thing_material(override, backculled, ctx["materials"], where + ": material")
    for o in objs:
        if o.type != "MESH":
            continue
        meshes += 1
        o.cycles.shadow_terminator_geometry_offset = 0.0
        o.cycles.shadow_terminator_offset = 0.0
        me = o.data
        if not smooth:
            me.use_auto_smooth = False  # custom normals are then ignored
            for poly in me.polygons:
                poly.use_smooth = False
        if mat is not None:
            me.materials.clear()
            me.materials.append(mat)
            continue
        for slot in o.material_slots:
            if slot.material is None:
                fail("%s: a mesh part without a material" % where)
            if slot.material.name not in own:
                own[slot.material.name] = slot.material
                prepare_imported_material(slot.material, args)
    emissive = {name for name, im in own.items() if imported_emission(im)}
    for o in objs:
        if o.type != "MESH" or mat is not None:
            continue
        # Emissive triangles are mesh lights in Cycles, sampled by solid angle (inexactly)
        # from within edge x twice the area of their plane (see build_object): said, not cut.
        mw = o.matrix_world
        for poly in o.data.polygons:
            slot = o.material_slots[poly.material_index].material
            if slot is None or slot.name not in emissive:
                continue
            pts = [mw @ o.data.vertices[v].co for v in poly.vertices]
            edge = max((pts[i] - pts[i - 1]).length for i in range(len(pts)))
            twice_area = sum(((pts[i] - pts[0]).cross(pts[i + 1] - pts[0])).length
                             for i in range(1, len(pts) - 1))
            ctx["model_light_faces"] += 1
            ctx["model_solid_angle_within"] = max(ctx["model_solid_angle_within"],
                                                  edge * twice_area / UNIT[0])
    if backculled:
        for im in own.values():  # each import makes its own materials
            backface_transparent(im)
    if meshes == 0:
        fail("%s: no mesh in the file" % where)
    ctx["models"] += 1
    ctx["model_materials"] += len(own)
    return objs


def model_points(objs):
    """The world-space vertices of imported meshes, back in the scene's frame."""
    pts = []
    for o in objs:
        if o.type == "MESH":
            mw = o.matrix_world
            for v in o.data.vertices:
                p = mw @ v.co
                pts.append(Vector((p.x, p.z, -p.y)) / UNIT[0])
    return pts


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
    d = to_blender_dir(triple(body["direction"], "sun direction"))
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

def camera_corners(cam_json):
    """The camera as zonetrace's four-corner form: viewpoint, TL, TR, BL, grid, view centre."""
    def grid(default):
        res = cam_json.get("gridresolution", default)
        if res is None:
            fail("camera: missing \"gridresolution\"")
        if not (isinstance(res, list) and len(res) == 2 and
                all(isinstance(x, int) and not isinstance(x, bool) and x > 0 for x in res)):
            fail("camera gridresolution must be [W, H], positive integers")
        return res
    if "viewpoint" in cam_json or "screen" in cam_json:
        keys_ok(cam_json, {"viewpoint", "screen", "gridresolution"},
                "camera (the four-corner form)")
        for k in ("viewpoint", "screen"):
            if k not in cam_json:
                fail("camera: missing %r" % k)
        eye = Vector(triple(cam_json["viewpoint"], "camera viewpoint"))
        scr = cam_json["screen"]
        if not isinstance(scr, list) or len(scr) != 4:
            fail("camera screen must be 4 triples (TL, TR, BL, BR)")
        tl, tr, bl = (Vector(triple(p, "camera screen corner")) for p in scr[:3])
        triple(scr[3], "camera screen corner")  # checked, not used, as in zonetrace
        w, h = grid(None)
        return eye, tl, tr, bl, w, h, tl + (tr - tl) / 2 + (bl - tl) / 2
    keys_ok(cam_json, {"position", "lookat", "up", "fov", "gridresolution"},
            "camera (the aimed form)")
    for k in ("position", "lookat"):
        if k not in cam_json:
            fail("camera: missing %r" % k)
    eye = Vector(triple(cam_json["position"], "camera position"))
    at = Vector(triple(cam_json["lookat"], "camera lookat"))
    up = Vector(triple(cam_json.get("up", [0, 1, 0]), "camera up"))
    fov = number(cam_json.get("fov", 40), "camera fov")
    if not 0 < fov < 180:
        fail("camera fov must be between 0 and 180 degrees")
    w, h = grid([512, 512])
    f = at - eye
    dist = f.length
    if dist == 0:
        fail("camera: position and lookat coincide")
    f /= dist
    r = f.cross(up)
    if r.length <= 1e-9 * up.length:
        fail("camera: up is zero or parallel to the view")
    r.normalize()
    u = r.cross(f)
    # zonetrace's zt_camera_look_at: the screen a thousandth of the distance ahead.
    near = 1e-3 * dist
    half_h = near * math.tan(math.radians(fov) / 2)
    half_w = half_h * w / h
    c = eye + near * f
    return eye, c - half_w * r + half_h * u, c + half_w * r + half_h * u, \
        c - half_w * r - half_h * u, w, h, at


def setup_camera(corners, size):
    """A pinhole through the viewpoint and the screen corners, the screen as near plane."""
    eye, tl, tr, bl, w, h, view_centre = corners
    if size is not None:
        w, h = size
    right, down = tr - tl, bl - tl
    sw, sh = right.length, down.length
    if sw == 0 or sh == 0 or right.cross(down).length <= 1e-10 * sw * sh:
        fail("camera: the screen's corners are collinear")
    if abs(right.dot(down)) > 1e-7 * sw * sh:
        fail("camera: the screen is not a rectangle (skewed); Cycles' camera has square "
             "corners")
    x, y = right / sw, -down / sh
    z = x.cross(y)  # Blender's camera looks along its -Z
    dist = (eye - tl).dot(z)
    if dist <= 0:
        fail("camera: the viewpoint is on the side of the screen from which the image is "
             "mirrored (or in its plane); Cycles' camera cannot mirror")
    centre = tl + right / 2 + down / 2
    axis = eye - dist * z  # the foot of the eye on the screen's plane
    shift_x, shift_y = (centre - axis).dot(x) / sw, (centre - axis).dot(y) / sw
    cam = bpy.data.cameras.new("camera")
    cam.type = "PERSP"
    # The screen's width fixes the field (horizontal fit); its height follows from the
    # aspect of the grid times the pixels' aspect.  Shifts are in screen widths.
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = 36.0
    cam.lens = 36.0 * dist / sw
    if abs(cam.lens - 36.0 * dist / sw) > 1e-5 * cam.lens:
        fail("camera: a field of view of %.6g degrees is beyond Blender's lens range"
             % math.degrees(2 * math.atan(sw / 2 / dist)))
    cam.shift_x, cam.shift_y = shift_x, shift_y
    cam.clip_start = dist * UNIT[0]  # zonetrace's rays start on the screen
    cam.clip_end = max(1e8, 1e3 * dist) * UNIT[0]
    pixel_aspect = (sw / w) / (sh / h)
    obj = bpy.data.objects.new("camera", cam)
    xb, yb, zb, pb = to_blender_dir(x), to_blender_dir(y), to_blender_dir(z), to_blender(eye)
    obj.matrix_world = Matrix(((xb.x, yb.x, zb.x, pb.x), (xb.y, yb.y, zb.y, pb.y),
                               (xb.z, yb.z, zb.z, pb.z), (0, 0, 0, 1)))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return w, h, pixel_aspect


def render_settings(s, w, h, pixel_aspect, args):
    s.render.engine = "CYCLES"
    s.render.resolution_x, s.render.resolution_y = w, h
    s.render.resolution_percentage = 100
    # Blender wants both aspects at least 1: the larger one carries the ratio.
    if pixel_aspect >= 1:
        s.render.pixel_aspect_x, s.render.pixel_aspect_y = pixel_aspect, 1.0
    else:
        s.render.pixel_aspect_x, s.render.pixel_aspect_y = 1.0, 1.0 / pixel_aspect
    got = s.render.pixel_aspect_x / s.render.pixel_aspect_y
    if abs(got - pixel_aspect) > 1e-6 * pixel_aspect:
        fail("camera: a pixel aspect of %.6g is beyond Blender's range (1/200 to 200)"
             % pixel_aspect)
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
    c.volume_bounces = b
    # Transparent passes (alpha-MASK holes, backculled backs) are not scatterings in zonetrace:
    # they must not end paths at --bounces (with --bounces 0 they would block the camera's
    # rays through the holes and every shadow ray crossing them).
    c.transparent_max_bounces = max(b, 64)
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


def parse_size(text):
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        fail("--size must be WxH, not %r" % text)
    if w <= 0 or h <= 0:
        fail("--size must be positive")
    return w, h


def main(argv):
    ap = argparse.ArgumentParser(prog="blender -b -P tools/cycles_reference.py --")
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--size", help="WxH: the pixel grid instead of gridresolution")
    ap.add_argument("--bounces", type=int, default=16, help="Cycles max bounces (all kinds)")
    ap.add_argument("--plane-size", type=float, default=10000.0, help="planes' half-size")
    ap.add_argument("--light-offset", type=float, default=0.01,
                    help="how far a foreground triangle lying in a background plane is moved "
                         "off it (0: not moved)")
    ap.add_argument("--sphere-subdivisions", type=int, default=6,
                    help="K: spheres that must be meshes get 20 x 4^K triangles")
    ap.add_argument("--light-subdivisions", type=int, default=-1,
                    help="K: each light triangle is cut into 4^K pieces (default: chosen per "
                         "triangle, see build_object)")
    ap.add_argument("--scale", default="auto",
                    help="Blender units per scene unit (default: the power of 2 that makes "
                         "light triangles at most 1 long, see build_object)")
    ap.add_argument("--ggx", choices=("multi", "single"), default="multi",
                    help="rough lobes: Multiscatter GGX (default), or single-scattering GGX "
                         "(to compare with a zonetrace built without its compensation)")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0: all)")
    ap.add_argument("--linear-filtering", action="store_true",
                    help="diagnostic: the imported sRGB textures without alpha (emissive, base "
                         "colour) made linear before Cycles filters them, as zonetrace (and "
                         "glTF) filter; Cycles filters the 8-bit sRGB codes")
    ap.add_argument("--no-dielectric-specular", action="store_true",
                    help="diagnostic: the imported Principled BSDFs' Specular set to 0, leaving "
                         "out glTF's specular layer over non-metals (F0 0.04), which zonetrace "
                         "does not render")
    args = ap.parse_args(argv)
    GGX_KIND[0] = "MULTI_GGX" if args.ggx == "multi" else "GGX"
    if not 0 <= args.sphere_subdivisions <= 8:
        fail("--sphere-subdivisions must be 0 to 8")
    if not -1 <= args.light_subdivisions <= 8:
        fail("--light-subdivisions must be 0 to 8 (or -1: chosen per triangle)")

    with open(args.scene) as f:
        try:
            doc = json.load(f)
        except ValueError as e:
            fail("%s: not JSON this script reads (the legacy group syntax is not supported): "
                 "%s" % (args.scene, e))
    keys_ok(doc, {"camera", "scene"}, "top level")
    if "camera" not in doc or "scene" not in doc:
        fail("top level: needs \"camera\" and \"scene\"")
    if not isinstance(doc["scene"], list):
        fail("\"scene\" must be a list")

    corners = camera_corners(doc["camera"])
    eye, tl, tr, bl, _, _, view_centre = corners
    cam_points = [eye, tl, tr, bl, tr + bl - tl]
    objs = []
    meshes = []
    sky = sun = None
    for index, item in enumerate(doc["scene"]):
        if not isinstance(item, dict) or len(item) != 1:
            fail("each scene item must be a one-key object, not %r" % (item,))
        (kind, body), = item.items()
        if kind in THING_PRIMS or kind in LIGHT_PRIMS or kind in ("thing", "light",
                                                                   "lightpoint"):
            objs.append(parse_item(kind, body, index))
        elif kind == "mesh":
            if not isinstance(body, dict):
                fail("scene item %d (mesh) must be an object" % index)
            meshes.append((index, body))
        elif kind == "sun":
            if sun is not None:
                fail("a second sun")
            sun = body
        elif kind == "sky":
            if sky is not None:
                fail("a second sky")
            if not isinstance(body, dict):
                fail("sky must be an object")
            sky = body
        else:
            fail("scene item %r is not supported by this script" % kind)
    nbg = check_background(objs, cam_points, args.light_offset)
    moved = sum(1 for o in objs for _, g in o.parts if g.get("moved"))
    if args.scale == "auto":
        # Light triangles at most 1 long (see build_object), by a power of 2: exact in float.
        longest = max([max((p1 - p0).length, (p2 - p1).length, (p0 - p2).length)
                       for o in objs if o.cls == "light" for kind, g in o.parts
                       if kind == "triangle" for p0, p1, p2 in [g["points"]]] +
                      [1.1 * g["radius"] / 2 ** args.sphere_subdivisions  # geodesic edges
                       for o in objs if o.cls == "light" for kind, g in o.parts
                       if kind == "sphere"] + [1.0])
        UNIT[0] = 2.0 ** -math.ceil(math.log2(longest))
    else:
        UNIT[0] = number(float(args.scale), "--scale")
        if not UNIT[0] > 0:
            fail("--scale must be positive")

    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    w, h, pixel_aspect = setup_camera(corners, parse_size(args.size) if args.size else None)
    ctx = {"materials": {}, "view_centre": view_centre, "plane_size": args.plane_size,
           "cam_points": cam_points, "sphere_k": args.sphere_subdivisions, "spheres": {},
           "mesh_spheres": 0, "light_k": args.light_subdivisions, "light_pieces": 0,
           "solid_angle_within": 0.0, "models": 0, "model_materials": 0,
           "model_light_faces": 0, "model_solid_angle_within": 0.0}
    for o in objs:
        build_object(o, ctx)
    scene_dir = os.path.dirname(os.path.abspath(args.scene))
    model_objs = []
    for index, body in meshes:
        model_objs += add_model(body, index, scene_dir, ctx, args)
    if model_objs and nbg:
        check_models_background(objs, model_points(model_objs))
    if sun is not None:
        add_sun(sun)
    setup_world(sky, scene_dir)
    render_settings(s, w, h, pixel_aspect, args)
    print("cycles_reference: %d objects (%d lights), %d background planes, %d triangles moved "
          "%g off them, %d spheres as meshes of %d triangles"
          % (len(objs), sum(o.cls == "light" for o in objs), nbg, moved, args.light_offset,
             ctx["mesh_spheres"], 20 * 4 ** args.sphere_subdivisions))
    if ctx["models"]:
        print("cycles_reference: %d glTF models imported by Blender, %d materials kept as "
              "imported (Principled BSDF, %s lobes%s)"
              % (ctx["models"], ctx["model_materials"], GGX_KIND[0],
                 ", Specular 0: no dielectric layer (diagnostic)" if args.no_dielectric_specular
                 else ""))
    if MASKED[0]:
        print("cycles_reference: %d imported MASK materials: Principled Alpha made 1 at or above "
              "alphaCutoff, 0 below (Cycles ignores the CLIP blend method)" % MASKED[0])
    if LINEARISED[0]:
        print("cycles_reference: %d imported sRGB textures made linear before filtering "
              "(--linear-filtering, a diagnostic)" % LINEARISED[0])
    if FIXED_EMISSION[0]:
        print("cycles_reference: %d imported emissive factors relinked (Blender 3.4.1's importer "
              "links its Mix node's float Result, 0, to the Emission)" % FIXED_EMISSION[0])
    if ctx["model_light_faces"]:
        print("cycles_reference: %d emissive model faces (Principled Emission x Strength, "
              "radiance): Cycles samples their solid angle (inexactly) within %.3g scene units "
              "of their planes (not cut: give the model small emissive triangles)"
              % (ctx["model_light_faces"], ctx["model_solid_angle_within"]))
    if ctx["light_pieces"]:
        print("cycles_reference: scale %g; light triangles cut into %d pieces: Cycles samples "
              "their solid angle (inexactly) only within %.3g scene units of their planes"
              % (UNIT[0], ctx["light_pieces"], ctx["solid_angle_within"]))

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
