"""A quadray scene as a Mitsuba 3 scene dictionary (issue 44).

`quadray export SCENE -o DIR` writes DIR/scene.json (the resolved scene),
DIR/object-N.ply (each functional object as a mesh in world space, with
normals and texture coordinates) and DIR/texture-N.exr (each texture map,
level 0, linear, row 0 at v = 0); `mitsuba_dict(DIR, ...)` turns them into
the scene Mitsuba's `load_dict` takes, with the same camera, pixel filter,
path length, materials and lights, so that both renderers converge to the
same image (up to the mesh's chordal error).

Covered: diffuse (albedo times its map), mirror, conductor (exact complex
Fresnel, smooth or GGX; Schlick's Fresnel with GGX up to roughness 0.2, as
`principled`, whose separable masking differs from quadray's by 1.6e-4
relative there at 80° from the normal: _schlick_conductor), dielectric (smooth or GGX)
surfaces, tangent-space normal maps on any of them (`normalmap`), nested
dielectrics (each object's outside is the smallest dielectric whose box
holds it: water in a glass's cavity; an index-matched one is a null
interface); point, sphere and directional lights; the uniform background;
homogeneous media (the fog around everything, a dielectric's interior)
with a Henyey-Greenstein phase function, for Mitsuba's `volpath`. Anything
else (roughness and displacement maps, albedo maps on other materials,
smooth or rougher Schlick conductors, emissive surfaces and rect lights (quadray's emit or
pass light on both sides), environment maps) raises `Unsupported`: a
comparison must not run on a scene Mitsuba would render differently.
"""

import argparse
import json
import os
import time

# Dr.Jit JIT-compiles through the system's libLLVM; Debian 12's LLVM 15
# aborts on Mitsuba 3.9's kernels ("Cannot select: fminimum"), LLVM 19
# (`apt-get install libllvm19`) works.
LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19

import mitsuba as mi  # noqa: E402

mi.set_variant("llvm_ad_rgb")


def arguments(doc, out, width, height, ref_spp):
    """The flags both side-by-side scripts take, with their defaults."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quadray", default="target/release/quadray")
    ap.add_argument("--out", default=out)
    ap.add_argument("--width", type=int, default=width)
    ap.add_argument("--height", type=int, default=height)
    ap.add_argument("--ref-spp", type=int, default=ref_spp)
    return ap


class Unsupported(Exception):
    """A scene feature the conversion does not express exactly."""


def rgb(v):
    return {"type": "rgb", "value": [float(x) for x in v]}


def _texture(exported, index, dir_):
    t = exported["textures"][index]
    return {
        "type": "bitmap",
        "filename": os.path.join(dir_, t["file"]),
        "raw": True,
        "filter_type": "bilinear",
        "wrap_mode": "repeat",
    }


def _bsdf(material, exported, dir_, ext_ior=1.0):
    maps = material["maps"]
    for key in ("roughness", "displacement"):
        if maps.get(key) is not None:
            raise Unsupported(f"material {material['name']}: a {key} map")
    kind = material["kind"]
    albedo = material["albedo"]
    if maps.get("albedo") is not None and kind != "Diffuse":
        raise Unsupported(f"material {material['name']}: an albedo map on a {kind if isinstance(kind, str) else next(iter(kind))}")
    if any(e > 0 for e in material["emission"]):
        # quadray's emissive surfaces emit on both sides, Mitsuba's area
        # emitters on the normal's side.
        raise Unsupported(f"material {material['name']}: emission")
    if kind == "Diffuse":
        if maps.get("albedo") is not None:
            reflectance = _texture(exported, maps["albedo"], dir_)
            if any(abs(a - 1.0) > 0 for a in albedo):
                # quadray multiplies the map by the albedo; Mitsuba's bitmap
                # has no tint, so bake it into a copy of the map.
                reflectance = _tinted(reflectance, albedo, dir_, maps["albedo"])
        else:
            reflectance = rgb(albedo)
        return {"type": "diffuse", "reflectance": reflectance}
    if kind == "Mirror":
        return {"type": "conductor", "material": "none", "specular_reflectance": rgb(albedo)}
    if "Conductor" in kind:
        c = kind["Conductor"]
        fresnel = c["fresnel"]
        if "Schlick" in fresnel:
            return _schlick_conductor(material["name"], fresnel["Schlick"]["f0"], float(c["roughness"]))
        eta, k = fresnel["Complex"]["eta"], fresnel["Complex"]["k"]
        if c["roughness"] == 0:
            return {"type": "conductor", "eta": rgb(eta), "k": rgb(k)}
        return {"type": "roughconductor", "eta": rgb(eta), "k": rgb(k), "distribution": "ggx",
                "alpha": float(c["roughness"]) ** 2, "sample_visible": True}
    if "Dielectric" in kind:
        d = kind["Dielectric"]
        if float(d["ior"]) == ext_ior:
            # Index-matched: quadray passes straight through (not a bounce).
            return {"type": "null"}
        if d["roughness"] == 0:
            return {"type": "dielectric", "int_ior": float(d["ior"]), "ext_ior": ext_ior}
        return {"type": "roughdielectric", "int_ior": float(d["ior"]), "ext_ior": ext_ior, "distribution": "ggx",
                "alpha": float(d["roughness"]) ** 2, "sample_visible": True}
    raise Unsupported(f"material {material['name']}: kind {kind}")


# The largest roughness at which a Schlick conductor converts (below).
SCHLICK_MAX_ROUGHNESS = 0.2


def _schlick_conductor(name, f0, roughness):
    """quadray's GGX conductor with Schlick's Fresnel (F0 = `f0`) as
    Mitsuba's `principled` with metallic 1: the same GGX distribution
    (α = roughness²), visible-normal sampling and Schlick's Fresnel of
    F0 = base colour at the microfacet normal. It differs in the masking:
    Mitsuba multiplies two G1 terms (separable), quadray takes the
    height-correlated G2 = 1 / (1 + Λ(wo) + Λ(wi)); 1/G_sep − 1/G2 =
    Λ(wo)Λ(wi), where GGX's Λ(θ) = (√(1 + α² tan²θ) − 1)/2. At roughness 0.2
    (α = 0.04) and 80° from the normal both ways, Λ = 0.013 and the two
    differ by 1.6e-4 relative (4.5 % at 88°); at roughness 0.5 and 80°, by
    about 8 %: rougher ones, and those quadray renders as a mirror (α below
    1e-3; principled has no delta lobe), raise Unsupported."""
    if not (roughness**2 >= 1e-3 and roughness <= SCHLICK_MAX_ROUGHNESS):
        raise Unsupported(f"material {name}: a Schlick conductor of roughness {roughness} (converted only in "
                          f"[√1e-3, {SCHLICK_MAX_ROUGHNESS}])")
    return {"type": "principled", "base_color": rgb(f0), "metallic": 1.0, "roughness": roughness,
            "specular": 0.5, "spec_tint": 0.0, "anisotropic": 0.0, "sheen": 0.0, "clearcoat": 0.0,
            "spec_trans": 0.0}


def _normal_mapped(bsdf, exported, index, dir_, mesh):
    """`bsdf` under quadray's tangent-space normal map `index` on the
    exported mesh `mesh` (Mitsuba's `normalmap`). Both read the map
    bilinearly at level 0, decode n = 2c − 1 and normalise it, with x along
    ∂p/∂u (made orthogonal to the normal). For y, Mitsuba takes n × ∂p/∂u,
    quadray that vector turned towards ∂p/∂v: on a mesh whose (u, v) turn
    the other way (the planar floor's u = x, v = z under the normal +y),
    the map is written again with its y (green) negated
    (scripts/mitsuba_normal_map_check.py checks the sign with a tilted map)."""
    texture = _texture(exported, index, dir_)
    if _left_handed_uv(os.path.join(dir_, mesh)):

        def negate_y(image):
            image[..., 1] = 1.0 - image[..., 1]

        texture = _map_copy(texture, os.path.join(dir_, f"texture-{index}-flipped-y.exr"), negate_y)
    # Mitsuba's defaults would darken the perturbed response by a
    # shadowing term and turn a normal the viewer is below over; quadray
    # does neither.
    return {"type": "normalmap", "normalmap": texture, "bsdf": bsdf, "use_shadowing_function": False,
            "flip_invalid_normals": False}


def _left_handed_uv(ply):
    """Whether n × ∂p/∂u points away from ∂p/∂v on most of the mesh's
    triangles (per triangle, from its vertices' positions and (u, v), n the
    mean of its vertex normals)."""
    import numpy as np

    mesh = mi.load_dict({"type": "ply", "filename": ply, "face_normals": False})
    p = np.array(mesh.vertex_positions_buffer()).reshape(-1, 3).astype(np.float64)
    n = np.array(mesh.vertex_normals_buffer()).reshape(-1, 3).astype(np.float64)
    uv = np.array(mesh.vertex_texcoords_buffer()).reshape(-1, 2).astype(np.float64)
    f = np.array(mesh.faces_buffer()).reshape(-1, 3)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    d1, d2 = uv[f[:, 1]] - uv[f[:, 0]], uv[f[:, 2]] - uv[f[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    ok = np.abs(det) > 1e-12
    dpdu = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2])[ok] / det[ok, None]
    dpdv = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1])[ok] / det[ok, None]
    normal = n[f].sum(axis=1)[ok]
    side = np.einsum("ij,ij->i", np.cross(normal, dpdu), dpdv)
    left, right = np.count_nonzero(side < 0), np.count_nonzero(side > 0)
    if min(left, right) > 0.01 * (left + right):
        # quadray turns its frame per hit point; one map per mesh cannot.
        raise Unsupported(f"{ply}: (u, v) turn both ways on one mesh ({left} and {right} triangles)")
    return left > right


def _tinted(texture, albedo, dir_, index):
    def tint(image):
        image[..., :3] *= [float(a) for a in albedo]

    return _map_copy(texture, os.path.join(dir_, f"texture-{index}-tinted.exr"), tint)


def _map_copy(texture, path, change):
    """`texture` read from a copy of its image at `path`, changed in place
    by `change` (on the image as a numpy array). Written each time: the
    export it comes from may have changed."""
    import numpy as np

    image = np.array(mi.Bitmap(texture["filename"]))
    change(image)
    mi.Bitmap(image).write(path)
    return dict(texture, filename=path)


def render(scene, path, spp, seed):
    """Renders the loaded Mitsuba scene `scene` at `spp` samples per pixel
    with `seed` into the EXR `path`; returns the seconds of mi.render and
    the write (which forces the evaluation before the clock stops). Mitsuba
    combines `seed` with the seed the scene was loaded with (mitsuba_dict's
    `seed`; its `spp` does not matter): load it with the same one."""
    start = time.perf_counter()
    mi.Bitmap(mi.render(scene, spp=spp, seed=seed)).write(path)
    return time.perf_counter() - start


def mitsuba_dict(dir_, width, height, spp, seed, integrator="path"):
    """The exported scene in `dir_` as a Mitsuba scene dictionary."""
    with open(os.path.join(dir_, "scene.json")) as f:
        exported = json.load(f)
    if exported.get("environment") is not None:
        raise Unsupported("an environment map")
    image, camera = exported["image"], exported["camera"]
    scene = {
        "type": "scene",
        # quadray's max_depth counts bounces; Mitsuba's counts segments.
        "integrator": {"type": integrator, "max_depth": int(image["max_depth"]) + 1},
        "sensor": {
            "type": "perspective",
            "fov": float(camera["vfov_degrees"]),
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=camera["position"], target=camera["look_at"],
                                                       up=camera["up"]),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                # quadray's pixel filter: a Gaussian of σ = 0.5 px
                # (PIXEL_FILTER_SIGMA), drawn by jittering the camera rays;
                # Mitsuba splats each sample with the same Gaussian. Both
                # converge to the same filtered image.
                "rfilter": {"type": "gaussian", "stddev": 0.5},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
    }
    if any(b > 0 for b in exported["background"]):
        scene["background"] = {"type": "constant", "radiance": rgb(exported["background"])}
    materials = exported["materials"]
    objects = exported["objects"]
    fog = exported.get("fog")
    media = any(m.get("medium") is not None for m in materials) or fog is not None
    if media and integrator == "path":
        scene["integrator"]["type"] = "volpath"
    if fog is not None:
        scene["fog"] = _medium(fog)
        scene["sensor"]["medium"] = {"type": "ref", "id": "fog"}
    parents = _dielectric_parents(objects, materials)
    for i, o in enumerate(objects):
        material = materials[o["material"]]
        parent = parents.get(i)
        ext_ior = 1.0 if parent is None else _ior(materials[objects[parent]["material"]])
        bsdf = _bsdf(material, exported, dir_, ext_ior)
        if material["maps"].get("normal") is not None:
            bsdf = _normal_mapped(bsdf, exported, material["maps"]["normal"], dir_, o["mesh"])
        if _ior(material) is None:
            # quadray's opaque surfaces scatter on both sides; Mitsuba's
            # only on the normal's side unless wrapped.
            bsdf = {"type": "twosided", "bsdf": bsdf}
        shape = {
            "type": "ply",
            "filename": os.path.join(dir_, o["mesh"]),
            "face_normals": False,
            "bsdf": bsdf,
        }
        # The medium on each side: a dielectric's own inside (its
        # material's medium, else none), outside the parent's inside or
        # the fog; an opaque surface has the outside's on both.
        outside = _inside_medium(scene, materials[objects[parent]["material"]], f"medium-{parent}") \
            if parent is not None else ({"type": "ref", "id": "fog"} if fog is not None else None)
        if outside is not None:
            shape["exterior"] = outside
        if _ior(material) is not None:
            inside = _inside_medium(scene, material, f"medium-{i}")
            if inside is not None:
                shape["interior"] = inside
        elif outside is not None:
            shape["interior"] = outside
        scene[f"object-{i}"] = shape
    for i, light in enumerate(exported["lights"]):
        (kind, p), = light.items()
        if kind == "Point":
            scene[f"light-{i}"] = {"type": "point", "position": p["position"], "intensity": rgb(p["intensity"])}
        elif kind == "Sphere":
            scene[f"light-{i}"] = {"type": "sphere", "center": p["centre"], "radius": float(p["radius"]),
                                   "emitter": {"type": "area", "radiance": rgb(p["radiance"])}}
        elif kind == "Rect":
            # quadray's rect light lets rays through from its back; a
            # Mitsuba emitter shape blocks them.
            raise Unsupported("a rect light (transparent from behind in quadray)")
        elif kind == "Directional":
            scene[f"light-{i}"] = {"type": "directional", "direction": [-x for x in p["direction"]],
                                   "irradiance": rgb(p["irradiance"])}
        else:
            raise Unsupported(f"light {kind}")
        if fog is not None and kind in ("Sphere", "Rect"):
            scene[f"light-{i}"]["exterior"] = {"type": "ref", "id": "fog"}
    return scene


def _medium(m):
    """A quadray medium (density σ_t, single-scattering albedo, HG g)."""
    return {"type": "homogeneous", "sigma_t": float(m["density"]), "albedo": rgb(m["albedo"]),
            "phase": {"type": "hg", "g": float(m["anisotropy"])}}


def _ior(material):
    kind = material["kind"]
    return float(kind["Dielectric"]["ior"]) if isinstance(kind, dict) and "Dielectric" in kind else None


def _inside_medium(scene, material, name):
    """A reference to the medium inside a dielectric (declared once), or None."""
    if material.get("medium") is None:
        return None
    if name not in scene:
        scene[name] = _medium(material["medium"])
    return {"type": "ref", "id": name}


def _dielectric_parents(objects, materials):
    """For each object, the smallest dielectric object whose mesh's box holds
    its own (what quadray's medium stack has around it), if any."""
    def volume(b):
        return (b[1][0] - b[0][0]) * (b[1][1] - b[0][1]) * (b[1][2] - b[0][2])

    def holds(a, b):
        return all(a[0][k] <= b[0][k] and b[1][k] <= a[1][k] for k in range(3)) and volume(a) > volume(b)

    dielectric = [i for i, o in enumerate(objects) if _ior(materials[o["material"]]) is not None]
    parents = {}
    for i in range(len(objects)):
        around = [j for j in dielectric if j != i and holds(objects[j]["mesh_bounds"], objects[i]["mesh_bounds"])]
        if around:
            parents[i] = min(around, key=lambda j: volume(objects[j]["mesh_bounds"]))
    return parents
