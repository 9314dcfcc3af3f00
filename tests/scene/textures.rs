//! Texture loading: small PNG, JPEG and EXR files are written to a temporary
//! folder and loaded back; procedural maps, resampling and mip chains.

use std::path::{Path, PathBuf};

use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, SmallVec, WritableImage};
use quadray::model::texture::{
    build_mips, bump_heights, checker, from_texels, load_texture, load_texture_file, normals_from_heights,
    resample_to_power_of_two, srgb_to_linear, TextureError, TextureKind, TextureUsage, MAX_TEXTURE_SIZE,
};

/// The sRGB-decoded value of 128/255.
const SRGB_128: f32 = 0.215_860_5;

fn near(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance
}

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
}

/// Writes a single-channel EXR file named `channel`.
fn write_exr_channel(path: &Path, channel: &str, width: usize, height: usize, value: impl Fn(usize, usize) -> f32) {
    let values = (0..width * height).map(|k| value(k % width, k / width)).collect();
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(channel, FlatSamples::F32(values))]));
    exr::prelude::Image::from_channels((width, height), channels).write().to_file(path).unwrap();
}

#[test]
fn png_colour_maps_are_srgb_decoded_and_data_maps_are_not() {
    let dir = Dir::new();
    let path = dir.path("c.png");
    image::RgbImage::from_fn(4, 4, |x, _| if x < 2 { image::Rgb([128, 0, 255]) } else { image::Rgb([64, 188, 10]) })
        .save(&path)
        .unwrap();
    let colour = load_texture(&path, TextureKind::Albedo).unwrap();
    assert_eq!((colour.width, colour.height, colour.levels.len()), (4, 4, 3));
    let t = colour.levels[0][0];
    assert!(near(t[0], SRGB_128, 1e-6) && t[1] == 0.0 && near(t[2], 1.0, 1e-6) && t[3] == 1.0, "{t:?}");
    let t = colour.levels[0][2];
    for (c, v) in t[..3].iter().zip([64u8, 188, 10]) {
        assert!(near(*c, srgb_to_linear(f32::from(v) / 255.0), 1e-7), "{t:?}");
    }
    for kind in [TextureKind::Normal, TextureKind::Roughness, TextureKind::Displacement] {
        let data = load_texture(&path, kind).unwrap();
        let t = data.levels[0][0];
        assert!(near(t[0], 128.0 / 255.0, 1e-6) && t[1] == 0.0 && t[2] == 1.0 && t[3] == 1.0, "{kind:?}: {t:?}");
    }
    assert_eq!(colour.source, path.display().to_string());
}

#[test]
fn sixteen_bit_png() {
    let dir = Dir::new();
    let path = dir.path("g16.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_pixel(2, 2, image::Luma([32768u16])).save(&path).unwrap();
    let data = load_texture(&path, TextureKind::Displacement).unwrap();
    assert!(near(data.levels[0][0][0], 32768.0 / 65535.0, 1e-6));
    let colour = load_texture(&path, TextureKind::Albedo).unwrap();
    assert!(near(colour.levels[0][0][2], srgb_to_linear(32768.0 / 65535.0), 1e-6));
}

#[test]
fn grey_and_alpha_channels() {
    let dir = Dir::new();
    let grey = dir.path("grey.png");
    image::GrayImage::from_pixel(2, 2, image::Luma([128])).save(&grey).unwrap();
    let l = load_texture_file(&grey, TextureUsage::Color).unwrap();
    assert_eq!((l.channels, l.has_alpha), (1, false));
    let t = l.image.levels[0][0];
    assert!(t[..3].iter().all(|&c| near(c, SRGB_128, 1e-6)) && t[3] == 1.0, "replicated: {t:?}");

    let grey_alpha = dir.path("ga.png");
    image::GrayAlphaImage::from_pixel(2, 2, image::LumaA([255, 128])).save(&grey_alpha).unwrap();
    let l = load_texture_file(&grey_alpha, TextureUsage::Color).unwrap();
    assert_eq!((l.channels, l.has_alpha), (1, true));
    let t = l.image.levels[0][0];
    assert!(t[..3].iter().all(|&c| near(c, 1.0, 1e-6)), "{t:?}");
    assert!(near(t[3], 128.0 / 255.0, 1e-6), "alpha is linear: {t:?}");

    let rgba = dir.path("rgba.png");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 0, 64])).save(&rgba).unwrap();
    let l = load_texture_file(&rgba, TextureUsage::Color).unwrap();
    assert_eq!((l.channels, l.has_alpha), (3, true));
    let t = l.image.levels[0][0];
    assert!(near(t[0], SRGB_128, 1e-6) && near(t[1], SRGB_128, 1e-6) && t[2] == 0.0, "{t:?}");
    assert!(near(t[3], 64.0 / 255.0, 1e-6), "{t:?}");
    // Roughness and displacement maps take any channel count.
    load_texture(&grey, TextureKind::Roughness).unwrap();
    load_texture(&grey_alpha, TextureKind::Displacement).unwrap();
    load_texture(&rgba, TextureKind::Normal).unwrap();
}

#[test]
fn jpeg_files() {
    let dir = Dir::new();
    let path = dir.path("c.jpg");
    let img = image::RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 128]));
    let mut file = std::fs::File::create(&path).unwrap();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut file, 100).encode_image(&img).unwrap();
    drop(file);
    let l = load_texture_file(&path, TextureUsage::Color).unwrap();
    assert_eq!((l.channels, l.image.width, l.image.height), (3, 8, 8));
    // JPEG is lossy: within a couple of code values of 128.
    let t = l.image.levels[0][27];
    for c in &t[..3] {
        assert!(near(*c, SRGB_128, 0.01), "{t:?}");
    }
    let data = load_texture(&path, TextureKind::Normal).unwrap();
    assert!(near(data.levels[0][27][0], 128.0 / 255.0, 2.5 / 255.0));

    // A grey JPEG has one channel, named .jpeg and in upper case.
    let grey = dir.path("g.JPEG");
    let mut file = std::fs::File::create(&grey).unwrap();
    let img = image::GrayImage::from_pixel(8, 8, image::Luma([200]));
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut file, 100).encode_image(&img).unwrap();
    drop(file);
    let l = load_texture_file(&grey, TextureUsage::Data).unwrap();
    assert_eq!(l.channels, 1);
    let e = load_texture(&grey, TextureKind::Normal).unwrap_err();
    assert!(matches!(e, TextureError::Channels { channels: 1, needed: 3, .. }), "{e}");
}

#[test]
fn exr_files_are_linear() {
    let dir = Dir::new();
    let path = dir.path("hdr.exr");
    exr::prelude::write_rgba_file(&path, 4, 2, |x, y| (0.5f32, 2.5f32, x as f32 * 0.25, 0.75 - y as f32 * 0.5))
        .unwrap();
    for kind in [TextureKind::Albedo, TextureKind::Normal, TextureKind::Roughness] {
        let t = load_texture(&path, kind).unwrap();
        assert_eq!((t.width, t.height), (4, 2));
        assert_eq!(t.levels[0][4 + 3], [0.5, 2.5, 0.75, 0.25], "{kind:?}: not decoded");
    }
    let rgb = dir.path("rgb.exr");
    exr::prelude::write_rgb_file(&rgb, 2, 2, |_, _| (0.1f32, 0.2f32, 0.3f32)).unwrap();
    let l = load_texture_file(&rgb, TextureUsage::Color).unwrap();
    assert_eq!((l.channels, l.has_alpha), (3, false));
    assert_eq!(l.image.levels[0][0], [0.1, 0.2, 0.3, 1.0]);

    // A single channel, Y or otherwise, is grey.
    for channel in ["Y", "R", "height"] {
        let grey = dir.path(&format!("{channel}.exr"));
        write_exr_channel(&grey, channel, 2, 2, |x, _| x as f32);
        let l = load_texture_file(&grey, TextureUsage::Color).unwrap();
        assert_eq!(l.channels, 1, "{channel}");
        assert_eq!(l.image.levels[0][1], [1.0, 1.0, 1.0, 1.0], "{channel}");
        let e = load_texture(&grey, TextureKind::Normal).unwrap_err().to_string();
        assert!(e.contains("a normal map needs 3 colour channels (RGB) but the image has 1"), "{e}");
    }
}

#[test]
fn npot_images_are_resampled_to_powers_of_two() {
    let dir = Dir::new();
    let path = dir.path("npot.png");
    image::RgbImage::from_pixel(3, 5, image::Rgb([100, 100, 100])).save(&path).unwrap();
    let t = load_texture(&path, TextureKind::Roughness).unwrap();
    assert_eq!((t.width, t.height), (4, 8));
    assert_eq!(t.levels.iter().map(Vec::len).collect::<Vec<_>>(), [32, 8, 2, 1]);
    // A constant image stays constant, on every level.
    for level in &t.levels {
        for texel in level {
            assert!(texel[..3].iter().all(|&c| near(c, 100.0 / 255.0, 1e-6)) && texel[3] == 1.0, "{texel:?}");
        }
    }

    // A smooth image keeps its mean.
    let (w, h) = (37u32, 23u32);
    let tau = std::f32::consts::TAU;
    let smooth: Vec<[f32; 4]> = (0..w * h)
        .map(|k| {
            let (x, y) = ((k % w) as f32 / w as f32, (k / w) as f32 / h as f32);
            let v = 0.5 + 0.3 * (tau * x).sin() * (tau * y).cos() + 0.1 * (2.0 * tau * y).sin();
            [v, 1.0 - v, 0.25, 1.0]
        })
        .collect();
    let mean = |t: &[[f32; 4]]| t.iter().map(|p| f64::from(p[0])).sum::<f64>() / t.len() as f64;
    let (w2, h2, resampled) = resample_to_power_of_two(w, h, smooth.clone());
    assert_eq!((w2, h2, resampled.len()), (64, 32, 64 * 32));
    assert!((mean(&resampled) - mean(&smooth)).abs() < 1e-3, "{} vs {}", mean(&resampled), mean(&smooth));
    assert!(resampled.iter().all(|p| near(p[0] + p[1], 1.0, 1e-5) && p[2] == 0.25));
    // Bilinear: values stay within the source's range.
    let (lo, hi) = smooth.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
    assert!(resampled.iter().all(|p| p[0] >= lo - 1e-6 && p[0] <= hi + 1e-6));

    // One power-of-two axis is left alone.
    let rows: Vec<[f32; 4]> = (0..8 * 3).map(|k| [(k % 8) as f32, 0.0, 0.0, 1.0]).collect();
    let (w2, h2, out) = resample_to_power_of_two(8, 3, rows);
    assert_eq!((w2, h2), (8, 4));
    assert!(out.iter().enumerate().all(|(k, p)| near(p[0], (k % 8) as f32, 1e-6)));
}

#[test]
fn mip_chains() {
    // A checkerboard of 0 and 1: every level is exact, and 1 x 1 is the mean.
    let board: Vec<[f32; 4]> =
        (0..16 * 4).map(|k| if (k % 16 + k / 16) % 2 == 0 { [1.0, 0.0, 1.0, 1.0] } else { [0.0; 4] }).collect();
    let levels = build_mips(16, 4, board);
    assert_eq!(levels.iter().map(Vec::len).collect::<Vec<_>>(), [64, 16, 4, 2, 1]);
    assert_eq!(levels[4], [[0.5, 0.0, 0.5, 0.5]]);
    assert!(levels[1].iter().all(|&t| t == [0.5, 0.0, 0.5, 0.5]));
    // A 1 x 1 texture has a single level.
    assert_eq!(build_mips(1, 1, vec![[0.3; 4]]), [vec![[0.3; 4]]]);
    // A column: 1 x 4 -> 1 x 2 -> 1 x 1, averaging along y.
    let col = build_mips(1, 4, vec![[0.0; 4], [1.0; 4], [2.0; 4], [3.0; 4]]);
    assert_eq!(col, [vec![[0.0; 4], [1.0; 4], [2.0; 4], [3.0; 4]], vec![[0.5; 4], [2.5; 4]], vec![[1.5; 4]]]);

    let t = checker(64, 8, [0.9, 0.8, 0.7], [0.05, 0.1, 0.2]);
    assert_eq!((t.width, t.height, t.levels.len()), (64, 64, 7));
    let top = t.levels[6][0];
    for (k, expect) in [0.475f32, 0.45, 0.45].into_iter().enumerate() {
        assert!(near(top[k], expect, 1e-6), "{top:?}");
    }
}

#[test]
fn one_texel_file() {
    let dir = Dir::new();
    let path = dir.path("one.png");
    image::RgbImage::from_pixel(1, 1, image::Rgb([255, 0, 0])).save(&path).unwrap();
    let t = load_texture(&path, TextureKind::Albedo).unwrap();
    assert_eq!((t.width, t.height), (1, 1));
    assert_eq!(t.levels, [vec![[1.0, 0.0, 0.0, 1.0]]]);
}

#[test]
fn procedural_maps() {
    let h = bump_heights(128, 50, 7);
    assert_eq!(h, bump_heights(128, 50, 7), "deterministic");
    assert_eq!((h.width, h.height, h.levels.len()), (128, 128, 8));
    let level = &h.levels[0];
    assert!(level.iter().all(|t| (0.0..=1.0).contains(&t[0])));
    assert_eq!(level.iter().map(|t| t[0]).fold(0.0, f32::max), 1.0);
    let n = normals_from_heights(&h, 8.0);
    assert_eq!((n.width, n.height, n.levels.len()), (128, 128, 8));
    let mut tilted = 0;
    for t in &n.levels[0] {
        let v = [2.0 * t[0] - 1.0, 2.0 * t[1] - 1.0, 2.0 * t[2] - 1.0];
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(near(len, 1.0, 1e-5) && v[2] > 0.0, "{t:?}");
        tilted += usize::from(v[2] < 0.99);
    }
    assert!(tilted > 128 * 128 / 4, "the bumps tilt the normals: {tilted}");
    // Uphill in +u is where the normal leans toward −u.
    let at = |x: usize, y: usize| level[y * 128 + x][0];
    let (x, y) = (0..128 * 128)
        .map(|k| (k % 128, k / 128))
        .max_by(|&(x, y), &(x2, y2)| {
            let slope = |x: usize, y: usize| at((x + 1) % 128, y) - at((x + 127) % 128, y);
            slope(x, y).total_cmp(&slope(x2, y2))
        })
        .unwrap();
    assert!(n.levels[0][y * 128 + x][0] < 0.5);
}

#[test]
fn missing_file() {
    let dir = Dir::new();
    let path = dir.path("nope.png");
    let e = load_texture(&path, TextureKind::Albedo).unwrap_err();
    assert!(matches!(e, TextureError::Missing { .. }), "{e}");
    assert_eq!(e.to_string(), format!("{}: no such file", path.display()));
}

#[test]
fn corrupt_files() {
    use rand::{RngCore, SeedableRng};
    let dir = Dir::new();
    let mut bytes = vec![0u8; 4096];
    rand_pcg::Pcg64::seed_from_u64(1).fill_bytes(&mut bytes);
    for (name, format) in [("noise.png", "PNG"), ("noise.jpg", "JPEG"), ("noise.exr", "EXR")] {
        let path = dir.path(name);
        std::fs::write(&path, &bytes).unwrap();
        let e = load_texture(&path, TextureKind::Albedo).unwrap_err();
        let m = e.to_string();
        assert!(matches!(e, TextureError::Corrupt { .. }), "{m}");
        assert!(m.starts_with(&format!("{}: not a valid {format} image: ", path.display())), "{m}");
    }
    // A truncated PNG.
    let path = dir.path("cut.png");
    image::RgbImage::from_fn(64, 64, |x, y| image::Rgb([x as u8, y as u8, 7])).save(&path).unwrap();
    let full = std::fs::read(&path).unwrap();
    std::fs::write(&path, &full[..full.len() / 2]).unwrap();
    let e = load_texture(&path, TextureKind::Albedo).unwrap_err();
    assert!(matches!(e, TextureError::Corrupt { format: "PNG", .. }), "{e}");
    // An empty file.
    let path = dir.path("empty.png");
    std::fs::write(&path, b"").unwrap();
    assert!(matches!(load_texture(&path, TextureKind::Albedo), Err(TextureError::Corrupt { .. })));
}

#[test]
fn unsupported_formats() {
    let dir = Dir::new();
    for name in ["notes.txt", "image.bmp", "no_extension"] {
        let path = dir.path(name);
        std::fs::write(&path, b"BM not really a bitmap").unwrap();
        let e = load_texture(&path, TextureKind::Albedo).unwrap_err();
        let m = e.to_string();
        assert!(matches!(e, TextureError::Unsupported { .. }), "{m}");
        assert!(m.starts_with(&format!("{}: unsupported texture format", path.display())), "{m}");
        assert!(m.contains("PNG") && m.contains(".exr"), "{m}");
    }
    assert!(load_texture(&dir.path("image.bmp"), TextureKind::Albedo).unwrap_err().to_string().contains("`.bmp`"));
    // A directory is not a texture.
    let e = load_texture(dir.0.path(), TextureKind::Albedo).unwrap_err();
    assert!(matches!(e, TextureError::Read { .. }), "{e}");
    // A PNG under another extension is recognised by its contents.
    let path = dir.path("actually_png.dat");
    image::GrayImage::from_pixel(2, 2, image::Luma([9])).save_with_format(&path, image::ImageFormat::Png).unwrap();
    load_texture(&path, TextureKind::Roughness).unwrap();
}

#[test]
fn normal_map_from_one_channel() {
    let dir = Dir::new();
    let path = dir.path("grey.png");
    image::GrayImage::from_pixel(2, 2, image::Luma([128])).save(&path).unwrap();
    let e = load_texture(&path, TextureKind::Normal).unwrap_err();
    assert!(matches!(e, TextureError::Channels { channels: 1, needed: 3, .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!("{}: a normal map needs 3 colour channels (RGB) but the image has 1", path.display())
    );
    let path = dir.path("ga.png");
    image::GrayAlphaImage::from_pixel(2, 2, image::LumaA([128, 255])).save(&path).unwrap();
    assert!(matches!(load_texture(&path, TextureKind::Normal), Err(TextureError::Channels { channels: 1, .. })));
}

/// Files larger than the limit are rejected from their header: a 16385 x 1
/// image is tiny on disk, and the loader never decodes it.
#[test]
fn too_large() {
    let dir = Dir::new();
    let big = MAX_TEXTURE_SIZE + 1;
    for (w, h) in [(big, 1), (1, big)] {
        let path = dir.path(&format!("big_{w}x{h}.png"));
        image::GrayImage::new(w, h).save(&path).unwrap();
        let e = load_texture(&path, TextureKind::Roughness).unwrap_err();
        assert!(matches!(e, TextureError::TooLarge { .. }), "{e}");
        assert_eq!(
            e.to_string(),
            format!("{}: the image is {w} x {h} texels; a texture may be at most 16384 on a side", path.display())
        );
    }
    let path = dir.path("big.exr");
    write_exr_channel(&path, "Y", big as usize, 1, |_, _| 0.5);
    assert!(matches!(load_texture(&path, TextureKind::Roughness), Err(TextureError::TooLarge { .. })));
    // The largest allowed side loads.
    let path = dir.path("edge.png");
    image::GrayImage::new(MAX_TEXTURE_SIZE, 1).save(&path).unwrap();
    let t = load_texture(&path, TextureKind::Roughness).unwrap();
    assert_eq!((t.width, t.height, t.levels.len()), (MAX_TEXTURE_SIZE, 1, 15));
}

#[test]
fn from_texels_resamples_and_builds_mips() {
    let t = from_texels("test".into(), 3, 3, vec![[0.5; 4]; 9]);
    assert_eq!((t.source.as_str(), t.width, t.height, t.levels.len()), ("test", 4, 4, 3));
    assert!(t.levels.iter().flatten().all(|p| *p == [0.5; 4]));
}

#[test]
fn exr_texels_must_be_finite() {
    let dir = Dir::new();
    for (name, bad) in [("nan.exr", f32::NAN), ("inf.exr", f32::INFINITY), ("neginf.exr", f32::NEG_INFINITY)] {
        let path = dir.path(name);
        exr::prelude::write_rgba_file(&path, 4, 3, |x, y| {
            let g = if (x, y) == (2, 1) { bad } else { 0.5 };
            (0.5f32, g, 0.5f32, 1.0f32)
        })
        .unwrap();
        let e = load_texture(&path, TextureKind::Albedo).unwrap_err();
        assert!(matches!(e, TextureError::NonFinite { x: 2, y: 1, .. }), "{name}: {e}");
        assert!(e.to_string().contains("texel (2, 1) holds"), "{e}");
    }
}
