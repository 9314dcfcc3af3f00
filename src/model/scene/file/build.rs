//! From the raw tree to the [`Scene`]: the checks across values, and the
//! objects, camera, materials, lights and scattered bumps they describe.

use std::ops::Range;

use glam::{DAffine3, DQuat, DVec2, DVec3, EulerRot, Vec3};
use toml::Spanned;

use crate::util::hash::hash_unit;

use super::{
    Camera, CameraKeyframe, CausticSettings, ConductorFresnel, DenoiseQuality, FilterMode, ImageSettings, Light,
    Material, MaterialKind, Preset, Quality, Scene, SceneObject, UvMapping, UvSettings, VolumeSettings,
};
use crate::model::geometry::{Aabb, FunctionalObject, GeometryError, Perturbation, Quadric};

use super::*;

pub(super) fn build_scene(src: &Source, raw: RawScene) -> Result<Scene, SceneError> {
    let image = raw.image.as_ref();
    let preset = match image.and_then(|i| i.preset.as_ref()) {
        Some(p) => Some(p.get_ref().parse::<Preset>().map_err(|e| src.error(Some(p.span()), "image.preset", e))?),
        None => None,
    };
    // A preset sets every quality setting; the file's own keys override it.
    let quality = preset.map_or_else(Quality::default, Preset::quality);
    let filter = match image.and_then(|i| i.filter.as_ref()) {
        Some(f) => f.get_ref().parse::<FilterMode>().map_err(|e| src.error(Some(f.span()), "image.filter", e))?,
        None => quality.filter,
    };
    let denoise_quality = match image.and_then(|i| i.denoise_quality.as_ref()) {
        Some(q) => {
            q.get_ref().parse::<DenoiseQuality>().map_err(|e| src.error(Some(q.span()), "image.denoise_quality", e))?
        }
        None => DenoiseQuality::default(),
    };
    let image = ImageSettings {
        width: image.and_then(|i| i.width).map_or(640, |v| v.get() as u32),
        height: image.and_then(|i| i.height).map_or(480, |v| v.get() as u32),
        spp: image.and_then(|i| i.spp).map_or(quality.spp, |v| v.get() as u32),
        seed: image.and_then(|i| i.seed).map_or(0, |v| v.get() as u32),
        exposure: image.and_then(|i| i.exposure).map_or(0.0, |v| v.get() as f32),
        max_depth: image.and_then(|i| i.max_depth).map_or(quality.max_depth, |v| v.get() as u32),
        filter,
        preset,
        denoise: image.and_then(|i| i.denoise).unwrap_or(quality.denoise),
        denoise_quality,
    };
    let camera = build_camera(src, &raw.camera)?;
    if let (Some(background), Some(environment)) = (&raw.background, &raw.environment) {
        // Point at whichever comes second in the file.
        let (b, e) = (background.span(), environment.span());
        let ((field, span), (other, first)) = if e.start > b.start {
            (("environment", e), ("background", b))
        } else {
            (("background", b), ("[environment]", e))
        };
        let line = src.line_of(first.start);
        return Err(src.error(
            Some(span),
            field,
            format!(
                "give either background or [environment], not both: the environment map replaces the uniform \
                 background as the light arriving from infinity ({other} is at line {line}); remove one"
            ),
        ));
    }
    let background = raw.background.as_ref().map_or(Vec3::ZERO, |b| b.get_ref().get().as_vec3());

    // Names first, then objects and lights, and only then the materials
    // with their texture maps: an error in an object is reported without
    // first generating or loading maps that can take many seconds.
    let mut names: Vec<&String> = Vec::with_capacity(raw.materials.len());
    let mut material_lines = Vec::with_capacity(raw.materials.len());
    for (i, raw_material) in raw.materials.iter().enumerate() {
        let m = raw_material.get_ref();
        let name = m.name.get_ref();
        if name.is_empty() {
            return Err(src.error(Some(m.name.span()), format!("materials[{i}].name"), "must not be empty"));
        }
        if let Some(first) = names.iter().position(|&n| n == name) {
            let line: usize = material_lines[first];
            return Err(src.error(
                Some(m.name.span()),
                format!("materials[{i}].name"),
                format!("duplicate material name {name:?} (first defined at line {line} as materials[{first}])"),
            ));
        }
        names.push(name);
        material_lines.push(src.line_of(raw_material.span().start));
    }
    let user_materials = names.len();

    let mut needs_default_material = false;
    let mut objects = Vec::with_capacity(raw.objects.len());
    for (i, o) in raw.objects.iter().enumerate() {
        let material = match &o.get_ref().material {
            Some(name) => match names.iter().position(|&n| n == name.get_ref()) {
                Some(k) => k,
                None => {
                    let known: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
                    let known = if known.is_empty() {
                        "no [[materials]] are defined".to_owned()
                    } else {
                        format!("defined: {}", known.join(", "))
                    };
                    return Err(src.error(
                        Some(name.span()),
                        format!("objects[{i}].material"),
                        format!("unknown material {:?} ({known})", name.get_ref()),
                    ));
                }
            },
            None => {
                needs_default_material = true;
                user_materials
            }
        };
        objects.push(build_object(src, i, o, material)?);
    }

    let lights = raw.lights.iter().enumerate().map(|(i, l)| build_light(src, i, l)).collect::<Result<Vec<_>, _>>()?;

    let mut textures = TextureCache::default();
    let mut materials: Vec<Material> = Vec::with_capacity(user_materials + 1);
    for (i, raw_material) in raw.materials.iter().enumerate() {
        materials.push(build_material(src, i, raw_material, &mut textures)?);
    }
    if needs_default_material {
        materials.push(Material::diffuse(DEFAULT_MATERIAL_NAME, Vec3::splat(0.8)));
    }

    let environment = match &raw.environment {
        Some(e) => Some(build_environment(src, e.get_ref(), &mut textures)?),
        None => None,
    };

    let fog = raw.fog.as_ref().map(|f| f.get_ref().build());
    let caustics = raw.caustics.as_ref();
    let caustics = CausticSettings {
        rays: caustics.and_then(|c| c.rays).map_or(quality.caustic_rays, |v| v.get() as u32),
        light_samples: caustics.and_then(|c| c.light_samples).map_or(quality.caustic_light_samples, |v| v.get() as u32),
    };
    let volume = VolumeSettings {
        samples: raw.volume.as_ref().and_then(|v| v.samples).map_or(quality.volume_samples, |v| v.get() as u32),
    };
    Ok(Scene {
        volume,
        image,
        camera,
        background,
        materials,
        objects,
        lights,
        environment,
        textures: textures.images,
        fog,
        caustics,
    })
}

pub(super) fn build_camera(src: &Source, raw: &Spanned<RawCamera>) -> Result<Camera, SceneError> {
    let c = raw.get_ref();
    let (position, look_at, up) = check_view(src, "camera", raw.span(), (c.position.get(), &c.look_at, c.up.as_ref()))?;
    let fov = c.fov.map_or(40.0, |f| f.get());
    let mut keyframes: Vec<CameraKeyframe> = Vec::new();
    for (i, k) in c.keyframes.iter().flatten().enumerate() {
        let name = format!("camera.keyframes[{i}]");
        let r = k.get_ref();
        let (position, look_at, up) = check_view(src, &name, k.span(), (r.position.get(), &r.look_at, r.up.as_ref()))?;
        let time = r.time.get();
        if keyframes.last().is_some_and(|p| p.time >= time) {
            return Err(src.error(Some(k.span()), format!("{name}.time"), "must be later than the keyframe before"));
        }
        // A keyframe's fov defaults to the camera's.
        keyframes.push(CameraKeyframe { time, position, look_at, up, vfov_degrees: r.fov.map_or(fov, |f| f.get()) });
    }
    Ok(Camera { position, look_at, up, vfov_degrees: fov, keyframes, fps: c.fps.map_or(24.0, |f| f.get()) })
}

/// A view as written: position, look_at and up (optional).
pub(super) type RawView<'a> = (DVec3, &'a Spanned<Triple<Finite>>, Option<&'a Spanned<Triple<Finite>>>);

/// Checks a view (position, look_at, up) of the camera or of a keyframe
/// (`name`: where, in messages) and returns it with the default up.
pub(super) fn check_view(
    src: &Source,
    name: &str,
    span: std::ops::Range<usize>,
    (position, look_at, up): RawView<'_>,
) -> Result<(DVec3, DVec3, DVec3), SceneError> {
    let c_look_at = look_at;
    let look_at = c_look_at.get_ref().get();
    let up_value = up.map_or(DVec3::Y, |u| u.get_ref().get());
    let view = look_at - position;
    let scale = position.abs().max(look_at.abs()).max_element().max(1.0);
    if view.length() <= 1e-9 * scale {
        return Err(src.error(
            Some(c_look_at.span()),
            format!("{name}.look_at"),
            format!("must differ from {name}.position (the view direction is look_at - position)"),
        ));
    }
    let default_note = format!(" (the default up is [0, 1, 0]; set {name}.up)");
    let (up_span, default_note) = match up {
        Some(u) => (u.span(), ""),
        None => (span, default_note.as_str()),
    };
    let up = up_value;
    if up.length() == 0.0 {
        return Err(src.error(Some(up_span), format!("{name}.up"), "must not be zero"));
    }
    let sin = view.normalize().cross(up.normalize()).length();
    if sin < 1e-6 {
        return Err(src.error(
            Some(up_span),
            format!("{name}.up"),
            format!("must not be parallel to the view direction look_at - position{default_note}"),
        ));
    }
    Ok((position, look_at, up))
}

/// The shape keys of an object, in the order they are listed in messages.
pub(super) const SHAPE_KEYS: [&str; 8] =
    ["sphere", "ellipsoid", "plane", "cylinder", "cone", "paraboloid", "hyperboloid", "quadric"];

/// The base quadric of an object's one shape key, with that key and the span
/// of its value.
pub(super) fn base_shape(
    src: &Source,
    i: usize,
    raw: &Spanned<RawObject>,
) -> Result<(Quadric, &'static str, Range<usize>), SceneError> {
    let o = raw.get_ref();
    let present: Vec<(&'static str, Range<usize>)> = [
        o.sphere.as_ref().map(Spanned::span),
        o.ellipsoid.as_ref().map(Spanned::span),
        o.plane.as_ref().map(Spanned::span),
        o.cylinder.as_ref().map(Spanned::span),
        o.cone.as_ref().map(Spanned::span),
        o.paraboloid.as_ref().map(Spanned::span),
        o.hyperboloid.as_ref().map(Spanned::span),
        o.quadric.as_ref().map(Spanned::span),
    ]
    .into_iter()
    .zip(SHAPE_KEYS)
    .filter_map(|(s, k)| s.map(|s| (k, s)))
    .collect();
    let (key, span) = match present.as_slice() {
        [one] => one.clone(),
        [] => {
            return Err(src.error(
                Some(raw.span()),
                format!("objects[{i}]"),
                format!("the object needs exactly one shape key ({}); found none", SHAPE_KEYS.join(", ")),
            ))
        }
        [_, second, ..] => {
            let keys: Vec<&str> = present.iter().map(|(k, _)| *k).collect();
            return Err(src.error(
                Some(second.1.clone()),
                format!("objects[{i}].{}", second.0),
                format!("the object needs exactly one shape key; found {}: {}", keys.len(), keys.join(", ")),
            ));
        }
    };
    let q = |k: [f64; 10]| Quadric::from_coefficients(k);
    let base = if let Some(s) = &o.sphere {
        Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(s.get_ref().radius.get()))
    } else if let Some(e) = &o.ellipsoid {
        Quadric::ellipsoid(DVec3::ZERO, e.get_ref().radii.get())
    } else if o.plane.is_some() {
        q([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0])
    } else if let Some(c) = &o.cylinder {
        let w = 1.0 / c.get_ref().radius.get().powi(2);
        q([-w, 0.0, -w, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    } else if let Some(c) = &o.cone {
        let t = c.get_ref().half_angle.get().to_radians().tan().powi(2);
        q([-1.0, t, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    } else if let Some(p) = &o.paraboloid {
        let k = p.get_ref().curvature.get();
        q([-k, 0.0, -k, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    } else if let Some(h) = &o.hyperboloid {
        let h = h.get_ref();
        let w = 1.0 / h.radius.get().powi(2);
        let s = h.slope.get().powi(2) * w;
        let k = if h.sheets.map_or(1, Int::get) == 1 { 1.0 } else { -1.0 };
        q([-w, s, -w, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, k])
    } else if let Some(c) = &o.quadric {
        c.get_ref().0
    } else {
        unreachable!("exactly one shape key is present")
    };
    Ok((base, key, span))
}

pub(super) fn build_object(
    src: &Source,
    i: usize,
    raw: &Spanned<RawObject>,
    material: usize,
) -> Result<SceneObject, SceneError> {
    let o = raw.get_ref();
    let (base, shape_key, shape_span) = base_shape(src, i, raw)?;

    let clip = match &o.clip {
        Some(c) => {
            let (min, max) = (c.get_ref().min.get(), c.get_ref().max.get());
            if let Some(axis) = (0..3).find(|&k| min[k] >= max[k]) {
                let name = ["x", "y", "z"][axis];
                return Err(src.error(
                    Some(c.span()),
                    format!("objects[{i}].clip"),
                    format!(
                        "clip.min must be less than clip.max on every axis ({name}: min {} >= max {})",
                        min[axis], max[axis]
                    ),
                ));
            }
            Some(Aabb::new(min, max))
        }
        None => None,
    };

    let mut perturbations = Vec::new();
    for (j, p) in o.perturbations.iter().enumerate() {
        let r = p.get_ref();
        let quadric = match (&r.bump, &r.quadric) {
            (Some(b), None) => Quadric::ellipsoid(b.centre.get(), b.radius.0),
            (None, Some(q)) => q.get_ref().0,
            (b, q) => {
                let found = if b.is_some() && q.is_some() { "found both" } else { "found neither" };
                return Err(src.error(
                    Some(p.span()),
                    format!("objects[{i}].perturbations[{j}]"),
                    format!("a perturbation needs exactly one of `bump` and `quadric`; {found}"),
                ));
            }
        };
        perturbations.push(Perturbation { quadric, form_factor: r.f.get() });
    }
    for (j, s) in o.scatter.iter().enumerate() {
        let r = s.get_ref();
        let on_radii = match (&r.on_radii, &o.sphere, &o.ellipsoid) {
            (Some(v), _, _) => v.get(),
            (None, Some(sphere), _) => DVec3::splat(sphere.get_ref().radius.get()),
            (None, None, Some(e)) => e.get_ref().radii.get(),
            (None, None, None) => {
                return Err(src.error(
                    Some(s.span()),
                    format!("objects[{i}].scatter[{j}].on_radii"),
                    "the required key `on_radii` is missing (it defaults to the radii only for spheres and ellipsoids)",
                ));
            }
        };
        perturbations.extend(scatter(ScatterParams {
            count: r.count.get() as usize,
            centre: r.centre.map_or(DVec3::ZERO, Triple::get),
            on_radii,
            radius: r.radius.0,
            form_factor: r.f.get(),
            alternate: r.alternate.unwrap_or(false),
            seed: r.seed.map_or(0, |v| v.get() as u32),
            jitter: r.jitter.map_or(0.0, |v| v.get()),
        }));
    }

    let shape = FunctionalObject { base, perturbations, clip };
    if let Err(e) = shape.bounds() {
        return Err(geometry_error(src, i, raw, shape_key, shape_span, &shape, e));
    }

    let translate = o.translate.map_or(DVec3::ZERO, Triple::get);
    let rotate = o.rotate.map_or(DVec3::ZERO, Triple::get);
    let scale = o.scale.map_or(DVec3::ONE, |s| s.0);
    let rotation =
        DQuat::from_euler(EulerRot::XYZ, rotate.x.to_radians(), rotate.y.to_radians(), rotate.z.to_radians());
    let transform = DAffine3::from_scale_rotation_translation(scale, rotation, translate);

    Ok(SceneObject {
        name: o.name.clone().unwrap_or_else(|| format!("objects[{i}]")),
        shape,
        transform,
        material,
        uv: o.uv.as_ref().map_or(Ok(UvSettings::default()), |uv| build_uv(src, i, uv))?,
    })
}

/// The texture coordinates of objects[i].
pub(super) fn build_uv(src: &Source, i: usize, raw: &Spanned<RawUv>) -> Result<UvSettings, SceneError> {
    let uv = raw.get_ref();
    let table = format!("objects[{i}].uv");
    let name = uv.mapping.unwrap_or(MappingName::Spherical);
    let axes = [("u_axis", &uv.u_axis), ("v_axis", &uv.v_axis)];
    let mapping = if name == MappingName::Planar {
        let mut vectors: [(DVec3, Range<usize>); 2] = Default::default();
        for ((key, axis), out) in axes.into_iter().zip(&mut vectors) {
            let Some(axis) = axis else {
                return Err(src.error(
                    Some(raw.span()),
                    format!("{table}.{key}"),
                    format!(
                        "the required key `{key}` of a planar mapping is missing; give both axes, e.g. \
                         uv = {{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 0, 1] }}"
                    ),
                ));
            };
            let v = axis.get_ref().get();
            if v == DVec3::ZERO {
                return Err(src.error(Some(axis.span()), format!("{table}.{key}"), "must not be zero"));
            }
            *out = (v, axis.span());
        }
        let [(u_axis, _), (v_axis, v_span)] = vectors;
        if u_axis.cross(v_axis).length() <= 1e-6 * u_axis.length() * v_axis.length() {
            return Err(src.error(
                Some(v_span),
                format!("{table}.v_axis"),
                "u_axis and v_axis are parallel, so the planar mapping is degenerate (u and v would vary \
                 together); give two axes that span a plane",
            ));
        }
        UvMapping::Planar { u_axis, v_axis }
    } else {
        if let Some((key, axis)) = axes.into_iter().find_map(|(k, a)| a.as_ref().map(|a| (k, a))) {
            let mapping = if name == MappingName::Spherical { "spherical" } else { "cylindrical" };
            let default_note = if uv.mapping.is_none() { " (the default mapping)" } else { "" };
            return Err(src.error(
                Some(axis.span()),
                format!("{table}.{key}"),
                format!(
                    "`{key}` does not apply to the {mapping} mapping{default_note}; only mapping = \"planar\" \
                     takes u_axis and v_axis"
                ),
            ));
        }
        if name == MappingName::Spherical {
            UvMapping::Spherical
        } else {
            UvMapping::Cylindrical
        }
    };
    Ok(UvSettings {
        mapping,
        scale: uv.scale.map_or(DVec2::ONE, |s| s.0),
        offset: uv.offset.map_or(DVec2::ZERO, |o| o.0),
    })
}

pub(super) fn geometry_error(
    src: &Source,
    i: usize,
    raw: &Spanned<RawObject>,
    shape_key: &str,
    shape_span: Range<usize>,
    shape: &FunctionalObject,
    e: GeometryError,
) -> SceneError {
    let o = raw.get_ref();
    match e {
        GeometryError::Unbounded(_) if shape.base.support_bounds().is_none() => src.error(
            Some(shape_span),
            format!("objects[{i}].{shape_key}"),
            format!(
                "the {shape_key} surface is unbounded; give the object a clip box, \
                 e.g. clip = {{ min = [-1, -1, -1], max = [1, 1, 1] }}"
            ),
        ),
        GeometryError::Unbounded(_) => {
            let j = o
                .perturbations
                .iter()
                .position(|p| {
                    let r = p.get_ref();
                    r.f.get() > 0.0 && r.quadric.as_ref().is_some_and(|q| q.get_ref().0.support_bounds().is_none())
                })
                .unwrap_or(0);
            let span = o.perturbations.get(j).map_or(raw.span(), Spanned::span);
            src.error(
                Some(span),
                format!("objects[{i}].perturbations[{j}]"),
                "a perturbation with a positive form factor and an unbounded support (its quadric is >= 0 \
                 arbitrarily far away) makes the surface unbounded; give the object a clip box",
            )
        }
        GeometryError::Empty(_) => match &o.clip {
            Some(c) => {
                src.error(Some(c.span()), format!("objects[{i}].clip"), "the surface has no point inside the clip box")
            }
            None => src.error(
                Some(shape_span),
                format!("objects[{i}].{shape_key}"),
                "the surface is empty: the quadric is negative everywhere",
            ),
        },
        e => src.error(Some(raw.span()), format!("objects[{i}]"), e.to_string()),
    }
}

/// The span of an optional spanned value.
pub(super) fn span_of<T>(value: &Option<Spanned<T>>) -> Option<Range<usize>> {
    value.as_ref().map(Spanned::span)
}

/// Rejects keys that do not apply to the table's type. `table` is the field
/// path of the table (`materials[2]`), `noun` what it is (`material`),
/// `types` the keys each type accepts, `kind` the table's type, `defaulted`
/// whether that type was not written, and `present` the optional keys given,
/// with the spans of their values.
pub(super) fn check_type_keys(
    src: &Source,
    table: &str,
    noun: &str,
    types: &[(&str, &[&str])],
    kind: &str,
    defaulted: bool,
    present: &[(&str, Option<Range<usize>>)],
) -> Result<(), SceneError> {
    let accepted = types.iter().find(|(t, _)| *t == kind).map_or(&[][..], |(_, keys)| *keys);
    let first_bad = present
        .iter()
        .filter_map(|(key, span)| span.clone().map(|s| (*key, s)))
        .filter(|(key, _)| !accepted.contains(key))
        .min_by_key(|(_, span)| span.start);
    let Some((key, span)) = first_bad else { return Ok(()) };
    let owners: Vec<String> =
        types.iter().filter(|(_, keys)| keys.contains(&key)).map(|(t, _)| format!("type = {t:?}")).collect();
    let default_note = if defaulted { " (the default type)" } else { "" };
    Err(src.error(
        Some(span),
        format!("{table}.{key}"),
        format!(
            "`{key}` does not apply to a {kind} {noun}{default_note}; a {kind} {noun} accepts {}. `{key}` belongs to {}",
            accepted.join(", "),
            owners.join(" or "),
        ),
    ))
}

pub(super) fn build_material(
    src: &Source,
    i: usize,
    raw: &Spanned<RawMaterial>,
    textures: &mut TextureCache,
) -> Result<Material, SceneError> {
    let m = raw.get_ref();
    let table = format!("materials[{i}]");
    let kind = m.kind.as_ref().map_or(MaterialType::Diffuse, |t| *t.get_ref());
    check_type_keys(
        src,
        &table,
        "material",
        &MATERIAL_KEYS,
        kind.name(),
        m.kind.is_none(),
        &[
            ("albedo", span_of(&m.albedo)),
            ("emission", span_of(&m.emission)),
            ("roughness", span_of(&m.roughness)),
            ("color", span_of(&m.color)),
            ("eta", span_of(&m.eta)),
            ("k", span_of(&m.k)),
            ("metal", span_of(&m.metal)),
            ("ior", span_of(&m.ior)),
            ("albedo_map", span_of(&m.albedo_map)),
            ("normal_map", span_of(&m.normal_map)),
            ("roughness_map", span_of(&m.roughness_map)),
            ("displacement_map", span_of(&m.displacement_map)),
            ("medium", span_of(&m.medium)),
        ],
    )?;
    let albedo = |default: f32| m.albedo.as_ref().map_or(Vec3::splat(default), |a| a.get_ref().get().as_vec3());
    let roughness = |default: f32| m.roughness.as_ref().map_or(default, |r| r.get_ref().get() as f32);
    // Conductors and dielectrics have no albedo; theirs is a neutral 1.
    let (kind, albedo) = match kind {
        // With a colour map the map alone sets the colour unless albedo is given.
        MaterialType::Diffuse => (MaterialKind::Diffuse, albedo(if m.albedo_map.is_some() { 1.0 } else { 0.8 })),
        MaterialType::Mirror => (MaterialKind::Mirror, albedo(1.0)),
        MaterialType::Conductor => (
            MaterialKind::Conductor { roughness: roughness(0.3), fresnel: conductor_fresnel(src, &table, raw)? },
            Vec3::ONE,
        ),
        MaterialType::Dielectric => (
            MaterialKind::Dielectric {
                roughness: roughness(0.0),
                ior: m.ior.as_ref().map_or(1.5, |v| v.get_ref().get() as f32),
            },
            Vec3::ONE,
        ),
    };
    Ok(Material {
        name: m.name.get_ref().clone(),
        kind,
        albedo,
        emission: m.emission.as_ref().map_or(Vec3::ZERO, |e| e.get_ref().get().as_vec3()),
        maps: build_maps(src, &table, m, textures)?,
        medium: m.medium.as_ref().map(|x| x.get_ref().build()),
    })
}

/// The Fresnel term of a conductor from its one of `color`, `eta` with `k`,
/// and `metal` (Schlick with 0.9 grey when none is given).
pub(super) fn conductor_fresnel(
    src: &Source,
    table: &str,
    raw: &Spanned<RawMaterial>,
) -> Result<ConductorFresnel, SceneError> {
    let m = raw.get_ref();
    // The forms given, in source order: (key for the field path, its description, span).
    let complex_key = match (span_of(&m.eta), span_of(&m.k)) {
        (Some(e), Some(k)) if k.start < e.start => Some(("k", k)),
        (Some(e), _) => Some(("eta", e)),
        (None, k) => k.map(|k| ("k", k)),
    };
    let mut forms: Vec<(&str, &str, Range<usize>)> = [
        span_of(&m.color).map(|s| ("color", "`color`", s)),
        complex_key.map(|(key, s)| (key, "`eta`/`k`", s)),
        span_of(&m.metal).map(|s| ("metal", "`metal`", s)),
    ]
    .into_iter()
    .flatten()
    .collect();
    forms.sort_by_key(|(_, _, span)| span.start);
    if let [first, second, ..] = forms.as_slice() {
        return Err(src.error(
            Some(second.2.clone()),
            format!("{table}.{}", second.0),
            format!(
                "a conductor takes one Fresnel form: `color` (Schlick), `eta` with `k` (complex index of \
                 refraction) or `metal` (a named metal); found {} and {}",
                first.1, second.1
            ),
        ));
    }
    let pair_missing = |missing: &str, given: &str, span: Range<usize>| {
        src.error(
            Some(span),
            format!("{table}.{missing}"),
            format!(
                "the required key `{missing}` is missing: `{given}` needs it (`eta` and `k` together give the \
                 complex index of refraction η + iκ)"
            ),
        )
    };
    Ok(match (&m.color, &m.eta, &m.k, &m.metal) {
        (Some(c), ..) => ConductorFresnel::Schlick { f0: c.get_ref().get().as_vec3() },
        (_, Some(eta), Some(k), _) => {
            ConductorFresnel::Complex { eta: eta.get_ref().get().as_vec3(), k: k.get_ref().get().as_vec3() }
        }
        (_, Some(eta), None, _) => return Err(pair_missing("k", "eta", eta.span())),
        (_, None, Some(k), _) => return Err(pair_missing("eta", "k", k.span())),
        (.., Some(metal)) => {
            let (eta, k) = metal.get_ref().ior();
            ConductorFresnel::Complex { eta, k }
        }
        _ => ConductorFresnel::Schlick { f0: Vec3::splat(0.9) },
    })
}

pub(super) fn build_light(src: &Source, i: usize, raw: &Spanned<RawLight>) -> Result<Light, SceneError> {
    let l = raw.get_ref();
    let table = format!("lights[{i}]");
    let kind = l.kind.name();
    check_type_keys(
        src,
        &table,
        "light",
        &LIGHT_KEYS,
        kind,
        false,
        &[
            ("position", span_of(&l.position)),
            ("intensity", span_of(&l.intensity)),
            ("radius", span_of(&l.radius)),
            ("radiance", span_of(&l.radiance)),
            ("corner", span_of(&l.corner)),
            ("edge_u", span_of(&l.edge_u)),
            ("edge_v", span_of(&l.edge_v)),
            ("direction", span_of(&l.direction)),
            ("irradiance", span_of(&l.irradiance)),
        ],
    )?;
    fn required<'a, T>(
        src: &Source,
        table: &str,
        kind: &str,
        raw: &Spanned<RawLight>,
        key: &str,
        value: &'a Option<Spanned<T>>,
    ) -> Result<&'a Spanned<T>, SceneError> {
        value.as_ref().ok_or_else(|| {
            src.error(
                Some(raw.span()),
                format!("{table}.{key}"),
                format!("the required key `{key}` of a {kind} light is missing"),
            )
        })
    }
    let vector = |key: &str, value: &Option<Spanned<Triple<Finite>>>| {
        required(src, &table, kind, raw, key, value).map(|v| (v.get_ref().get(), v.span()))
    };
    let colour = |key: &str, value: &Option<Spanned<Triple<NonNegative>>>| {
        required(src, &table, kind, raw, key, value).map(|v| v.get_ref().get().as_vec3())
    };
    match l.kind {
        LightKind::Point => Ok(Light::Point {
            position: vector("position", &l.position)?.0,
            intensity: colour("intensity", &l.intensity)?,
        }),
        LightKind::Sphere => {
            let centre = vector("position", &l.position)?.0;
            let radius = required(src, &table, kind, raw, "radius", &l.radius)?.get_ref().get();
            Ok(Light::Sphere { centre, radius, radiance: colour("radiance", &l.radiance)? })
        }
        LightKind::Rect => {
            let corner = vector("corner", &l.corner)?.0;
            let (edge_u, u_span) = vector("edge_u", &l.edge_u)?;
            let (edge_v, v_span) = vector("edge_v", &l.edge_v)?;
            let radiance = colour("radiance", &l.radiance)?;
            for (key, edge, span) in [("edge_u", edge_u, &u_span), ("edge_v", edge_v, &v_span)] {
                if edge.length() == 0.0 {
                    return Err(src.error(Some(span.clone()), format!("{table}.{key}"), "must not be zero"));
                }
            }
            if edge_u.cross(edge_v).length() <= 1e-6 * edge_u.length() * edge_v.length() {
                return Err(src.error(
                    Some(v_span),
                    format!("{table}.edge_v"),
                    "edge_u and edge_v are parallel, so the rect light has no area; \
                     give two edges that span a parallelogram",
                ));
            }
            Ok(Light::Rect { corner, edge_u, edge_v, radiance })
        }
        LightKind::Directional => {
            let (direction, span) = vector("direction", &l.direction)?;
            let Some(direction) = direction.try_normalize() else {
                return Err(src.error(
                    Some(span),
                    format!("{table}.direction"),
                    "must not be zero (it points from the scene toward the light and is normalised on load)",
                ));
            };
            Ok(Light::Directional { direction, irradiance: colour("irradiance", &l.irradiance)? })
        }
    }
}

// ---------------------------------------------------------------------------
// Scattered bumps
// ---------------------------------------------------------------------------

pub(super) struct ScatterParams {
    pub(super) count: usize,
    pub(super) centre: DVec3,
    pub(super) on_radii: DVec3,
    pub(super) radius: DVec3,
    pub(super) form_factor: f64,
    pub(super) alternate: bool,
    pub(super) seed: u32,
    pub(super) jitter: f64,
}

/// `count` ellipsoidal bumps centred on points of the ellipsoid `on_radii`
/// around `centre`, placed by a Fibonacci spiral around the y axis and
/// optionally jittered along the surface by up to `jitter` times the mean
/// spacing.
pub(super) fn scatter(p: ScatterParams) -> impl Iterator<Item = Perturbation> {
    let n = p.count;
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let spacing = (4.0 * std::f64::consts::PI / n as f64).sqrt();
    (0..n).map(move |i| {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let phi = i as f64 * golden_angle;
        let mut u = DVec3::new(r * phi.cos(), y, r * phi.sin());
        if p.jitter > 0.0 {
            let t1 = u.any_orthonormal_vector();
            let t2 = u.cross(t1);
            let a = hash_unit(p.seed, i as u64, 0) - 0.5;
            let b = hash_unit(p.seed, i as u64, 1) - 0.5;
            u = (u + p.jitter * spacing * (a * t1 + b * t2)).normalize();
        }
        let f = if p.alternate && i % 2 == 1 { -p.form_factor } else { p.form_factor };
        Perturbation { quadric: Quadric::ellipsoid(p.centre + p.on_radii * u, p.radius), form_factor: f }
    })
}
