//! `quadray export`: meshes, maps and the resolved scene for other renderers.

use std::path::Path;
use std::process::Command;

/// A moved, scaled sphere with a checker map.
const SCENE: &str = include_str!("export_ball.toml");

fn quadray(args: &[&str], cwd: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_quadray")).args(args).current_dir(cwd).output().unwrap()
}

/// The vertices of a binary PLY of `quadray export`: x y z nx ny nz u v.
fn ply_vertices(path: &Path) -> (Vec<[f32; 8]>, usize) {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = String::from_utf8_lossy(&bytes[..end]).into_owned();
    let count = |element: &str| -> usize {
        let line = header.lines().find(|l| l.starts_with(&format!("element {element} "))).unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (vertices, faces) = (count("vertex"), count("face"));
    assert_eq!(bytes.len() - end, vertices * 32 + faces * 13, "the body's size");
    let floats: Vec<[f32; 8]> = bytes[end..end + vertices * 32]
        .chunks(32)
        .map(|v| std::array::from_fn(|i| f32::from_le_bytes(v[4 * i..4 * i + 4].try_into().unwrap())))
        .collect();
    (floats, faces)
}

#[test]
fn an_exported_sphere_is_on_its_surface_in_world_space_with_its_map() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ball.toml"), SCENE).unwrap();
    let out = quadray(&["export", "ball.toml", "-o", "out", "--cells", "32"], dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("object-0.ply: ball (checks):"), "{stderr}");
    let folder = dir.path().join("out");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("scene.json")).unwrap()).unwrap();
    let object = &json["objects"][0];
    assert_eq!(object["mesh"], "object-0.ply");
    assert!(object.get("shape").is_none(), "the mesh replaces the shape");
    assert_eq!(json["textures"][0]["file"], "texture-0.exr");
    assert_eq!(json["materials"][0]["maps"]["albedo"], 0);
    let (w, h, texels) = quadray::model::texture::read_exr_image(&folder.join("texture-0.exr")).unwrap();
    assert_eq!((w, h), (64, 64));
    assert!((texels[0][0] - 0.9).abs() < 1e-6 && (texels[0][2] - 0.1).abs() < 1e-6, "{:?}", texels[0]);

    // World space: radius 2 around (0, 1, 0), outward normals, u in the
    // mapping's range (a period of 4, shifted by one along the seam).
    let (vertices, faces) = ply_vertices(&folder.join("object-0.ply"));
    assert!(faces > 1000, "{faces} triangles");
    for v in &vertices {
        let p = glam::Vec3::new(v[0], v[1] - 1.0, v[2]);
        let n = glam::Vec3::new(v[3], v[4], v[5]);
        assert!((p.length() - 2.0).abs() < 1e-5, "{p}");
        assert!((n.length() - 1.0).abs() < 1e-5 && n.dot(p.normalize()) > 0.9999, "{n} at {p}");
        assert!((0.0..=8.0).contains(&v[6]) && (0.0..=2.0).contains(&v[7]), "uv {} {}", v[6], v[7]);
    }
}

#[test]
fn export_refuses_a_file_as_its_folder_and_too_few_cells() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ball.toml"), SCENE).unwrap();
    std::fs::write(dir.path().join("taken"), "").unwrap();
    let out = quadray(&["export", "ball.toml", "-o", "taken"], dir.path());
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("taken is a file: the output is a folder"));
    let out = quadray(&["export", "ball.toml", "-o", "out", "--cells", "3"], dir.path());
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--cells"), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!dir.path().join("out").exists(), "nothing written");
}
