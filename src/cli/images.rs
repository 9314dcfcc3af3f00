//! `quadray merge`, `quadray compare` and `quadray denoise`: commands on
//! rendered images.

use std::path::{Path, PathBuf};

use super::common::*;
use anyhow::{bail, Context as _, Result};
use clap::Parser;
use quadray::jobs::output::write_outputs_with;

#[derive(Parser, Debug)]
pub(crate) struct MergeArgs {
    /// The tiles' EXR files.
    #[arg(required = true)]
    pub(crate) tiles: Vec<PathBuf>,
    /// Output path, as `render -o`: `NAME.png`, `NAME.exr`, or a name
    /// without those extensions for both.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Write the EXR with 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    pub(crate) half: bool,
}

/// `quadray merge`: tiles into the whole frame.
pub(crate) fn merge(args: MergeArgs) -> Result<()> {
    let outputs = checked_outputs(&args.output)?;
    let tiles = args
        .tiles
        .iter()
        .map(|p| Ok((p.clone(), quadray::jobs::output::read_render_exr(p)?)))
        .collect::<Result<Vec<_>>>()?;
    let (out, metadata) = quadray::jobs::merge::merge(&tiles)?;
    if tiles.iter().any(|(_, t)| t.output.denoised.is_some()) {
        eprintln!(
            "the tiles' denoised images are left out (each was denoised alone): the merged frame is their raw \
             radiance; `quadray denoise` denoises it whole"
        );
    }
    let exposure = metadata
        .iter()
        .find(|(k, _)| k == quadray::jobs::output::METADATA_EXPOSURE)
        .and_then(|(_, v)| v.parse().ok())
        .unwrap_or(0.0);
    let files = output_files(&outputs, exposure, args.half);
    write_outputs_with(&out, &files, &metadata)?;
    let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
    eprintln!("merged {} tiles into {} ({}x{}, {} spp)", tiles.len(), names.join(", "), out.width, out.height, out.spp);
    Ok(())
}

#[derive(Parser, Debug)]
pub(crate) struct DenoiseArgs {
    /// A render's EXR (`quadray render`): its radiance (`noisy.RGB` where it
    /// was denoised before, else RGB) and, where present, the denoiser's
    /// albedo and normal channels.
    pub(crate) input: PathBuf,
    /// Output path, as `render -o`: `NAME.png`, `NAME.exr`, or a name
    /// without those extensions for both. The EXR keeps every channel of
    /// the input, with RGB denoised and the raw radiance as `noisy.RGB`.
    /// Default: the input's name with `-denoised` (`a.exr`: `a-denoised.png`
    /// and `a-denoised.exr`).
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// The denoiser's quality: `fast`, `balanced` or `high`.
    #[arg(long, default_value_t = quadray::jobs::denoise::DenoiseQuality::High)]
    pub(crate) quality: quadray::jobs::denoise::DenoiseQuality,
    /// Write the EXR with 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    pub(crate) half: bool,
}

/// Fails unless `path` is an OpenEXR file (its magic number), naming what
/// it is instead of the EXR reader's "file identifier missing".
fn require_exr(path: &Path) -> Result<()> {
    let mut magic = [0u8; 4];
    let read = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .with_context(|| format!("cannot read {}", path.display()));
    read?;
    if magic != [0x76, 0x2f, 0x31, 0x01] {
        let what = match magic {
            [0x89, b'P', b'N', b'G'] => "a PNG image",
            [0xff, 0xd8, 0xff, _] => "a JPEG image",
            _ => "not an OpenEXR file",
        };
        bail!(
            "{} is {what}: `quadray denoise` reads a render's EXR (written by `quadray render`, with its albedo \
             and normal channels)",
            path.display()
        );
    }
    Ok(())
}

/// `quadray denoise`: an existing render denoised.
pub(crate) fn denoise(args: DenoiseArgs) -> Result<()> {
    let out_name = args.output.clone().unwrap_or_else(|| {
        let mut name = args.input.with_extension("").into_os_string();
        name.push("-denoised");
        PathBuf::from(name)
    });
    let outputs = checked_outputs(&out_name)?;
    require_exr(&args.input)?;
    let mut denoiser = quadray::jobs::denoise::Denoiser::load()?;
    let quadray::jobs::output::ExrFile { mut output, mut metadata } =
        quadray::jobs::output::read_render_exr(&args.input)
            .with_context(|| format!("cannot read {} as a render", args.input.display()))?;
    if output.aov.is_empty() || output.aov.iter().all(|a| a.denoise_albedo == [0.0; 3]) {
        eprintln!(
            "{} has no denoiser features (denoise_albedo, denoise_normal): denoising the colour alone",
            args.input.display()
        );
        output.aov.clear();
    }
    let (done, seconds) = super::render::denoise_into(&mut denoiser, &mut output, args.quality)?;
    let exposure = metadata
        .iter()
        .find(|(k, _)| k == quadray::jobs::output::METADATA_EXPOSURE)
        .and_then(|(_, v)| v.parse().ok())
        .unwrap_or(0.0);
    metadata.retain(|(k, _)| k != quadray::jobs::output::METADATA_DENOISED);
    metadata.push((quadray::jobs::output::METADATA_DENOISED.to_string(), done.clone()));
    let files = output_files(&outputs, exposure, args.half);
    write_outputs_with(&output, &files, &metadata)?;
    let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
    eprintln!("denoised: {done}; {seconds:.2} s");
    eprintln!("wrote {}", names.join(", "));
    Ok(())
}

#[derive(Parser, Debug)]
pub(crate) struct CompareArgs {
    /// The reference image (EXR).
    pub(crate) reference: PathBuf,
    /// The image to compare with it (EXR).
    pub(crate) test: PathBuf,
    /// Exposure in stops applied to both before FLIP's tone mapping.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub(crate) exposure: f32,
}

pub(crate) fn compare(args: CompareArgs) -> Result<()> {
    let read = |path: &Path| -> Result<quadray::passes::RenderOutput> {
        let (width, height, texels) =
            quadray::model::texture::read_exr_image(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(quadray::passes::RenderOutput::from_radiance(
            width,
            height,
            texels.iter().map(|t| [t[0], t[1], t[2]]).collect(),
        ))
    };
    let reference = read(&args.reference)?;
    let test = read(&args.test)?;
    if (reference.width, reference.height) != (test.width, test.height) {
        bail!(
            "{} is {}x{} but {} is {}x{}",
            args.reference.display(),
            reference.width,
            reference.height,
            args.test.display(),
            test.width,
            test.height
        );
    }
    let flip = quadray::tools::metrics::flip_mean(&reference, &test, args.exposure)?;
    let rel_mse = quadray::tools::metrics::relative_mse(&reference, &test)?;
    let lum = |p: &[f32; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (worst, _) =
        reference.radiance.iter().zip(&test.radiance).enumerate().fold((0, -1.0f32), |best, (i, (r, t))| {
            let d = (lum(r) - lum(t)).abs();
            if d > best.1 {
                (i, d)
            } else {
                best
            }
        });
    println!("FLIP {flip:.4}  relative MSE {rel_mse:.5}");
    println!(
        "largest luminance difference at pixel ({}, {}): reference {:.4}, test {:.4}",
        worst as u32 % reference.width,
        worst as u32 / reference.width,
        lum(&reference.radiance[worst]),
        lum(&test.radiance[worst])
    );
    // Bit for bit: a refactor that must not change an image is checked here.
    let differing = reference
        .radiance
        .iter()
        .flatten()
        .zip(test.radiance.iter().flatten())
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    match differing {
        0 => println!("identical: every radiance value is the same to the bit"),
        n => println!("{n} of {} radiance values differ in their bits", 3 * reference.radiance.len()),
    }
    Ok(())
}
