//! `quadray export`: a scene for other renderers: every object as a
//! triangle mesh (PLY, world space, with normals and texture coordinates),
//! every texture map as an EXR, and the resolved scene as JSON.

use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use clap::Parser;
use quadray::model::geometry::mesh::tessellate;

use super::common::read_scene;

#[derive(Parser, Debug)]
pub(crate) struct ExportArgs {
    /// Scene file (TOML, see scenes/README.md). Omit it for the built-in default scene.
    pub(crate) scene: Option<PathBuf>,
    /// Output folder (created; files in it with the same names are replaced).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Grid cells along each object's longest side: the mesh's resolution
    /// (its chordal error falls as the square of the cell size; detail
    /// narrower than a cell is lost).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(4..=2048))]
    pub(crate) cells: u32,
}

/// `quadray export`: writes `scene.json` (the resolved scene: camera,
/// materials, lights, fog, objects with their mesh file; texture maps as
/// `texture-N.exr`, level 0, linear values, row 0 at v = 0) and
/// `object-N.ply` per object.
pub(crate) fn export(args: ExportArgs) -> Result<()> {
    let mut scene = read_scene(args.scene.as_deref())?;
    if args.output.is_file() {
        bail!("{} is a file: the output is a folder", args.output.display());
    }
    std::fs::create_dir_all(&args.output).with_context(|| format!("cannot create {}", args.output.display()))?;
    // Texture maps go to EXR files (level 0); the JSON names them (taken out
    // first: their mip chains would make a JSON tree of gigabytes).
    let maps = std::mem::take(&mut scene.textures);
    let mut json = serde_json::to_value(&scene).context("cannot serialise the scene")?;
    let mut textures = Vec::new();
    for (i, t) in maps.iter().enumerate() {
        let file = format!("texture-{i}.exr");
        let texels = &t.levels[0];
        let width = t.width as usize;
        exr::prelude::write_rgba_file(args.output.join(&file), width, t.height as usize, |x, y| {
            let [r, g, b, a] = texels[y * width + x];
            (r, g, b, a)
        })
        .with_context(|| format!("cannot write {}", args.output.join(&file).display()))?;
        textures.push(serde_json::json!({ "source": t.source, "width": t.width, "height": t.height, "file": file }));
    }
    json["textures"] = serde_json::Value::Array(textures);
    for (i, object) in scene.objects.iter().enumerate() {
        let started = std::time::Instant::now();
        let (mesh, report) = tessellate(&object.shape, &object.uv, args.cells as usize)
            .with_context(|| format!("object {} ({})", i, object.name))?;
        let world = mesh.transformed(&object.transform);
        let file = format!("object-{i}.ply");
        std::fs::write(args.output.join(&file), world.to_ply())
            .with_context(|| format!("cannot write {}", args.output.join(&file).display()))?;
        eprintln!(
            "{file}: {} ({}): {} triangles, grid {}x{}x{} of {:.3e}, vertices within {:.1e} of the surface{} ({:.1} s)",
            object.name,
            scene.materials[object.material].name,
            world.triangles.len(),
            report.grid[0],
            report.grid[1],
            report.grid[2],
            report.spacing,
            report.max_distance,
            if report.unconverged > 0 {
                format!(", {} left at their cell's mean crossing", report.unconverged)
            } else {
                String::new()
            },
            started.elapsed().as_secs_f64()
        );
        let entry = &mut json["objects"][i];
        entry["mesh"] = serde_json::json!(file);
        entry["mesh_triangles"] = serde_json::json!(world.triangles.len());
        entry["mesh_spacing"] = serde_json::json!(report.spacing);
        entry["mesh_max_distance"] = serde_json::json!(report.max_distance);
        let (lo, hi) =
            world.positions.iter().fold((glam::DVec3::MAX, glam::DVec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        entry["mesh_bounds"] = serde_json::json!([lo.to_array(), hi.to_array()]);
        // The shape and transform are in the mesh.
        entry.as_object_mut().map(|o| o.remove("shape"));
    }
    let path = args.output.join("scene.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json)?)
        .with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
