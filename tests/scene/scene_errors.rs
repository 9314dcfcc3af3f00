//! Bad scene files must give messages that name the file, the line, the
//! field and the reason. Each input is written to a temporary file and loaded
//! with `load_scene`, as the binary does.

use std::path::Path;

use quadray::model::scene::{
    load_scene, parse_scene, ConductorFresnel, Light, MaterialKind, Scene, SceneError, DEFAULT_SCENE,
    DEFAULT_SCENE_NAME,
};

/// A valid camera, three lines long.
const CAMERA: &str = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n";

/// Writes `text` to `<tempdir>/<name>` and loads it.
fn load(name: &str, text: &str) -> Result<Scene, SceneError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    load_scene(&path)
}

/// Loads `text` from `<name>`, expects an error at `line` and checks that the
/// message starts with `<path>:<line>:` and contains every one of `needles`.
#[track_caller]
fn check(name: &str, text: &str, line: usize, needles: &[&str]) -> String {
    let message = match load(name, text) {
        Ok(_) => panic!("{name}: expected an error for\n{text}"),
        Err(e) => e.to_string(),
    };
    let first = message.lines().next().unwrap();
    let location = format!("{name}:{line}:");
    assert!(first.contains(&location), "{name}: expected `{location}` in\n{message}");
    for n in needles {
        assert!(message.contains(n), "{name}: expected `{n}` in\n{message}");
    }
    message
}

#[test]
fn unknown_keys() {
    check("typo.toml", &format!("{CAMERA}[image]\nwidht = 5\n"), 5, &["image.widht", "unknown field `widht`"]);
    check(
        "typo_shape.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1, colour = 2 }}\n"),
        5,
        &["objects[0].sphere.colour", "unknown field `colour`"],
    );
    check(
        "typo_object.toml",
        &format!(
            "{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n\n[[objects]]\nsphere = {{ radius = 1 }}\ncolor = 1\n"
        ),
        9,
        &["objects[1].color", "unknown field `color`"],
    );
    check(
        "typo_bump.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nbump = {{ centre = [0, 1, 0], radius = 0.1 }}\nform = 1\n"),
        8,
        &["objects[0].perturbations[0].form", "unknown field `form`"],
    );
    check("typo_top.toml", &format!("backgruond = [0, 0, 0]\n{CAMERA}"), 1, &["backgruond", "unknown field"]);
    // A top-level key after a table lands in that table; the message says so.
    check(
        "late_background.toml",
        &format!("{CAMERA}background = [0, 0, 0]\n"),
        4,
        &["camera.background", "must come before the first [table]"],
    );
}

#[test]
fn nan_and_infinity() {
    let m = check(
        "nan.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = nan }}\n"),
        5,
        &["objects[0].sphere.radius", "must be a finite number (got NaN)"],
    );
    assert!(m.contains("nan.toml:5:21:"), "column of the value: {m}");
    check(
        "inf.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\ntranslate = [1, -inf, 0]\n"),
        6,
        &["objects[0].translate[1]", "must be a finite number (got -inf)", ":6:17:"],
    );
    check(
        "inf_camera.toml",
        "[camera]\nposition = [0, 0, +inf]\nlook_at = [0, 0, 0]\n",
        2,
        &["camera.position[2]", "must be a finite number (got inf)"],
    );
    check(
        "nan_f.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nbump = {{ centre = [0, 1, 0], radius = 0.1 }}\nf = nan\n"),
        8,
        &["objects[0].perturbations[0].f", "finite"],
    );
    check(
        "nan_quadric.toml",
        &format!("{CAMERA}[[objects]]\nquadric = [-1, -1, -1, 0, 0, 0, 0, 0, nan, 1]\n"),
        5,
        &["objects[0].quadric[8]", "finite"],
    );
    check("nan_background.toml", &format!("background = [0, inf, 0]\n{CAMERA}"), 1, &["background[1]", "finite"]);
}

#[test]
fn negative_radii() {
    check(
        "sphere_radius.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects]]\nsphere = {{ radius = -1 }}\n"),
        7,
        &["objects[1].sphere.radius", "must be positive (got -1)", ":7:21:"],
    );
    check(
        "zero_radius.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 0 }}\n"),
        5,
        &["objects[0].sphere.radius", "must be positive (got 0)"],
    );
    check(
        "light_radius.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"sphere\"\nposition = [0, 4, 0]\nradius = -2\nradiance = [1, 1, 1]\n"),
        7,
        &["lights[0].radius", "must be positive (got -2)"],
    );
    check(
        "bump_radius.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n\n[[objects.perturbations]]\nbump = {{ centre = [0, 1, 0], radius = -0.2 }}\nf = 1\n"),
        8,
        &["objects[0].perturbations[0].bump.radius", "must be positive (got -0.2)"],
    );
    check(
        "bump_radii.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nbump = {{ centre = [0, 1, 0], radius = [0.1, -0.2, 0.1] }}\nf = 1\n"),
        7,
        &["objects[0].perturbations[0].bump.radius[1]", "must be positive"],
    );
    check(
        "scatter_radius.toml",
        &format!(
            "{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.scatter]]\ncount = 10\nradius = -0.1\nf = 1\n"
        ),
        8,
        &["objects[0].scatter[0].radius", "must be positive"],
    );
    check(
        "scale.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nscale = [1, 0, 1]\n"),
        6,
        &["objects[0].scale[1]", "must be positive (got 0)"],
    );
}

#[test]
fn image_settings() {
    for (key, value, shown) in
        [("width", "0", "0"), ("height", "-5", "-5"), ("spp", "0", "0"), ("width", "20000", "20000")]
    {
        let name = format!("image_{key}_{}.toml", value.trim_start_matches('-'));
        check(
            &name,
            &format!("[image]\n{key} = {value}\n{CAMERA}"),
            2,
            &[&format!("image.{key}"), &format!("(got {shown})"), "must be an integer from 1 to"],
        );
    }
    check("spp_float.toml", &format!("[image]\nspp = 2.5\n{CAMERA}"), 2, &["image.spp", "expected an integer"]);
    check("seed.toml", &format!("[image]\nseed = -1\n{CAMERA}"), 2, &["image.seed", "from 0 to 4294967295"]);
    for depth in ["0", "65"] {
        check(
            &format!("max_depth_{depth}.toml"),
            &format!("{CAMERA}[image]\nspp = 4\nmax_depth = {depth}\n"),
            6,
            &[":6:13:", "image.max_depth", "must be an integer from 1 to 64", &format!("(got {depth})")],
        );
    }
    check(
        "max_depth_float.toml",
        &format!("[image]\nmax_depth = 4.0\n{CAMERA}"),
        2,
        &["image.max_depth", "expected an integer from 1 to 64"],
    );
}

#[test]
fn degenerate_quadrics() {
    check(
        "zero_quadric.toml",
        &format!("{CAMERA}[[objects]]\nquadric = [0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n"),
        5,
        &["objects[0].quadric", "degenerate"],
    );
    check(
        "constant_quadric.toml",
        &format!("{CAMERA}[[objects]]\nquadric = [0, 0, 0, 0, 0, 0, 0, 0, 0, 3]\n"),
        5,
        &["objects[0].quadric", "degenerate"],
    );
    check(
        "constant_perturbation.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nquadric = [0, 0, 0, 0, 0, 0, 0, 0, 0, 1]\nf = 1\n"),
        7,
        &["objects[0].perturbations[0].quadric", "degenerate"],
    );
    check(
        "short_quadric.toml",
        &format!("{CAMERA}[[objects]]\nquadric = [1, 2, 3]\n"),
        5,
        &["objects[0].quadric", "must be an array of 10 numbers (got 3)"],
    );
    check(
        "empty_quadric.toml",
        &format!("{CAMERA}[[objects]]\nquadric = [-1, -1, -1, 0, 0, 0, 0, 0, 0, -1]\n"),
        5,
        &["objects[0].quadric", "empty"],
    );
}

#[test]
fn unbounded_surfaces_need_a_clip_box() {
    for (key, shape) in [
        ("plane", "plane = {}"),
        ("cylinder", "cylinder = { radius = 0.5 }"),
        ("cone", "cone = { half_angle = 30 }"),
        ("paraboloid", "paraboloid = { curvature = 1 }"),
        ("hyperboloid", "hyperboloid = { radius = 0.5, slope = 1 }"),
        ("hyperboloid", "hyperboloid = { radius = 0.5, slope = 1, sheets = 2 }"),
        ("quadric", "quadric = [1, 1, -1, 0, 0, 0, 0, 0, 0, -1]"),
    ] {
        let text = format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects]]\nname = \"x\"\n{shape}\n");
        check(&format!("unbounded_{key}.toml"), &text, 8, &[&format!("objects[1].{key}"), "unbounded", "clip"]);
        // With a clip box it loads.
        let clipped = format!("{text}clip = {{ min = [-1, -1, -1], max = [1, 1, 1] }}\n");
        load(&format!("clipped_{key}.toml"), &clipped).unwrap_or_else(|e| panic!("{e}"));
    }
    check(
        "unbounded_bump.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nquadric = [1, 0, 0, 0, 0, 0, 0, 0, 0, 0]\nf = 1\n"),
        6,
        &["objects[0].perturbations[0]", "unbounded", "clip"],
    );
}

#[test]
fn clip_boxes() {
    check(
        "clip_inverted.toml",
        &format!("{CAMERA}[[objects]]\nplane = {{}}\nclip = {{ min = [-1, 1, -1], max = [1, -1, 1] }}\n"),
        6,
        &["objects[0].clip", "min must be less than clip.max", "y: min 1 >= max -1"],
    );
    check(
        "clip_outside.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nclip = {{ min = [2, 2, 2], max = [3, 3, 3] }}\n"),
        6,
        &["objects[0].clip", "no point inside the clip box"],
    );
    check(
        "clip_missing_max.toml",
        &format!("{CAMERA}[[objects]]\nplane = {{}}\nclip = {{ min = [-1, -1, -1] }}\n"),
        6,
        &["objects[0].clip.max", "missing"],
    );
}

#[test]
fn materials() {
    let m = check(
        "unknown_material.toml",
        &format!(
            "{CAMERA}[[materials]]\nname = \"clay\"\n[[objects]]\nsphere = {{ radius = 1 }}\nmaterial = \"gold\"\n"
        ),
        8,
        &["objects[0].material", "unknown material \"gold\"", "\"clay\""],
    );
    assert!(m.contains(":8:12:"), "{m}");
    check(
        "duplicate_material.toml",
        &format!("{CAMERA}[[materials]]\nname = \"a\"\n\n[[materials]]\nname = \"a\"\n"),
        8,
        &["materials[1].name", "duplicate material name \"a\"", "line 4"],
    );
    check(
        "albedo.toml",
        &format!("{CAMERA}[[materials]]\nname = \"a\"\nalbedo = [0.5, 1.5, 0]\n"),
        6,
        &["materials[0].albedo[1]", "between 0 and 1 (got 1.5)"],
    );
    check(
        "emission.toml",
        &format!("{CAMERA}[[materials]]\nname = \"a\"\nemission = [0, -1, 0]\n"),
        6,
        &["materials[0].emission[1]", "must not be negative"],
    );
    check(
        "material_name.toml",
        &format!("{CAMERA}[[materials]]\nalbedo = [0.5, 0.5, 0.5]\n"),
        4,
        &["materials[0].name", "missing"],
    );
}

/// A `[[materials]]` table named "m" after the camera; its body starts on line 6.
fn material(body: &str) -> String {
    format!("{CAMERA}[[materials]]\nname = \"m\"\n{body}")
}

#[test]
fn material_keys_must_fit_the_type() {
    check(
        "ior_on_diffuse.toml",
        &material("albedo = [0.5, 0.5, 0.5]\nior = 1.5\n"),
        7,
        &[
            ":7:7:",
            "materials[0].ior",
            "`ior` does not apply to a diffuse material (the default type)",
            "a diffuse material accepts name, type, albedo, emission",
            "type = \"dielectric\"",
        ],
    );
    check(
        "albedo_on_conductor.toml",
        &material("type = \"conductor\"\nalbedo = [1, 0.8, 0.3]\n"),
        7,
        &[
            "materials[0].albedo",
            "`albedo` does not apply to a conductor material",
            "a conductor material accepts name, type, roughness, color, eta, k, metal, emission",
        ],
    );
    check(
        "albedo_on_dielectric.toml",
        &material("type = \"dielectric\"\nior = 1.33\nalbedo = [1, 1, 1]\n"),
        8,
        &[
            "materials[0].albedo",
            "does not apply to a dielectric material",
            "accepts name, type, ior, roughness, emission",
        ],
    );
    check(
        "roughness_on_mirror.toml",
        &material("type = \"mirror\"\nroughness = 0.2\n"),
        7,
        &["materials[0].roughness", "does not apply to a mirror material", "accepts name, type, albedo, emission"],
    );
    check(
        "metal_on_dielectric.toml",
        &material("type = \"dielectric\"\nmetal = \"gold\"\n"),
        7,
        &["materials[0].metal", "does not apply to a dielectric material", "type = \"conductor\""],
    );
    // A key that belongs to no type is an unknown key.
    check(
        "material_typo.toml",
        &material("type = \"conductor\"\nrougness = 0.2\n"),
        7,
        &["materials[0].rougness", "unknown key `rougness`; did you mean `roughness`?", "a conductor material accepts"],
    );
    // Only the keys of the material's own type are listed.
    check(
        "diffuse_typo.toml",
        &material("albdo = [0.5, 0.5, 0.5]\n"),
        6,
        &["materials[0].albdo", "did you mean `albedo`?", "a diffuse material accepts name, type, albedo, emission"],
    );
    let e = parse_scene(&material("albdo = [0.5, 0.5, 0.5]\n"), "t.toml").unwrap_err().to_string();
    assert!(!e.contains("roughness"), "the keys of other types are listed: {e}");
}

#[test]
fn material_types() {
    check(
        "material_type.toml",
        &material("type = \"glass\"\n"),
        6,
        &[
            ":6:8:",
            "materials[0].type",
            "unknown variant `glass`",
            "expected one of `diffuse`, `conductor`, `dielectric`, `mirror`",
        ],
    );
    check(
        "metal_name.toml",
        &material("type = \"conductor\"\nmetal = \"iron\"\n"),
        7,
        &["materials[0].metal", "unknown variant `iron`", "`gold`, `silver`, `copper`, `aluminium`"],
    );
}

#[test]
fn conductor_fresnel_forms() {
    let m = check(
        "two_fresnel_forms.toml",
        &material("type = \"conductor\"\ncolor = [0.9, 0.6, 0.5]\nmetal = \"copper\"\n"),
        8,
        &["materials[0].metal", "one Fresnel form", "found `color` and `metal`"],
    );
    assert!(m.contains(":8:9:"), "{m}");
    check(
        "metal_and_eta.toml",
        &material("type = \"conductor\"\nmetal = \"gold\"\neta = [0.2, 0.4, 1.4]\nk = [3.6, 2.5, 1.9]\n"),
        8,
        &["materials[0].eta", "found `metal` and `eta`/`k`"],
    );
    check(
        "eta_without_k.toml",
        &material("type = \"conductor\"\nroughness = 0.1\neta = [0.2, 0.4, 1.4]\n"),
        8,
        &["materials[0].k", "the required key `k` is missing", "`eta` and `k` together"],
    );
    check(
        "k_without_eta.toml",
        &material("type = \"conductor\"\nk = [3.6, 2.5, 1.9]\n"),
        7,
        &["materials[0].eta", "the required key `eta` is missing"],
    );
    check(
        "eta_zero.toml",
        &material("type = \"conductor\"\neta = [0.2, 0, 1.4]\nk = [3.6, 2.5, 1.9]\n"),
        7,
        &["materials[0].eta[1]", "must be positive (got 0)"],
    );
    check(
        "k_negative.toml",
        &material("type = \"conductor\"\neta = [0.2, 0.4, 1.4]\nk = [3.6, -2.5, 1.9]\n"),
        8,
        &["materials[0].k[1]", "must not be negative (got -2.5)"],
    );
    check(
        "color_above_one.toml",
        &material("type = \"conductor\"\ncolor = [0.9, 1.2, 0.5]\n"),
        7,
        &["materials[0].color[1]", "must be between 0 and 1 (got 1.2)"],
    );
}

#[test]
fn material_ranges() {
    check(
        "negative_ior.toml",
        &material("type = \"dielectric\"\nior = -1.5\n"),
        7,
        &[":7:7:", "materials[0].ior", "must be positive (got -1.5)"],
    );
    check(
        "zero_ior.toml",
        &material("type = \"dielectric\"\nior = 0\n"),
        7,
        &["materials[0].ior", "must be positive (got 0)"],
    );
    check(
        "rough_conductor.toml",
        &material("type = \"conductor\"\nroughness = 1.5\n"),
        7,
        &[":7:13:", "materials[0].roughness", "must be between 0 and 1 (got 1.5)"],
    );
    check(
        "rough_dielectric.toml",
        &material("type = \"dielectric\"\nroughness = -0.1\n"),
        7,
        &["materials[0].roughness", "must be between 0 and 1 (got -0.1)"],
    );
    check(
        "mirror_albedo.toml",
        &material("type = \"mirror\"\nalbedo = [1, 1, 1.01]\n"),
        7,
        &["materials[0].albedo[2]", "must be between 0 and 1 (got 1.01)"],
    );
}

#[test]
fn shape_keys() {
    check(
        "no_shape.toml",
        &format!("{CAMERA}\n[[objects]]\nname = \"nothing\"\n"),
        5,
        &["objects[0]", "exactly one shape key", "found none"],
    );
    check(
        "two_shapes.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nplane = {{}}\n"),
        6,
        &["objects[0].plane", "exactly one shape key", "sphere, plane"],
    );
    check(
        "bad_half_angle.toml",
        &format!("{CAMERA}[[objects]]\ncone = {{ half_angle = 90 }}\n"),
        5,
        &["objects[0].cone.half_angle", "between 0 and 90"],
    );
    check(
        "zero_curvature.toml",
        &format!("{CAMERA}[[objects]]\nparaboloid = {{ curvature = 0 }}\n"),
        5,
        &["objects[0].paraboloid.curvature", "must not be zero"],
    );
    check(
        "sheets.toml",
        &format!("{CAMERA}[[objects]]\nhyperboloid = {{ radius = 1, slope = 1, sheets = 3 }}\n"),
        5,
        &["objects[0].hyperboloid.sheets", "(got 3)"],
    );
    check(
        "sphere_number.toml",
        &format!("{CAMERA}[[objects]]\nsphere = 1\n"),
        5,
        &["objects[0].sphere", "expected a table such as { radius = 1 }"],
    );
    check(
        "perturbation_kind.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.perturbations]]\nf = 1\n"),
        6,
        &["objects[0].perturbations[0]", "exactly one of `bump` and `quadric`"],
    );
    check(
        "scatter_on_radii.toml",
        &format!("{CAMERA}[[objects]]\nplane = {{}}\nclip = {{ min = [-1, -1, -1], max = [1, 1, 1] }}\n[[objects.scatter]]\ncount = 3\nradius = 0.1\nf = 1\n"),
        7,
        &["objects[0].scatter[0].on_radii", "missing"],
    );
    check(
        "scatter_count.toml",
        &format!(
            "{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[[objects.scatter]]\ncount = 0\nradius = 0.1\nf = 1\n"
        ),
        7,
        &["objects[0].scatter[0].count", "(got 0)"],
    );
}

#[test]
fn camera() {
    check(
        "look_at.toml",
        "[camera]\nposition = [1, 2, 3]\nlook_at = [1, 2, 3]\n",
        3,
        &["camera.look_at", "must differ from camera.position"],
    );
    check(
        "up_parallel.toml",
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 0, 2]\n",
        4,
        &["camera.up", "parallel to the view direction"],
    );
    // Looking straight down with the default up.
    check(
        "up_default.toml",
        "\n[camera]\nposition = [0, 5, 0]\nlook_at = [0, 0, 0]\n",
        2,
        &["camera.up", "parallel", "default up"],
    );
    check(
        "up_zero.toml",
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 0, 0]\n",
        4,
        &["camera.up", "must not be zero"],
    );
    for fov in ["0", "180", "-10", "200"] {
        check(
            &format!("fov_{}.toml", fov.trim_start_matches('-')),
            &format!("{CAMERA}fov = {fov}\n"),
            4,
            &["camera.fov", "between 0 and 180", &format!("(got {fov})")],
        );
    }
    check("no_camera.toml", "[image]\nwidth = 10\n", 1, &["camera", "missing"]);
    check("no_look_at.toml", "[camera]\nposition = [0, 0, 5]\n", 1, &["camera.look_at", "missing"]);
    check(
        "short_vector.toml",
        "[camera]\nposition = [0, 5]\nlook_at = [0, 0, 0]\n",
        2,
        &["camera.position", "must be an array of 3 numbers (got 2)"],
    );
}

#[test]
fn lights() {
    check(
        "light_type.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"spot\"\nposition = [0, 0, 0]\n"),
        5,
        &["lights[0].type", "unknown variant `spot`", "`point`, `sphere`, `rect`, `directional`"],
    );
    check(
        "light_intensity.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\n"),
        4,
        &["lights[0].intensity", "missing"],
    );
    check(
        "light_radiance.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"sphere\"\nposition = [0, 0, 0]\nradius = 1\n"),
        4,
        &["lights[0].radiance", "missing"],
    );
    check(
        "light_extra.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, 1, 1]\nradius = 1\n"),
        8,
        &["lights[0].radius", "does not apply to a point light"],
    );
    check(
        "light_position_on_rect.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"rect\"\nposition = [0, 0, 0]\n"),
        6,
        &["lights[0].position", "does not apply to a rect light", "accepts type, corner, edge_u, edge_v, radiance"],
    );
    check(
        "light_rect_missing.toml",
        &format!(
            "{CAMERA}\n[[lights]]\ntype = \"rect\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nradiance = [1, 1, 1]\n"
        ),
        5,
        &["lights[0].edge_v", "the required key `edge_v` of a rect light is missing"],
    );
    check(
        "light_directional_extra.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nirradiance = [1, 1, 1]\nradiance = [1, 1, 1]\n"),
        8,
        &["lights[0].radiance", "does not apply to a directional light", "accepts type, direction, irradiance"],
    );
    check(
        "light_negative.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, -1, 1]\n"),
        7,
        &["lights[0].intensity[1]", "must not be negative"],
    );
}

/// A rect light with the given edges; `edge_u` is on line 7, `edge_v` on line 8.
fn rect(edge_u: &str, edge_v: &str) -> String {
    format!(
        "{CAMERA}[[lights]]\ntype = \"rect\"\ncorner = [0, 2, 0]\nedge_u = {edge_u}\nedge_v = {edge_v}\nradiance = [1, 1, 1]\n"
    )
}

#[test]
fn degenerate_rect_lights() {
    check(
        "rect_parallel.toml",
        &rect("[1, 0, 0]", "[-3, 0, 0]"),
        8,
        &[":8:10:", "lights[0].edge_v", "edge_u and edge_v are parallel", "no area"],
    );
    check("rect_zero_u.toml", &rect("[0, 0, 0]", "[0, 0, 1]"), 7, &[":7:10:", "lights[0].edge_u", "must not be zero"]);
    check("rect_zero_v.toml", &rect("[1, 0, 0]", "[0, 0, 0]"), 8, &["lights[0].edge_v", "must not be zero"]);
    check("rect_nan.toml", &rect("[1, 0, 0]", "[0, 0, nan]"), 8, &["lights[0].edge_v[2]", "must be a finite number"]);
    check(
        "rect_radiance.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"rect\"\ncorner = [0, 2, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 0, 1]\nradiance = [1, -1, 1]\n"),
        9,
        &["lights[0].radiance[1]", "must not be negative"],
    );
    // Perpendicular and slanted edges are fine.
    load("rect_ok.toml", &rect("[1, 0, 0]", "[0.5, 0, 1]")).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn directional_lights() {
    let text = |direction: &str| {
        format!("{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = {direction}\nirradiance = [3, 3, 3]\n")
    };
    check("sun_zero.toml", &text("[0, 0, 0]"), 6, &[":6:13:", "lights[0].direction", "must not be zero", "normalised"]);
    check(
        "sun_missing_irradiance.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\n"),
        4,
        &["lights[0].irradiance", "the required key `irradiance` of a directional light is missing"],
    );
    check(
        "sun_negative.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nirradiance = [-3, 3, 3]\n"),
        7,
        &["lights[0].irradiance[0]", "must not be negative"],
    );
    let s = load("sun.toml", &text("[0, 10, 0]")).unwrap();
    assert_eq!(s.lights, [Light::Directional { direction: glam::DVec3::Y, irradiance: glam::Vec3::splat(3.0) }]);
}

#[test]
fn toml_syntax_errors() {
    check(
        "syntax.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 \n"),
        5,
        &["invalid TOML", "inline table"],
    );
    check("syntax_key.toml", &format!("{CAMERA}[image\nwidth = 3\n"), 4, &["invalid TOML"]);
    check("duplicate_key.toml", &format!("{CAMERA}fov = 30\nfov = 40\n"), 5, &["invalid TOML", "duplicate key"]);
    check("wrong_type.toml", &format!("{CAMERA}fov = \"wide\"\n"), 4, &["camera.fov", "invalid type"]);
}

#[test]
fn missing_file_names_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("does_not_exist.toml");
    let e = load_scene(&path).unwrap_err();
    assert!(matches!(e, SceneError::Read { .. }));
    let m = e.to_string();
    assert!(m.contains(&path.display().to_string()), "{m}");
    assert!(m.contains("cannot read"), "{m}");
}

#[test]
fn error_fields_are_structured() {
    let e = parse_scene(&format!("{CAMERA}[image]\nspp = 0\n"), "x.toml").unwrap_err();
    match e {
        SceneError::Invalid { file, line, column, field, message, snippet } => {
            assert_eq!((file.as_str(), line, column, field.as_str()), ("x.toml", 5, 7, "image.spp"));
            assert!(message.contains("(got 0)"));
            assert_eq!(snippet, "\n5 | spp = 0\n  |       ^");
        }
        e => panic!("{e}"),
    }
}

#[test]
fn empty_scenes_are_allowed() {
    let s = load("empty.toml", CAMERA).unwrap();
    assert!(s.objects.is_empty() && s.lights.is_empty() && s.materials.is_empty());
}

#[test]
fn default_scene_parses() {
    let s = parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((s.image.width, s.image.height, s.image.spp), (640, 480, 16));
    assert!(s.objects.len() >= 4);
    let bumpy = s.objects.iter().find(|o| o.name == "bumpy sphere").unwrap();
    assert_eq!(bumpy.shape.perturbations.len(), 40);
}

#[test]
fn every_scene_file_loads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut n = 0;
    for dir in [root.clone(), root.join("tests")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
                n += 1;
            }
        }
    }
    assert!(n >= 2);
    let s = load_scene(&root.join("tests/one_sphere.toml")).unwrap();
    assert_eq!((s.image.width, s.image.height, s.image.spp), (64, 48, 1));
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.lights.len(), 1);
    let s = load_scene(&root.join("tests/materials.toml")).unwrap();
    assert_eq!(s.image.max_depth, 4);
    let kinds: Vec<_> = s.materials.iter().map(|m| std::mem::discriminant(&m.kind)).collect();
    for kind in [
        MaterialKind::Diffuse,
        MaterialKind::Mirror,
        MaterialKind::Dielectric { roughness: 0.0, ior: 1.5 },
        MaterialKind::Conductor { roughness: 0.3, fresnel: ConductorFresnel::Schlick { f0: glam::Vec3::ONE } },
    ] {
        assert!(kinds.contains(&std::mem::discriminant(&kind)), "{kind:?}");
    }
    assert!(matches!(s.lights[..], [Light::Rect { .. }, Light::Directional { .. }]), "{:?}", s.lights);
}

/// Every complete example (a ```toml block with a [camera]) in
/// scenes/README.md must load.
#[test]
fn readme_examples_load() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/README.md")).unwrap();
    let mut n = 0;
    for block in readme.split("```toml\n").skip(1) {
        let block = block.split("```").next().unwrap();
        if block.contains("[camera]") {
            parse_scene(block, "README.md").unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 1);
}

#[test]
fn single_brackets_for_an_array_of_tables() {
    check(
        "single_brackets.toml",
        &format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\n[objects.perturbations]\nf = 1\n"),
        6,
        &["objects[0].perturbations", "write [[objects.perturbations]]"],
    );
}

/// A valid material prefix for map tests: the map line is line 6.
fn map_scene(line: &str) -> String {
    format!("{CAMERA}[[materials]]\nname = \"m\"\n{line}\n")
}

#[test]
fn missing_texture_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let text = map_scene("albedo_map = \"textures/missing.png\"");
    std::fs::write(&scene, &text).unwrap();
    let m = load_scene(&scene).unwrap_err().to_string();
    let texture = dir.path().join("textures/missing.png");
    let expected = format!(
        "{}:6:14: materials[0].albedo_map: cannot load the albedo map: {}: no such file",
        scene.display(),
        texture.display()
    );
    assert_eq!(m.lines().next().unwrap(), expected, "{m}");
    assert!(m.contains("6 | albedo_map = \"textures/missing.png\"\n  |              ^^^^^^^^^^^^^^^^^^^^^^"), "{m}");

    // The table form points at its `file`.
    let text = map_scene("displacement_map = { file = \"h.exr\", scale = 0.1 }");
    let m = check("missing_table.toml", &text, 6, &["materials[0].displacement_map.file", "h.exr: no such file"]);
    assert!(m.contains(":6:29:"), "{m}");
}

#[test]
fn bad_texture_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("noise.png"), b"definitely not a PNG file").unwrap();
    std::fs::write(dir.path().join("picture.bmp"), b"BM").unwrap();
    image::GrayImage::from_pixel(2, 2, image::Luma([7])).save(dir.path().join("grey.png")).unwrap();
    let scene = dir.path().join("s.toml");
    for (line, needles) in [
        ("albedo_map = \"noise.png\"", &["materials[0].albedo_map", "noise.png: not a valid PNG image"][..]),
        ("albedo_map = \"picture.bmp\"", &["picture.bmp: unsupported texture format `.bmp`"][..]),
        (
            "normal_map = \"grey.png\"",
            &["materials[0].normal_map: cannot load the normal map", "grey.png: a normal map needs 3"][..],
        ),
    ] {
        std::fs::write(&scene, map_scene(line)).unwrap();
        let m = load_scene(&scene).unwrap_err().to_string();
        assert!(m.starts_with(&format!("{}:6:14: ", scene.display())), "{m}");
        for n in needles {
            assert!(m.contains(n), "expected `{n}` in\n{m}");
        }
    }
}

#[test]
fn texture_files_load_relative_to_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("maps")).unwrap();
    image::RgbImage::from_pixel(3, 3, image::Rgb([128, 128, 128])).save(dir.path().join("maps/a.png")).unwrap();
    let scene = dir.path().join("s.toml");
    let text = format!(
        "{}[[materials]]\nname = \"n\"\ntype = \"conductor\"\nroughness_map = \"maps/a.png\"\nnormal_map = \"maps/a.png\"\n\
         [[objects]]\nmaterial = \"m\"\nsphere = {{ radius = 1 }}\nuv = {{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 1, 0] }}\n",
        map_scene("albedo_map = { file = \"maps/a.png\" }")
    );
    std::fs::write(&scene, text).unwrap();
    let s = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    // The colour map and the (shared) data maps.
    assert_eq!(s.textures.len(), 2);
    assert_eq!(s.materials[0].maps.albedo, Some(0));
    assert_eq!((s.materials[1].maps.roughness, s.materials[1].maps.normal), (Some(1), Some(1)));
    assert_eq!((s.textures[0].width, s.textures[0].height), (4, 4));
    assert!((s.textures[0].levels[0][0][0] - 0.215_860_5).abs() < 1e-5);
    assert!((s.textures[1].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-5);
}

#[test]
fn map_keys_must_fit_the_material() {
    check(
        "roughness_on_diffuse.toml",
        &map_scene("roughness_map = \"r.png\""),
        6,
        &[
            "materials[0].roughness_map",
            "`roughness_map` does not apply to a diffuse material (the default type)",
            "belongs to type = \"conductor\" or type = \"dielectric\"",
        ],
    );
    check(
        "roughness_on_mirror.toml",
        &map_scene("type = \"mirror\"\nroughness_map = { checker = { size = 8, cells = 2, colors = [0.1, 0.5] } }"),
        7,
        &["materials[0].roughness_map", "does not apply to a mirror material"],
    );
    check(
        "albedo_on_dielectric.toml",
        &map_scene("type = \"dielectric\"\nalbedo_map = \"a.png\""),
        7,
        &[
            "materials[0].albedo_map",
            "does not apply to a dielectric material",
            "type = \"diffuse\" or type = \"mirror\"",
        ],
    );
    check(
        "bumps_albedo.toml",
        &map_scene("albedo_map = { bumps = { size = 8, count = 3 } }"),
        6,
        &["materials[0].albedo_map.bumps", "`bumps` does not apply to an albedo map; it takes `file` or `checker`"],
    );
}

#[test]
fn bad_map_values() {
    check(
        "negative_scale.toml",
        &map_scene("displacement_map = { bumps = { size = 64, count = 5 }, scale = -0.02 }"),
        6,
        &["materials[0].displacement_map.scale", "must be positive (got -0.02)", ":6:64:"],
    );
    check(
        "zero_scale.toml",
        &map_scene("displacement_map = { file = \"h.png\", scale = 0 }"),
        6,
        &["materials[0].displacement_map.scale", "must be positive (got 0)"],
    );
    check(
        "no_scale.toml",
        &map_scene("displacement_map = \"h.png\""),
        6,
        &["materials[0].displacement_map", "needs a height scale", "scale = 0.02"],
    );
    check(
        "npot_checker.toml",
        &map_scene("albedo_map = { checker = { size = 1000, cells = 10, colors = [0, 1] } }"),
        6,
        &["materials[0].albedo_map.checker.size", "must be a power of two from 1 to 16384", "(got 1000)"],
    );
    check(
        "typo_map.toml",
        &map_scene("normal_map = { bumps = { size = 64, count = 5, strenght = 2 } }"),
        6,
        &["materials[0].normal_map.bumps.strenght", "unknown field `strenght`"],
    );
    check(
        "bad_colour.toml",
        &map_scene("albedo_map = { checker = { size = 64, cells = 8, colors = [[1, 1, 1], [0, 0, -1]] } }"),
        6,
        &["materials[0].albedo_map.checker.colors[1][2]", "must be between 0 and 1 (got -1)"],
    );
}

/// An object's `uv` with a valid scene around it: the `uv` line is line 6.
fn uv_scene(uv: &str) -> String {
    format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nuv = {uv}\n")
}

#[test]
fn uv_errors() {
    check(
        "bad_mapping.toml",
        &uv_scene("{ mapping = \"cubic\" }"),
        6,
        &["objects[0].uv.mapping", "unknown variant `cubic`", "`planar`, `spherical`, `cylindrical`"],
    );
    check(
        "parallel_axes.toml",
        &uv_scene("{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [2, 0, 0] }"),
        6,
        &["objects[0].uv.v_axis", "u_axis and v_axis are parallel", ":6:57:"],
    );
    check(
        "missing_axis.toml",
        &uv_scene("{ mapping = \"planar\", v_axis = [0, 0, 1] }"),
        6,
        &["objects[0].uv.u_axis", "the required key `u_axis` of a planar mapping is missing"],
    );
    check(
        "zero_axis.toml",
        &uv_scene("{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 0, 0] }"),
        6,
        &["objects[0].uv.v_axis", "must not be zero"],
    );
    check(
        "axis_on_sphere.toml",
        &uv_scene("{ mapping = \"spherical\", u_axis = [1, 0, 0] }"),
        6,
        &["objects[0].uv.u_axis", "does not apply to the spherical mapping", "mapping = \"planar\""],
    );
    check("zero_uv_scale.toml", &uv_scene("{ scale = [0, 1] }"), 6, &["objects[0].uv.scale[0]", "must not be zero"]);
}

#[test]
fn textured_example_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/textured.toml");
    let s = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(!s.textures.is_empty());
    assert!(s.materials.iter().any(|m| m.maps.albedo.is_some()));
    assert!(s.materials.iter().any(|m| m.maps.normal.is_some()));
    assert!(s.objects.iter().any(|o| matches!(o.uv.mapping, quadray::model::scene::UvMapping::Planar { .. })));
    for t in &s.textures {
        assert!(t.width.is_power_of_two() && t.height.is_power_of_two(), "{}", t.source);
        assert_eq!(t.levels[0].len(), (t.width * t.height) as usize);
        assert_eq!(t.levels.last().unwrap().len(), 1);
    }
}

/// A scene with an `[environment]` table on line 4 and `line` on line 5.
fn environment_scene(line: &str) -> String {
    format!("{CAMERA}[environment]\n{line}\n")
}

#[test]
fn missing_environment_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, environment_scene("map = \"skies/missing.exr\"")).unwrap();
    let m = load_scene(&scene).unwrap_err().to_string();
    let texture = dir.path().join("skies/missing.exr");
    let expected = format!(
        "{}:5:7: environment.map: cannot load the environment map: {}: no such file",
        scene.display(),
        texture.display()
    );
    assert_eq!(m.lines().next().unwrap(), expected, "{m}");
    assert!(m.contains("5 | map = \"skies/missing.exr\"\n  |       ^^^^^^^^^^^^^^^^^^^"), "{m}");

    // The table form points at its `file`.
    let m = check(
        "missing_env_table.toml",
        &environment_scene("map = { file = \"sky.png\" }\nscale = 2"),
        5,
        &["environment.map.file: cannot load the environment map:", "sky.png: no such file"],
    );
    assert!(m.contains(":5:16:"), "{m}");

    // Not an image.
    std::fs::write(dir.path().join("sky.exr"), b"not an EXR file").unwrap();
    std::fs::write(&scene, environment_scene("map = \"sky.exr\"")).unwrap();
    let m = load_scene(&scene).unwrap_err().to_string();
    assert!(m.starts_with(&format!("{}:5:7: environment.map: cannot load the environment map: ", scene.display())));
    assert!(m.contains("sky.exr: not a valid EXR image"), "{m}");
}

#[test]
fn environment_files_load_relative_to_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("skies")).unwrap();
    image::RgbImage::from_pixel(6, 3, image::Rgb([255, 128, 0])).save(dir.path().join("skies/sky.png")).unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, environment_scene("map = \"skies/sky.png\"\nscale = 3")).unwrap();
    let s = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let env = s.environment.unwrap();
    assert_eq!((env.texture, env.scale), (0, 3.0));
    let t = &s.textures[0];
    // Resampled to powers of two; sRGB-decoded like a colour map.
    assert_eq!((t.width, t.height), (8, 4));
    let texel = t.levels[0][0];
    assert!((texel[0] - 1.0).abs() < 1e-5 && (texel[1] - 0.215_860_5).abs() < 1e-5 && texel[2] == 0.0, "{texel:?}");
}

#[test]
fn bad_environment_values() {
    check(
        "sky_width.toml",
        &environment_scene("map = { sky = { width = 500, height = 250 } }"),
        5,
        &["environment.map.sky.width", "must be a power of two from 2 to 4096", "(got 500)", ":5:25:"],
    );
    check(
        "sky_height.toml",
        &environment_scene("map = { sky = { width = 512, height = 4096 } }"),
        5,
        &["environment.map.sky.height", "must be a power of two from 1 to 2048", "(got 4096)"],
    );
    check(
        "sky_too_wide.toml",
        &environment_scene("map = { sky = { width = 8192, height = 1024 } }"),
        5,
        &["environment.map.sky.width", "(got 8192)"],
    );
    check(
        "sky_no_height.toml",
        &environment_scene("map = { sky = { width = 512 } }"),
        5,
        &["environment.map.sky.height", "the required key `height` is missing"],
    );
    check(
        "negative_env_scale.toml",
        &environment_scene("map = { sky = { width = 8, height = 4 } }\nscale = -0.5"),
        6,
        &["environment.scale", "must not be negative (got -0.5)", ":6:9:"],
    );
    check(
        "nan_env_scale.toml",
        &environment_scene("map = { sky = { width = 8, height = 4 } }\nscale = nan"),
        6,
        &["environment.scale", "must be a finite number"],
    );
    check("no_env_map.toml", &environment_scene("scale = 1"), 4, &["environment.map", "the required key `map`"]);
    check(
        "env_file_and_sky.toml",
        &environment_scene("map = { sky = { width = 8, height = 4 }, file = \"a.exr\" }"),
        5,
        &["environment.map.file", "needs exactly one of `file` and `sky`; found both"],
    );
    check(
        "env_neither.toml",
        &environment_scene("map = {}"),
        5,
        &["environment.map", "needs exactly one of `file` and `sky`; found neither"],
    );
    check("env_empty_path.toml", &environment_scene("map = \"\""), 5, &["environment.map", "must not be empty"]);
}

#[test]
fn unknown_environment_keys() {
    check(
        "env_typo.toml",
        &environment_scene("map = { sky = { width = 8, height = 4 } }\nscael = 2"),
        6,
        &["environment.scael", "unknown field `scael`", "expected `map` or `scale`"],
    );
    check(
        "env_map_typo.toml",
        &environment_scene("map = { skye = { width = 8, height = 4 } }"),
        5,
        &["environment.map.skye", "unknown field `skye`", "expected `file` or `sky`"],
    );
    check(
        "sky_typo.toml",
        &environment_scene("map = { sky = { width = 8, heigth = 4 } }"),
        5,
        &["environment.map.sky.heigth", "unknown field `heigth`"],
    );
    // A checker is a material map, not an environment.
    check(
        "env_checker.toml",
        &environment_scene("map = { checker = { size = 8, cells = 2, colors = [0, 1] } }"),
        5,
        &["environment.map.checker", "unknown field `checker`"],
    );
}

#[test]
fn background_and_environment_together() {
    let sky = "map = { sky = { width = 8, height = 4 } }";
    // The [environment] table comes second: the error points at its header.
    let m = check(
        "both.toml",
        &format!("background = [0.1, 0.1, 0.1]\n{CAMERA}[environment]\n{sky}\n"),
        5,
        &["environment: give either background or [environment], not both", "(background is at line 1)"],
    );
    assert!(m.contains("both.toml:5:1:") && m.contains("\n5 | [environment]\n  | ^"), "{m}");
    // Inline before the background: the error points at the background.
    let m = check(
        "both_inline.toml",
        &format!("environment = {{ {sky} }}\nbackground = [0, 0, 0]\n{CAMERA}"),
        2,
        &["background: give either background or [environment], not both", "([environment] is at line 1)"],
    );
    assert!(m.contains("both_inline.toml:2:14:"), "{m}");
}

#[test]
fn sky_example_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sky.toml");
    let s = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((s.image.width, s.image.height, s.image.spp, s.image.max_depth), (640, 480, 32, 6));
    // Lit only by the sky.
    assert!(s.lights.is_empty());
    assert!(s.materials.iter().all(|m| m.emission == glam::Vec3::ZERO));
    assert_eq!(s.background, glam::Vec3::ZERO);
    let env = s.environment.expect("an environment map");
    assert_eq!(env.scale, 1.0);
    let sky = &s.textures[env.texture];
    assert_eq!(*sky, quadray::model::sampling::envmap::procedural_sky(512, 256));
    // A glossy metal sphere and a diffuse floor.
    let material = |name: &str| &s.materials[s.objects.iter().find(|o| o.name == name).unwrap().material];
    let MaterialKind::Conductor { roughness, .. } = material("metal sphere").kind else { panic!("not a metal") };
    assert!(roughness > 0.0 && roughness < 0.2, "glossy: {roughness}");
    assert_eq!(material("floor").kind, MaterialKind::Diffuse);
}
