//! Writing files so that a failure leaves nothing behind: every file goes to
//! a temporary name beside its destination and is renamed into place once
//! written (a set of files only when all of them are), and the names of an
//! animation's frames. The lowest layer: images, checkpoints, plots, farm
//! scripts and reports all write through it.

use std::io;
use std::path::{Path, PathBuf};

fn temporary_path(path: &Path) -> io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, format!("{} has no file name", path.display())))?;
    Ok(path.with_file_name(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id())))
}

/// `path` with the frame number before its extension: `out.exr` →
/// `out.0002.exr`, `out` → `out.0002` (the names of `render --frame`).
pub fn frame_path(path: &Path, frame: u32) -> PathBuf {
    let stem = path.file_stem().map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let name = match path.extension() {
        Some(e) => format!("{stem}.{frame:04}.{}", e.to_string_lossy()),
        None => format!("{stem}.{frame:04}"),
    };
    path.with_file_name(name)
}

/// Writes several files all or nothing: `write(i, tmp)` fills a temporary
/// file beside `paths[i]`, and only when all are written are they renamed
/// into place. On error every temporary file is removed, and the error names
/// the file that failed.
pub fn write_all_or_nothing(paths: &[PathBuf], write: impl Fn(usize, &Path) -> io::Result<()>) -> io::Result<()> {
    let named = |path: &Path, e: io::Error| io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()));
    let mut temporaries = Vec::new();
    let result = (|| {
        for (i, path) in paths.iter().enumerate() {
            let tmp = temporary_path(path)?;
            temporaries.push(tmp.clone());
            write(i, &tmp).map_err(|e| named(path, e))?;
        }
        // A destination that cannot be replaced fails the whole set before any
        // file is renamed into place.
        if let Some(dir) = paths.iter().find(|p| p.is_dir()) {
            return Err(named(dir, io::Error::new(io::ErrorKind::IsADirectory, "a directory is in the way")));
        }
        for (path, tmp) in paths.iter().zip(&temporaries) {
            std::fs::rename(tmp, path).map_err(|e| named(path, e))?;
        }
        Ok(())
    })();
    if result.is_err() {
        for tmp in &temporaries {
            let _ = std::fs::remove_file(tmp);
        }
    }
    result
}

/// Writes `bytes` to `path` through a temporary file beside it and a rename:
/// readers see the old file or the new one, never a part.
pub fn write_file_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_all_or_nothing(&[path.to_path_buf()], |_, tmp| std::fs::write(tmp, bytes))
}
