//! Tests of the scene reader: every field, its checks and its messages.

use super::*;
use glam::{DAffine3, DVec2, DVec3, Vec3};

use super::super::{
    Camera, ConductorFresnel, DenoiseQuality, EnvironmentMapSettings, FilterMode, ImageSettings, Light, Material,
    MaterialKind, MaterialMaps, Preset, Scene, UvMapping, UvSettings,
};
use crate::model::geometry::{Aabb, FunctionalObject, Quadric};
use crate::model::texture;
use crate::model::texture::environment::procedural_sky;

const CAMERA: &str = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n";

fn parse(body: &str) -> Scene {
    let text = format!("{CAMERA}{body}");
    parse_scene(&text, "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn one_shape(shape: &str) -> FunctionalObject {
    parse(&format!("[[objects]]\n{shape}\nclip = {{ min = [-3, -3, -3], max = [3, 3, 3] }}\n")).objects[0].shape.clone()
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

#[test]
fn defaults() {
    let s = parse("");
    assert_eq!(
        s.image,
        ImageSettings {
            width: 640,
            height: 480,
            spp: 16,
            seed: 0,
            exposure: 0.0,
            max_depth: 6,
            filter: FilterMode::None,
            preset: None,
            denoise: false,
            denoise_quality: DenoiseQuality::High,
        }
    );
    assert_eq!(s.camera.up, DVec3::Y);
    assert_eq!(s.camera.vfov_degrees, 40.0);
    assert_eq!(s.background, Vec3::ZERO);
    assert!(s.objects.is_empty() && s.lights.is_empty() && s.materials.is_empty());
}

#[test]
fn presets_set_the_quality_and_the_files_keys_override_them() {
    let s =
        parse_scene(&format!("[image]\npreset = \"final\"\nmax_depth = 10\n[volume]\nsamples = 3\n{CAMERA}"), "t.toml")
            .unwrap();
    let q = Preset::Final.quality();
    assert_eq!(s.image.preset, Some(Preset::Final));
    assert_eq!((s.image.spp, s.image.filter, s.caustics.rays), (q.spp, q.filter, q.caustic_rays));
    assert_eq!((s.image.max_depth, s.volume.samples), (10, 3));
    let s = parse_scene(&format!("[image]\nfilter = \"ray-cones\"\n{CAMERA}"), "t.toml").unwrap();
    assert_eq!((s.image.filter, s.image.preset, s.image.spp), (FilterMode::RayCones, None, 16));
    // Denoising: the quick presets turn it on, the file's key overrides.
    let s = parse_scene(&format!("[image]\npreset = \"preview\"\n{CAMERA}"), "t.toml").unwrap();
    assert!(s.image.denoise);
    let s = parse_scene(&format!("[image]\npreset = \"interactive\"\ndenoise = false\n{CAMERA}"), "t.toml").unwrap();
    assert!(!s.image.denoise);
    let s = parse_scene(&format!("[image]\ndenoise = true\ndenoise_quality = \"fast\"\n{CAMERA}"), "t.toml").unwrap();
    assert_eq!((s.image.denoise, s.image.denoise_quality), (true, DenoiseQuality::Fast));
}

#[test]
fn unknown_presets_and_filters_are_errors_at_their_line() {
    let e = parse_scene(&format!("[image]\npreset = \"fast\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
    assert!(e.starts_with("t.toml:2:10: image.preset: unknown preset `fast`"), "{e}");
    let e = parse_scene(&format!("[image]\nwidth = 8\nfilter = \"ewa\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
    assert!(e.starts_with("t.toml:3:10: image.filter: unknown filter `ewa`"), "{e}");
    let e = parse_scene(&format!("[image]\ndenoise_quality = \"best\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
    assert!(e.starts_with("t.toml:2:19: image.denoise_quality: unknown denoise quality `best`"), "{e}");
    let e = parse_scene(&format!("[image]\ndenoise = \"yes\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
    assert!(e.contains("image.denoise"), "{e}");
}

#[test]
fn image_and_background() {
    let text = "background = [0.1, 0.2, 0.3]\n[image]\nwidth = 64\nheight = 48\nspp = 3\nseed = 4000000000\nexposure = -1.5\nmax_depth = 12\n";
    let s = parse_scene(&format!("{text}{CAMERA}"), "t.toml").unwrap();
    assert_eq!(
        s.image,
        ImageSettings {
            width: 64,
            height: 48,
            spp: 3,
            seed: 4_000_000_000,
            exposure: -1.5,
            max_depth: 12,
            filter: FilterMode::None,
            preset: None,
            denoise: false,
            denoise_quality: DenoiseQuality::High,
        }
    );
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
}

#[test]
fn sphere_and_ellipsoid() {
    let s = one_shape("sphere = { radius = 2 }");
    assert!(near(s.eval(DVec3::new(2.0, 0.0, 0.0)), 0.0));
    assert!(near(s.eval(DVec3::new(0.0, 0.0, -2.0)), 0.0));
    assert!(s.eval(DVec3::ZERO) > 0.0);
    assert!(s.eval(DVec3::new(0.0, 2.1, 0.0)) < 0.0);
    let e = one_shape("ellipsoid = { radii = [1, 0.5, 2] }");
    for p in [DVec3::X, DVec3::new(0.0, 0.5, 0.0), DVec3::new(0.0, 0.0, -2.0)] {
        assert!(near(e.eval(p), 0.0));
    }
    assert!(e.eval(DVec3::ZERO) > 0.0);
}

#[test]
fn plane_cylinder_cone_paraboloid() {
    let p = one_shape("plane = {}");
    assert!(near(p.eval(DVec3::new(1.0, 0.0, 2.0)), 0.0));
    assert!(p.eval(DVec3::new(0.0, -1.0, 0.0)) > 0.0);
    assert!((p.normal(DVec3::ZERO) - DVec3::Y).length() < 1e-12);
    let c = one_shape("cylinder = { radius = 0.5 }");
    assert!(near(c.eval(DVec3::new(0.5, 7.0, 0.0)), 0.0));
    assert!(near(c.eval(DVec3::new(0.3, -1.0, 0.4)), 0.0));
    assert!(c.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
    let k = one_shape("cone = { half_angle = 30 }");
    let t = 30f64.to_radians().tan();
    assert!(near(k.eval(DVec3::new(t * 2.0, 2.0, 0.0)), 0.0));
    assert!(near(k.eval(DVec3::new(0.0, -1.0, t)), 0.0));
    assert!(k.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
    assert!(k.eval(DVec3::new(1.0, 0.0, 0.0)) < 0.0);
    let q = one_shape("paraboloid = { curvature = 2 }");
    assert!(near(q.eval(DVec3::new(1.0, 2.0, 0.0)), 0.0));
    assert!(q.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
    assert!(q.eval(DVec3::new(0.0, -1.0, 0.0)) < 0.0);
}

#[test]
fn hyperboloids() {
    let h = one_shape("hyperboloid = { radius = 0.5, slope = 2 }");
    assert!(near(h.eval(DVec3::new(0.5, 0.0, 0.0)), 0.0));
    // x² + z² = r² + s² y²
    let r = (0.25f64 + 4.0).sqrt();
    assert!(near(h.eval(DVec3::new(0.0, 1.0, r)), 0.0));
    assert!(h.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
    assert!(h.eval(DVec3::new(1.0, 0.0, 0.0)) < 0.0);
    let h2 = one_shape("hyperboloid = { radius = 0.5, slope = 2, sheets = 2 }");
    // s² y² - (x² + z²) = r²: vertices at y = ±r/s
    assert!(near(h2.eval(DVec3::new(0.0, 0.25, 0.0)), 0.0));
    assert!(near(h2.eval(DVec3::new(0.0, -0.25, 0.0)), 0.0));
    assert!(near(h2.eval(DVec3::new((4.0f64 - 0.25).sqrt(), 1.0, 0.0)), 0.0));
    assert!(h2.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
    assert!(h2.eval(DVec3::ZERO) < 0.0);
}

#[test]
fn general_quadric_and_clip() {
    let s = parse(
        "[[objects]]\nquadric = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nclip = { min = [-1, -2, -3], max = [1, 2, 3] }\n",
    );
    let o = &s.objects[0].shape;
    assert_eq!(o.base.coefficients(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]);
    assert_eq!(o.clip, Some(Aabb::new(DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0))));
    assert_eq!(one_shape("sphere = { radius = 1 }").clip.unwrap().max, DVec3::splat(3.0));
    assert_eq!(parse("[[objects]]\nsphere = { radius = 1 }\n").objects[0].shape.clip, None);
}

#[test]
fn transforms() {
    let s = parse(
        "[[objects]]\nsphere = { radius = 1 }\ntranslate = [1, 2, 3]\n\
         [[objects]]\nsphere = { radius = 1 }\nrotate = [0, 0, 90]\nscale = 2\n\
         [[objects]]\nsphere = { radius = 1 }\nscale = [1, 2, 3]\n\
         [[objects]]\nsphere = { radius = 1 }\nrotate = [90, 90, 0]\n",
    );
    let t = &s.objects;
    assert_eq!(t[0].transform, DAffine3::from_translation(DVec3::new(1.0, 2.0, 3.0)));
    let p = t[1].transform.transform_point3(DVec3::X);
    assert!((p - DVec3::new(0.0, 2.0, 0.0)).length() < 1e-12, "{p}");
    let p = t[2].transform.transform_point3(DVec3::ONE);
    assert!((p - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
    // Euler XYZ: R = Rx · Ry · Rz, so the vector is turned about z, then y, then x.
    let r = glam::DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2)
        * glam::DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let v = DVec3::new(0.3, -0.5, 0.7);
    assert!((t[3].transform.transform_vector3(v) - r * v).length() < 1e-12);
    assert_eq!(t[0].name, "objects[0]");
}

#[test]
fn perturbations() {
    let s = parse(
        "[[objects]]\nsphere = { radius = 1 }\n\
         [[objects.perturbations]]\nbump = { centre = [0, 1, 0], radius = 0.2 }\nf = 0.5\n\
         [[objects.perturbations]]\nbump = { center = [1, 0, 0], radius = [0.1, 0.2, 0.3] }\nf = -0.25\n\
         [[objects.perturbations]]\nquadric = [-1, -1, -1, 0, 0, 0, 0, 0, 0, 0.01]\nf = 2\n",
    );
    let p = &s.objects[0].shape.perturbations;
    assert_eq!(p.len(), 3);
    assert_eq!(p[0].quadric, Quadric::ellipsoid(DVec3::Y, DVec3::splat(0.2)));
    assert_eq!(p[0].form_factor, 0.5);
    assert_eq!(p[1].quadric, Quadric::ellipsoid(DVec3::X, DVec3::new(0.1, 0.2, 0.3)));
    assert_eq!(p[1].form_factor, -0.25);
    assert_eq!(p[2].quadric.coefficients()[9], 0.01);
    // The bump raises the surface above the pole.
    assert!(s.objects[0].shape.eval(DVec3::new(0.0, 1.01, 0.0)) > 0.0);
}

#[test]
fn scatter_places_bumps_on_the_ellipsoid() {
    let s = parse(
        "[[objects]]\nsphere = { radius = 2 }\n\
         [[objects.perturbations]]\nbump = { centre = [0, 2, 0], radius = 0.2 }\nf = 0.5\n\
         [[objects.scatter]]\ncount = 1000\nradius = 0.05\nf = 0.8\nalternate = true\n\
         [[objects.scatter]]\ncount = 10\non_radii = [1, 2, 3]\ncentre = [0, 1, 0]\nradius = 0.1\nf = 0.3\njitter = 0.5\nseed = 7\n",
    );
    let p = &s.objects[0].shape.perturbations;
    assert_eq!(p.len(), 1 + 1000 + 10);
    let centre = |q: &Quadric| q.support_bounds().unwrap().unwrap().centre();
    for (k, b) in p[1..1001].iter().enumerate() {
        assert!(near(centre(&b.quadric).length(), 2.0));
        assert_eq!(b.form_factor, if k % 2 == 0 { 0.8 } else { -0.8 });
        assert!(near(b.quadric.support_bounds().unwrap().unwrap().size().x, 0.1));
    }
    for b in &p[1001..] {
        let c = centre(&b.quadric) - DVec3::Y;
        assert!(near((c / DVec3::new(1.0, 2.0, 3.0)).length(), 1.0));
        assert_eq!(b.form_factor, 0.3);
    }
    // Deterministic.
    let again = parse(
        "[[objects]]\nsphere = { radius = 2 }\n\
         [[objects.scatter]]\ncount = 10\non_radii = [1, 2, 3]\ncentre = [0, 1, 0]\nradius = 0.1\nf = 0.3\njitter = 0.5\nseed = 7\n",
    );
    assert_eq!(&again.objects[0].shape.perturbations[..], &p[1001..]);
}

#[test]
fn materials_and_default_material() {
    let s = parse(
        "[[materials]]\nname = \"a\"\nalbedo = [0.1, 0.2, 0.3]\n\
         [[materials]]\nname = \"lamp\"\nemission = [5, 5, 5]\n\
         [[objects]]\nsphere = { radius = 1 }\nmaterial = \"lamp\"\n\
         [[objects]]\nname = \"plain\"\nsphere = { radius = 1 }\n\
         [[objects]]\nsphere = { radius = 1 }\n",
    );
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.materials[0].albedo, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(s.materials[0].emission, Vec3::ZERO);
    assert_eq!(s.materials[1].albedo, Vec3::splat(0.8));
    assert_eq!(s.materials[1].emission, Vec3::splat(5.0));
    assert_eq!(s.materials[2].name, DEFAULT_MATERIAL_NAME);
    assert_eq!(s.objects.iter().map(|o| o.material).collect::<Vec<_>>(), [1, 2, 2]);
    assert_eq!(s.objects[1].name, "plain");
    // No default material when every object names one.
    let s = parse("[[materials]]\nname = \"a\"\n[[objects]]\nsphere = { radius = 1 }\nmaterial = \"a\"\n");
    assert_eq!(s.materials.len(), 1);
}

#[test]
fn lights() {
    let s = parse(
        "[[lights]]\ntype = \"point\"\nposition = [1, 2, 3]\nintensity = [10, 10, 10]\n\
         [[lights]]\ntype = \"sphere\"\nposition = [0, 5, 0]\nradius = 0.5\nradiance = [4, 3, 2]\n",
    );
    assert_eq!(
        s.lights,
        [
            Light::Point { position: DVec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(10.0) },
            Light::Sphere { centre: DVec3::new(0.0, 5.0, 0.0), radius: 0.5, radiance: Vec3::new(4.0, 3.0, 2.0) },
        ]
    );
}

#[test]
fn max_depth_range() {
    for depth in [1, 64] {
        let s = parse_scene(&format!("[image]\nmax_depth = {depth}\n{CAMERA}"), "t.toml").unwrap();
        assert_eq!(s.image.max_depth, depth);
    }
    for depth in ["0", "65", "-1", "2.5"] {
        let e = parse_scene(&format!("[image]\nmax_depth = {depth}\n{CAMERA}"), "t.toml").unwrap_err();
        let SceneError::Invalid { line, ref field, .. } = e else { panic!("{e}") };
        assert_eq!((line, field.as_str()), (2, "image.max_depth"), "{e}");
    }
}

fn one_material(body: &str) -> Material {
    let s = parse(&format!("[[materials]]\nname = \"m\"\n{body}"));
    s.materials.into_iter().next().unwrap()
}

fn material_error(body: &str) -> String {
    let text = format!("{CAMERA}[[materials]]\nname = \"m\"\n{body}");
    parse_scene(&text, "t.toml").map(|_| ()).unwrap_err().to_string()
}

#[test]
fn material_types_and_defaults() {
    let d = one_material("");
    assert_eq!(d, Material::diffuse("m", Vec3::splat(0.8)));
    assert_eq!(one_material("type = \"diffuse\"\nalbedo = [0.1, 0.2, 0.3]").albedo, Vec3::new(0.1, 0.2, 0.3));

    let m = one_material("type = \"mirror\"");
    assert_eq!((m.kind, m.albedo, m.emission), (MaterialKind::Mirror, Vec3::ONE, Vec3::ZERO));
    assert_eq!(one_material("type = \"mirror\"\nalbedo = [0.9, 0.8, 0.7]").albedo, Vec3::new(0.9, 0.8, 0.7));

    let c = one_material("type = \"conductor\"");
    assert_eq!(
        c.kind,
        MaterialKind::Conductor { roughness: 0.3, fresnel: ConductorFresnel::Schlick { f0: Vec3::splat(0.9) } }
    );
    assert_eq!(c.albedo, Vec3::ONE);
    let c = one_material("type = \"conductor\"\nroughness = 0\nemission = [1, 2, 3]");
    assert!(matches!(c.kind, MaterialKind::Conductor { roughness: 0.0, .. }));
    assert_eq!(c.emission, Vec3::new(1.0, 2.0, 3.0));

    let g = one_material("type = \"dielectric\"");
    assert_eq!((g.kind, g.albedo), (MaterialKind::Dielectric { roughness: 0.0, ior: 1.5 }, Vec3::ONE));
    let w = one_material("type = \"dielectric\"\nior = 1.33\nroughness = 0.25");
    assert_eq!(w.kind, MaterialKind::Dielectric { roughness: 0.25, ior: 1.33 });

    // Emission on every type.
    for ty in ["diffuse", "conductor", "dielectric", "mirror"] {
        let m = one_material(&format!("type = \"{ty}\"\nemission = [4, 5, 6]"));
        assert_eq!(m.emission, Vec3::new(4.0, 5.0, 6.0), "{ty}");
    }
}

#[test]
fn conductor_fresnel_forms() {
    let fresnel = |body: &str| match one_material(&format!("type = \"conductor\"\n{body}")).kind {
        MaterialKind::Conductor { fresnel, .. } => fresnel,
        k => panic!("{k:?}"),
    };
    assert_eq!(fresnel("color = [0.95, 0.64, 0.54]"), ConductorFresnel::Schlick { f0: Vec3::new(0.95, 0.64, 0.54) });
    assert_eq!(
        fresnel("eta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.2]"),
        ConductorFresnel::Complex { eta: Vec3::new(0.2, 0.9, 1.1), k: Vec3::new(3.9, 2.4, 2.2) }
    );
    // k = 0 is allowed (a non-absorbing "conductor").
    assert_eq!(
        fresnel("k = [0, 0, 0]\neta = [1.5, 1.5, 1.5]"),
        ConductorFresnel::Complex { eta: Vec3::splat(1.5), k: Vec3::ZERO }
    );
    assert_eq!(fresnel("metal = \"aluminum\""), fresnel("metal = \"aluminium\""));
}

#[test]
fn named_metals_are_complex_iors() {
    /// Reflectance at normal incidence of a conductor in vacuum.
    fn f0(eta: Vec3, k: Vec3) -> Vec3 {
        ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k)
    }
    let mut seen = Vec::new();
    for (metal, preset) in
        [("gold", Metal::Gold), ("silver", Metal::Silver), ("copper", Metal::Copper), ("aluminium", Metal::Aluminium)]
    {
        let m = one_material(&format!("type = \"conductor\"\nmetal = \"{metal}\"\nroughness = 0.1"));
        let MaterialKind::Conductor { roughness, fresnel: ConductorFresnel::Complex { eta, k } } = m.kind else {
            panic!("{metal}: {:?}", m.kind)
        };
        assert_eq!(roughness, 0.1);
        assert_eq!((eta, k), preset.ior(), "{metal}");
        assert!(eta.min_element() > 0.0 && k.min_element() > 0.0, "{metal}");
        let r = f0(eta, k);
        assert!(r.min_element() > 0.3 && r.max_element() < 1.0, "{metal}: {r}");
        seen.push(r);
    }
    // Gold and copper are red-yellow: reflectance falls from red to blue;
    // silver and aluminium are nearly neutral and bright.
    for r in &seen[..1] {
        assert!(r.x > r.y && r.y > r.z, "{r}");
    }
    assert!(seen[2].x > seen[2].y && seen[2].x > seen[2].z, "copper {}", seen[2]);
    for r in [seen[1], seen[3]] {
        assert!(r.min_element() > 0.85 && r.max_element() - r.min_element() < 0.05, "{r}");
    }
}

#[test]
fn material_key_errors() {
    let e = material_error("ior = 1.5\n");
    assert!(
        e.starts_with("t.toml:6:7: materials[0].ior: `ior` does not apply to a diffuse material (the default type)"),
        "{e}"
    );
    assert!(e.contains("accepts name, type, albedo, emission") && e.contains("type = \"dielectric\""), "{e}");
    let e = material_error("type = \"conductor\"\nalbedo = [1, 1, 1]\n");
    assert!(e.contains("materials[0].albedo: `albedo` does not apply to a conductor material;"), "{e}");
    assert!(e.contains("type = \"diffuse\" or type = \"mirror\""), "{e}");
    let e = material_error("type = \"glass\"\n");
    assert!(e.contains("materials[0].type") && e.contains("`dielectric`"), "{e}");
    let e = material_error("type = \"conductor\"\nmetal = \"gold\"\ncolor = [1, 1, 1]\n");
    assert!(e.starts_with("t.toml:8:9: materials[0].color:") && e.contains("found `metal` and `color`"), "{e}");
    let e = material_error("type = \"conductor\"\neta = [1, 1, 1]\n");
    assert!(e.starts_with("t.toml:7:7: materials[0].k: the required key `k` is missing"), "{e}");
    let e = material_error("type = \"conductor\"\nk = [1, 1, 1]\n");
    assert!(e.contains("materials[0].eta: the required key `eta` is missing"), "{e}");
    let e = material_error("type = \"conductor\"\nmetal = \"iron\"\n");
    assert!(e.contains("materials[0].metal") && e.contains("unknown variant `iron`"), "{e}");
    let e = material_error("type = \"dielectric\"\nior = 0\n");
    assert!(e.contains("materials[0].ior: must be positive (got 0)"), "{e}");
    let e = material_error("type = \"conductor\"\neta = [1, 0, 1]\nk = [1, 1, 1]\n");
    assert!(e.contains("materials[0].eta[1]: must be positive (got 0)"), "{e}");
}

#[test]
fn rect_and_directional_lights() {
    let s = parse(
        "[[lights]]\ntype = \"rect\"\ncorner = [-1, 2, -1]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, 2]\nradiance = [5, 4, 3]\n\
         [[lights]]\ntype = \"directional\"\ndirection = [0, 3, 4]\nirradiance = [2, 2, 2]\n",
    );
    assert_eq!(
        s.lights[0],
        Light::Rect {
            corner: DVec3::new(-1.0, 2.0, -1.0),
            edge_u: DVec3::new(2.0, 0.0, 0.0),
            edge_v: DVec3::new(0.0, 0.0, 2.0),
            radiance: Vec3::new(5.0, 4.0, 3.0),
        }
    );
    let Light::Directional { direction, irradiance } = s.lights[1] else { panic!("{:?}", s.lights[1]) };
    assert!((direction - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-12, "normalised: {direction}");
    assert_eq!(irradiance, Vec3::splat(2.0));
    // The documented example emits downward.
    let Light::Rect { edge_u, edge_v, .. } = s.lights[0] else { unreachable!() };
    assert_eq!(edge_u.cross(edge_v), DVec3::new(0.0, -4.0, 0.0));
}

#[test]
fn light_errors() {
    let err = |body: &str| parse_scene(&format!("{CAMERA}[[lights]]\n{body}"), "t.toml").unwrap_err().to_string();
    let rect = |u: &str, v: &str| {
        err(&format!("type = \"rect\"\ncorner = [0, 0, 0]\nedge_u = {u}\nedge_v = {v}\nradiance = [1, 1, 1]\n"))
    };
    let e = rect("[1, 0, 0]", "[-2, 0, 0]");
    assert!(e.starts_with("t.toml:8:10: lights[0].edge_v: edge_u and edge_v are parallel"), "{e}");
    let e = rect("[0, 0, 0]", "[0, 0, 1]");
    assert!(e.starts_with("t.toml:7:10: lights[0].edge_u: must not be zero"), "{e}");
    let e = rect("[1, 0, 0]", "[0, 0, 0]");
    assert!(e.starts_with("t.toml:8:10: lights[0].edge_v: must not be zero"), "{e}");
    let e = err("type = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n");
    assert!(e.starts_with("t.toml:6:13: lights[0].direction: must not be zero"), "{e}");
    let e = err("type = \"rect\"\nposition = [0, 0, 0]\n");
    assert!(e.contains("lights[0].position: `position` does not apply to a rect light;"), "{e}");
    assert!(e.contains("accepts type, corner, edge_u, edge_v, radiance"), "{e}");
    let e = err("type = \"directional\"\ndirection = [0, 1, 0]\n");
    assert!(e.starts_with("t.toml:4:1: lights[0].irradiance: the required key `irradiance` of a directional"), "{e}");
    let e = err("type = \"sphere\"\nradius = 1\nradiance = [1, 1, 1]\n");
    assert!(e.contains("lights[0].position: the required key `position` of a sphere light is missing"), "{e}");
}

#[test]
fn camera_keyframes_interpolate_and_must_increase() {
    let text = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfps = 2\n\
                [[camera.keyframes]]\ntime = 0\nposition = [0, 0, 4]\nlook_at = [0, 0, 0]\n\
                [[camera.keyframes]]\ntime = 1\nposition = [2, 0, 4]\nlook_at = [0, 0, 0]\nfov = 60\n";
    let s = parse_scene(text, "t").unwrap();
    assert_eq!(s.camera.keyframes.len(), 2);
    assert_eq!(s.camera.keyframes[0].vfov_degrees, 40.0);
    // Frame 1 at 2 fps: halfway.
    let c = s.camera.at_frame(1);
    assert_eq!((c.position, c.vfov_degrees), (DVec3::new(1.0, 0.0, 4.0), 50.0));
    assert_eq!(s.camera.at_frame(7).position, DVec3::new(2.0, 0.0, 4.0));
    assert_eq!(s.camera.render_origin(), DVec3::new(0.0, 0.0, 4.0));
    let e = parse_scene(&text.replace("time = 1", "time = 0"), "t").unwrap_err().to_string();
    assert!(e.contains("camera.keyframes[1].time") && e.contains("later"), "{e}");
    let e = parse_scene(&text.replace("position = [2, 0, 4]", "position = [0, 0, 0]"), "t").unwrap_err().to_string();
    assert!(e.contains("camera.keyframes[1].look_at"), "{e}");
}

#[test]
fn camera() {
    let s =
        parse_scene("[camera]\nposition = [1, 2, 3]\nlook_at = [0, 1, 0]\nup = [0, 0, 1]\nfov = 60\n", "t").unwrap();
    assert_eq!(s.camera, Camera::still(DVec3::new(1.0, 2.0, 3.0), DVec3::Y, DVec3::Z, 60.0));
}

#[test]
fn default_scene_parses_and_is_bounded() {
    let s = parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.objects.len() >= 3);
    assert!(!s.lights.is_empty());
    for o in &s.objects {
        assert!(o.shape.bounds().is_ok(), "{}", o.name);
    }
}

#[test]
fn generated_maps_and_deduplication() {
    let s = parse(
        "[[materials]]\nname = \"a\"\nalbedo_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], 0.1] } }\n\
         normal_map = { bumps = { size = 32, count = 10, seed = 3, strength = 4.0 } }\n\
         [[materials]]\nname = \"b\"\ntype = \"mirror\"\n\
         albedo_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]] } }\n\
         displacement_map = { bumps = { size = 32, count = 10, seed = 3 }, scale = 0.02 }\n\
         [[materials]]\nname = \"c\"\ntype = \"conductor\"\n\
         roughness_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], 0.1] } }\n\
         normal_map = { bumps = { size = 32, count = 10, seed = 3, strength = 4 } }\n\
         displacement_map = { bumps = { size = 32, count = 10, seed = 3 }, scale = 0.5 }\n\
         [[materials]]\nname = \"d\"\ntype = \"dielectric\"\n\
         normal_map = { bumps = { size = 32, count = 10, seed = 4 } }\n",
    );
    let maps: Vec<&MaterialMaps> = s.materials.iter().map(|m| &m.maps).collect();
    // a: checker 0, normals 1; b: the same checker, heights 2; c: the
    // checker read as data is another texture (3), the same normals, the
    // same heights with another scale; d: other normals (4).
    assert_eq!(*maps[0], MaterialMaps { albedo: Some(0), normal: Some(1), roughness: None, displacement: None });
    assert_eq!(
        *maps[1],
        MaterialMaps { albedo: Some(0), normal: None, roughness: None, displacement: Some((2, 0.02)) }
    );
    assert_eq!(
        *maps[2],
        MaterialMaps { albedo: None, normal: Some(1), roughness: Some(3), displacement: Some((2, 0.5)) }
    );
    assert_eq!(maps[3].normal, Some(4));
    assert_eq!(s.textures.len(), 5);
    // With a colour map, a diffuse albedo defaults to 1; without, to 0.8.
    assert_eq!(s.materials[0].albedo, Vec3::ONE);
    assert_eq!(
        one_material("albedo_map = { checker = { size = 1, cells = 1, colors = [1, 1] } }\nalbedo = [0.5, 0.5, 0.5]")
            .albedo,
        Vec3::splat(0.5)
    );
    let checker = &s.textures[0];
    assert_eq!((checker.width, checker.height, checker.levels.len()), (16, 16, 5));
    assert_eq!(checker.levels[0][0], [0.9, 0.9, 0.9, 1.0]);
    assert_eq!(checker.levels[0][4], [0.1, 0.1, 0.1, 1.0]);
    assert_eq!(s.textures[3].levels[0], checker.levels[0]);
    assert_eq!(s.textures[1], texture::normals_from_heights(&texture::bump_heights(32, 10, 3), 4.0));
    assert_eq!(s.textures[2], texture::bump_heights(32, 10, 3));
    assert_eq!(s.textures[4], texture::normals_from_heights(&texture::bump_heights(32, 10, 4), 1.0));
    // No maps, no textures.
    assert!(parse("[[materials]]\nname = \"m\"\n").textures.is_empty());
}

/// Writes an 8-bit PNG with `channels` channels (1 or 3) of value `v`.
fn write_png(path: &Path, channels: u8, v: u8) {
    match channels {
        1 => image::GrayImage::from_pixel(2, 2, image::Luma([v])).save(path).unwrap(),
        _ => image::RgbImage::from_pixel(2, 2, image::Rgb([v, v, v])).save(path).unwrap(),
    }
}

#[test]
fn texture_files_are_relative_to_the_scene_and_loaded_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("tex")).unwrap();
    write_png(&dir.path().join("tex/grey.png"), 1, 128);
    write_png(&dir.path().join("tex/rgb.png"), 3, 128);
    let text = format!(
        "{CAMERA}[[materials]]\nname = \"a\"\nalbedo_map = \"tex/grey.png\"\nnormal_map = \"tex/rgb.png\"\n\
         [[materials]]\nname = \"b\"\nalbedo_map = {{ file = \"tex/grey.png\" }}\n\
         displacement_map = {{ file = \"tex/rgb.png\", scale = 0.1 }}\n\
         [[materials]]\nname = \"c\"\ntype = \"conductor\"\nroughness_map = \"tex/grey.png\"\n\
         normal_map = \"{}\"\n",
        dir.path().join("tex/rgb.png").display().to_string().replace('\\', "\\\\")
    );
    let scene_file = dir.path().join("scene.toml");
    let s = parse_scene(&text, &scene_file.display().to_string()).unwrap_or_else(|e| panic!("{e}"));
    let maps: Vec<&MaterialMaps> = s.materials.iter().map(|m| &m.maps).collect();
    // grey as colour: 0; rgb as data: 1 (normal, displacement, and by
    // absolute path); grey as data: 2.
    assert_eq!((maps[0].albedo, maps[0].normal), (Some(0), Some(1)));
    assert_eq!((maps[1].albedo, maps[1].displacement), (Some(0), Some((1, 0.1))));
    assert_eq!((maps[2].roughness, maps[2].normal), (Some(2), Some(1)));
    assert_eq!(s.textures.len(), 3);
    assert!((s.textures[0].levels[0][0][0] - 0.215_860_5).abs() < 1e-6, "sRGB-decoded");
    assert!((s.textures[1].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");
    assert!((s.textures[2].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");
    assert!(s.textures[0].source.ends_with("grey.png"));

    // A grey image cached for a roughness map is still no normal map.
    let text = format!(
        "{CAMERA}[[materials]]\nname = \"c\"\ntype = \"conductor\"\nroughness_map = \"tex/grey.png\"\n\
         normal_map = \"tex/grey.png\"\n"
    );
    let e = parse_scene(&text, &scene_file.display().to_string()).unwrap_err().to_string();
    assert!(e.contains(":8:14: materials[0].normal_map: cannot load the normal map:"), "{e}");
    assert!(e.contains("grey.png: a normal map needs 3 colour channels (RGB) but the image has 1"), "{e}");

    // A missing file names the resolved path and the field.
    let text = format!("{CAMERA}[[materials]]\nname = \"m\"\nalbedo_map = {{ file = \"tex/nope.png\" }}\n");
    let e = parse_scene(&text, &scene_file.display().to_string()).unwrap_err().to_string();
    let missing = dir.path().join("tex/nope.png").display().to_string();
    assert!(e.contains(":6:23: materials[0].albedo_map.file: cannot load the albedo map: "), "{e}");
    assert!(e.contains(&format!("{missing}: no such file")), "{e}");
}

#[test]
fn objects_are_checked_before_maps_are_loaded() {
    // An unbounded object is reported even though the material's map is
    // missing: maps (which can take seconds to load or generate) come
    // last.
    let text = format!(
        "{CAMERA}[[materials]]\nname = \"m\"\nalbedo_map = \"nope.png\"\n\
         [[objects]]\nname = \"floor\"\nmaterial = \"m\"\nplane = {{}}\n"
    );
    let e = parse_scene(&text, "t.toml").unwrap_err().to_string();
    assert!(e.contains("objects[0].plane: the plane surface is unbounded"), "{e}");
    // A bounded object: now the map is loaded, and its error reported.
    let text = text.replace("plane = {}", "plane = {}\nclip = { min = [-1, -1, -1], max = [1, 1, 1] }");
    let e = parse_scene(&text, "t.toml").unwrap_err().to_string();
    assert!(e.contains("materials[0].albedo_map: cannot load the albedo map"), "{e}");
}

#[test]
fn uv_settings() {
    let s = parse(
        "[[objects]]\nsphere = { radius = 1 }\n\
         [[objects]]\nsphere = { radius = 1 }\nuv = { scale = [8, 4], offset = [0.5, -1] }\n\
         [[objects]]\nsphere = { radius = 1 }\nuv = { mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 0, 2], scale = [2, -2] }\n\
         [[objects]]\nsphere = { radius = 1 }\nuv = { mapping = \"cylindrical\", scale = [4, 1] }\n",
    );
    let uv: Vec<UvSettings> = s.objects.iter().map(|o| o.uv).collect();
    assert_eq!(uv[0], UvSettings::default());
    assert_eq!(uv[0], UvSettings { mapping: UvMapping::Spherical, scale: DVec2::ONE, offset: DVec2::ZERO });
    assert_eq!(
        uv[1],
        UvSettings { mapping: UvMapping::Spherical, scale: DVec2::new(8.0, 4.0), offset: DVec2::new(0.5, -1.0) }
    );
    assert_eq!(uv[2].mapping, UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::new(0.0, 0.0, 2.0) });
    assert_eq!(uv[2].scale, DVec2::new(2.0, -2.0));
    assert_eq!((uv[3].mapping, uv[3].scale), (UvMapping::Cylindrical, DVec2::new(4.0, 1.0)));
}

#[test]
fn uv_errors() {
    let err = |uv: &str| {
        let text = format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nuv = {uv}\n");
        parse_scene(&text, "t.toml").unwrap_err().to_string()
    };
    let e = err("{ mapping = \"cubic\" }");
    assert!(e.starts_with("t.toml:6:18: objects[0].uv.mapping: unknown variant `cubic`"), "{e}");
    assert!(e.contains("`planar`, `spherical`, `cylindrical`"), "{e}");
    let e = err("{ mapping = \"planar\", u_axis = [1, 0, 0] }");
    assert!(e.starts_with("t.toml:6:6: objects[0].uv.v_axis: the required key `v_axis` of a planar"), "{e}");
    let e = err("{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [-2, 0, 0] }");
    assert!(e.starts_with("t.toml:6:57: objects[0].uv.v_axis: u_axis and v_axis are parallel"), "{e}");
    let e = err("{ mapping = \"planar\", u_axis = [0, 0, 0], v_axis = [1, 0, 0] }");
    assert!(e.starts_with("t.toml:6:37: objects[0].uv.u_axis: must not be zero"), "{e}");
    let e = err("{ u_axis = [1, 0, 0] }");
    assert!(e.contains("objects[0].uv.u_axis: `u_axis` does not apply to the spherical mapping (the default"), "{e}");
    let e = err("{ mapping = \"cylindrical\", v_axis = [1, 0, 0] }");
    assert!(e.contains("objects[0].uv.v_axis: `v_axis` does not apply to the cylindrical mapping;"), "{e}");
    let e = err("{ scale = [1, 0] }");
    assert!(e.starts_with("t.toml:6:20: objects[0].uv.scale[1]: must not be zero"), "{e}");
    let e = err("{ scale = [1, 2, 3] }");
    assert!(e.contains("objects[0].uv.scale: must be an array of 2 numbers (got 3)"), "{e}");
    let e = err("{ offset = [1, 2], scael = [1, 1] }");
    assert!(e.contains("objects[0].uv.scael: unknown field `scael`"), "{e}");
}

#[test]
fn map_errors() {
    let e = material_error("normal_map = { checker = { size = 4, cells = 2, colors = [0, 1] } }\n");
    assert!(e.starts_with("t.toml:6:26: materials[0].normal_map.checker: `checker` does not apply"), "{e}");
    assert!(e.contains("a normal map; it takes `file` or `bumps`"), "{e}");
    let e = material_error("albedo_map = { file = \"a.png\", checker = { size = 4, cells = 2, colors = [0, 1] } }\n");
    assert!(e.starts_with("t.toml:6:42: materials[0].albedo_map.checker: the albedo map needs exactly one of"), "{e}");
    assert!(e.contains("found both"), "{e}");
    let e = material_error("albedo_map = {}\n");
    assert!(
        e.contains("materials[0].albedo_map: the albedo map needs exactly one of `file` and `checker`; found neither")
    );
    let e = material_error("albedo_map = { file = \"a.png\", scale = 2 }\n");
    assert!(e.contains("materials[0].albedo_map.scale: `scale` applies only to a displacement map"), "{e}");
    let e = material_error("displacement_map = \"h.png\"\n");
    assert!(e.starts_with("t.toml:6:20: materials[0].displacement_map: a displacement map needs a height"), "{e}");
    let e = material_error("displacement_map = { file = \"h.png\" }\n");
    assert!(e.contains("materials[0].displacement_map.scale: the required key `scale`"), "{e}");
    let e = material_error("displacement_map = { file = \"h.png\", scale = -0.1 }\n");
    assert!(e.contains("materials[0].displacement_map.scale: must be positive (got -0.1)"), "{e}");
    let e = material_error("displacement_map = { bumps = { size = 8, count = 1, strength = 2 }, scale = 1 }\n");
    assert!(e.contains("materials[0].displacement_map.bumps.strength: `strength` applies only"), "{e}");
    let e = material_error("albedo_map = { checker = { size = 100, cells = 2, colors = [0, 1] } }\n");
    assert!(e.contains("materials[0].albedo_map.checker.size: must be a power of two from 1 to 16384"), "{e}");
    let e = material_error("albedo_map = { checker = { size = 4, cells = 8, colors = [0, 1] } }\n");
    assert!(e.contains("materials[0].albedo_map.checker.cells: must be at most the texture size 4 (got 8)"));
    let e = material_error("albedo_map = { checker = { size = 4, cells = 2, colors = [0, 1, 1] } }\n");
    assert!(e.contains("materials[0].albedo_map.checker.colors: must be an array of 2 colours (got 3)"), "{e}");
    let e = material_error("albedo_map = { checker = { size = 4, cells = 2, colors = [0, [1, 2, 0]] } }\n");
    assert!(e.contains("materials[0].albedo_map.checker.colors[1][1]: must be between 0 and 1 (got 2)"), "{e}");
    let e = material_error("normal_map = { bumps = { size = 4, count = 0 } }\n");
    assert!(e.contains("materials[0].normal_map.bumps.count: must be an integer from 1 to"), "{e}");
    let e = material_error("normal_map = 3\n");
    assert!(e.contains("materials[0].normal_map: invalid type: integer `3`, expected a file path"), "{e}");
    let e = material_error("albedo_map = \"\"\n");
    assert!(e.contains("materials[0].albedo_map: the texture path must not be empty"), "{e}");
    let e = material_error("roughness_map = \"r.png\"\n");
    assert!(e.contains("materials[0].roughness_map: `roughness_map` does not apply to a diffuse material"), "{e}");
    assert!(e.contains("belongs to type = \"conductor\" or type = \"dielectric\""), "{e}");
    let e = material_error("type = \"conductor\"\nalbedo_map = \"a.png\"\n");
    assert!(e.contains("`albedo_map` does not apply to a conductor material"), "{e}");
    assert!(e.contains("belongs to type = \"diffuse\" or type = \"mirror\""), "{e}");
}

#[test]
fn environment_sky_and_scale() {
    // No [environment]: none.
    assert_eq!(parse("").environment, None);
    let s = parse("[environment]\nmap = { sky = { width = 16, height = 8 } }\n");
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 1.0 }));
    assert_eq!(s.background, Vec3::ZERO);
    assert_eq!(s.textures, [procedural_sky(16, 8)]);
    // After the material maps; the scale is kept; any power-of-two sizes in range.
    let s = parse(
        "[[materials]]\nname = \"a\"\nalbedo_map = { checker = { size = 4, cells = 2, colors = [0, 1] } }\n\
         [environment]\nscale = 0.25\nmap = { sky = { width = 2, height = 1 } }\n",
    );
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 1, scale: 0.25 }));
    assert_eq!((s.textures[1].width, s.textures[1].height), (2, 1));
    assert_eq!(s.materials[0].maps.albedo, Some(0));
    let s = parse("[environment]\nmap = { sky = { width = 8, height = 8 } }\nscale = 0\n");
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 0.0 }));
    // The largest sky is accepted (read without generating it).
    let largest: RawSky = toml::from_str("width = 4096\nheight = 2048").unwrap();
    assert_eq!((largest.width.0, largest.height.0), (4096, 2048));
    // The inline form, before the first table.
    let s = parse_scene(&format!("environment = {{ map = {{ sky = {{ width = 8, height = 4 }} }} }}\n{CAMERA}"), "t")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 1.0 }));
}

#[test]
fn environment_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("env")).unwrap();
    write_png(&dir.path().join("env/grey.png"), 1, 128);
    exr::prelude::write_rgb_file(dir.path().join("env/hdr.exr"), 4, 2, |x, _| (5.0f32, 0.5, x as f32)).unwrap();
    let scene_file = dir.path().join("scene.toml").display().to_string();
    let load = |body: &str| parse_scene(&format!("{CAMERA}{body}"), &scene_file);

    // EXR: linear, values above 1 kept; the path is relative to the scene.
    let s = load("[environment]\nmap = \"env/hdr.exr\"\nscale = 2\n").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 2.0 }));
    let t = &s.textures[0];
    assert_eq!((t.width, t.height), (4, 2));
    assert_eq!(t.levels[0][3], [5.0, 0.5, 3.0, 1.0]);
    assert!(t.source.ends_with("hdr.exr"), "{}", t.source);

    // PNG: sRGB-decoded like a colour map; the table form; shared with
    // an albedo map of the same file, but not with a data map of it.
    let s = load(
        "[[materials]]\nname = \"a\"\ntype = \"conductor\"\nroughness_map = \"env/grey.png\"\n\
         [[materials]]\nname = \"b\"\nalbedo_map = \"env/grey.png\"\n\
         [environment]\nmap = { file = \"env/grey.png\" }\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.materials[0].maps.roughness, Some(0));
    assert_eq!(s.materials[1].maps.albedo, Some(1));
    assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 1, scale: 1.0 }));
    assert_eq!(s.textures.len(), 2);
    assert!((s.textures[1].levels[0][0][0] - 0.215_860_5).abs() < 1e-6, "sRGB-decoded");
    assert!((s.textures[0].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");

    // A missing file names the field, the scene's line and column and the resolved path.
    let e = load("[environment]\nmap = \"env/nope.exr\"\n").unwrap_err().to_string();
    let missing = dir.path().join("env/nope.exr").display().to_string();
    assert!(e.contains(":5:7: environment.map: cannot load the environment map: "), "{e}");
    assert!(e.contains(&format!("{missing}: no such file")), "{e}");
    let e = load("[environment]\nmap = { file = \"nope.png\" }\n").unwrap_err().to_string();
    assert!(e.contains(":5:16: environment.map.file: cannot load the environment map: "), "{e}");
}

#[test]
fn environment_errors() {
    let err = |body: &str| parse_scene(&format!("{CAMERA}{body}"), "t.toml").unwrap_err().to_string();
    let sky = "map = { sky = { width = 8, height = 4 } }";

    // Both background and [environment]: at the second.
    let e = parse_scene(&format!("background = [1, 1, 1]\n{CAMERA}[environment]\n{sky}\n"), "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.toml:5:1: environment: give either background or [environment], not both"), "{e}");
    assert!(e.contains("(background is at line 1)") && e.contains("\n5 | [environment]\n"), "{e}");
    let e = parse_scene(&format!("environment = {{ {sky} }}\nbackground = [0, 0, 0]\n{CAMERA}"), "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.toml:2:14: background: give either background or [environment], not both"), "{e}");
    assert!(e.contains("([environment] is at line 1)"), "{e}");

    let e = err("[environment]\nmap = { sky = { width = 500, height = 256 } }\n");
    assert!(e.starts_with("t.toml:5:25: environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
    assert!(e.contains("(got 500)"), "{e}");
    let e = err("[environment]\nmap = { sky = { width = 1, height = 1 } }\n");
    assert!(e.contains("environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
    let e = err("[environment]\nmap = { sky = { width = 8192, height = 4096 } }\n");
    assert!(e.contains("environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
    let e = err("[environment]\nmap = { sky = { width = 8, height = 0 } }\n");
    assert!(
        e.contains("environment.map.sky.height: must be a power of two from 1 to 2048,") && e.contains("(got 0)"),
        "{e}"
    );
    let e = err("[environment]\nmap = { sky = { width = 8 } }\n");
    assert!(e.contains("environment.map.sky.height: the required key `height` is missing"), "{e}");
    let e = err(&format!("[environment]\n{sky}\nscale = -1\n"));
    assert!(e.starts_with("t.toml:6:9: environment.scale: must not be negative (got -1)"), "{e}");
    let e = err(&format!("[environment]\n{sky}\nscale = inf\n"));
    assert!(e.contains("environment.scale: must be a finite number"), "{e}");
    let e = err(&format!("[environment]\n{sky}\nexposure = 1\n"));
    assert!(e.starts_with("t.toml:6:1: environment.exposure: unknown field `exposure`"), "{e}");
    let e = err("[environment]\nmap = { sky = { width = 8, height = 4, sun = 1 } }\n");
    assert!(e.contains("environment.map.sky.sun: unknown field `sun`"), "{e}");
    let e = err("[environment]\nmap = { checker = 1 }\n");
    assert!(e.contains("environment.map.checker: unknown field `checker`, expected `file` or `sky`"), "{e}");
    let e = err("[environment]\nscale = 1\n");
    assert!(e.contains("environment.map: the required key `map` is missing"), "{e}");
    let e = err("[environment]\nmap = {}\n");
    assert!(
        e.starts_with(
            "t.toml:5:7: environment.map: the environment map needs exactly one of `file` and `sky`; found neither"
        ),
        "{e}"
    );
    let e = err("[environment]\nmap = { file = \"a.exr\", sky = { width = 8, height = 4 } }\n");
    assert!(e.starts_with("t.toml:5:31: environment.map.sky: the environment map needs exactly one"), "{e}");
    assert!(e.contains("found both"), "{e}");
    let e = err("[environment]\nmap = \"\"\n");
    assert!(e.contains("environment.map: the texture path must not be empty"), "{e}");
    let e = err("[environment]\nmap = 3\n");
    assert!(e.contains("environment.map: invalid type: integer `3`, expected a file path such as \"sky.exr\""), "{e}");
    // A background written after [environment] lands in it; the message says so.
    let e = err(&format!("[environment]\n{sky}\nbackground = [0, 0, 0]\n"));
    assert!(e.contains("environment.background: unknown field") && e.contains("must come before"), "{e}");
}

#[test]
fn fog_and_dielectric_media() {
    // Top-level keys come before the first [table].
    let with_fog = |fog: &str| parse_scene(&format!("{fog}\n{CAMERA}"), "t.toml");
    let s = with_fog("fog = { density = 0.2, albedo = [0.9, 0.8, 0.7], anisotropy = 0.3 }").unwrap();
    let fog = s.fog.unwrap();
    assert_eq!((fog.density, fog.albedo, fog.anisotropy), (0.2, Vec3::new(0.9, 0.8, 0.7), 0.3));
    // Defaults: no absorption, isotropic.
    let fog = with_fog("fog = { density = 1 }").unwrap().fog.unwrap();
    assert_eq!((fog.albedo, fog.anisotropy), (Vec3::ONE, 0.0));
    assert!(parse("").fog.is_none());
    let m = one_material("type = \"dielectric\"\nior = 1.33\nmedium = { density = 0.5, albedo = [0.4, 0.4, 0.4] }\n");
    assert_eq!(m.medium.unwrap().albedo, Vec3::splat(0.4));

    let err = |fog: &str| with_fog(fog).unwrap_err().to_string();
    let e = err("fog = { density = -1 }");
    assert!(e.contains("fog.density: must not be negative (got -1)"), "{e}");
    let e = err("fog = { density = 1, anisotropy = 1 }");
    assert!(e.contains("fog.anisotropy: must be between -0.99 and 0.99 (got 1)"), "{e}");
    let e = err("fog = { density = 1, colour = [1, 1, 1] }");
    assert!(e.contains("fog.colour: unknown field"), "{e}");
    let e = err("fog = { albedo = [1, 1, 1] }");
    assert!(e.contains("fog.density: the required key `density` is missing"), "{e}");
    let e = parse_scene(&format!("{CAMERA}[[materials]]\nname = \"m\"\nmedium = {{ density = 1 }}\n"), "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("materials[0].medium") && e.contains("dielectric"), "{e}");
}

#[test]
fn error_location_counts_characters() {
    let e =
        parse_scene("# é\n[camera]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\nfov = 200 # é\n", "x.toml").unwrap_err();
    let SceneError::Invalid { line, column, ref field, .. } = e else { panic!("{e}") };
    assert_eq!((line, column, field.as_str()), (5, 7, "camera.fov"));
    assert!(e.to_string().contains("\n5 | fov = 200 # é\n  |       ^^^"), "{e}");
}
