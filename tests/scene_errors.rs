//! Bad scene files must give messages that name the file, the line, the
//! field and the reason. Each input is written to a temporary file and loaded
//! with `load_scene`, as the binary does.

use std::path::Path;

use quadray::scene::{load_scene, parse_scene, Scene, SceneError, DEFAULT_SCENE, DEFAULT_SCENE_NAME};

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
        &["lights[0].type", "unknown variant `spot`"],
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
        "light_negative.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = [1, -1, 1]\n"),
        7,
        &["lights[0].intensity[1]", "must not be negative"],
    );
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
