//! Pixel bounds: the part of the frame a render covers (a crop window or
//! one tile of a split render), as pbrt-v4's `--pixelbounds`. Random
//! sequences depend on the absolute pixel, so a pixel renders the same in
//! every crop that contains it and tiles stitch without seams.

use std::fmt;
use std::str::FromStr;

/// A rectangle of pixels of a `frame_width` x `frame_height` frame,
/// half-open: columns `x0..x1`, rows `y0..y1` (row 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct PixelBounds {
    /// First column.
    pub x0: u32,
    /// One past the last column.
    pub x1: u32,
    /// First row.
    pub y0: u32,
    /// One past the last row.
    pub y1: u32,
}

/// What is wrong with a crop or tile request.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum BoundsError {
    /// Not four comma-separated integers.
    #[error("a crop is x0,x1,y0,y1 (pixel bounds, half-open), got {0:?}")]
    CropSyntax(String),
    /// Not `i/N`.
    #[error("a tile is i/N with 0 <= i < N (e.g. 0/4), got {0:?}")]
    TileSyntax(String),
    /// Empty or outside the frame.
    #[error("pixel bounds {bounds} are empty or outside the {width}x{height} frame")]
    Outside {
        /// The bounds asked for.
        bounds: PixelBounds,
        /// Frame width.
        width: u32,
        /// Frame height.
        height: u32,
    },
    /// More tiles than rows.
    #[error("{tiles} tiles of a frame {height} rows high: at most one tile per row")]
    TooManyTiles {
        /// Tiles asked for.
        tiles: u32,
        /// Frame height.
        height: u32,
    },
}

impl PixelBounds {
    /// The whole `width` x `height` frame.
    pub fn full(width: u32, height: u32) -> Self {
        Self { x0: 0, x1: width, y0: 0, y1: height }
    }

    /// Columns covered.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Rows covered.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Pixels covered.
    pub fn pixels(&self) -> usize {
        self.width() as usize * self.height() as usize
    }

    /// Whether the bounds are the whole `width` x `height` frame.
    pub fn is_full(&self, width: u32, height: u32) -> bool {
        *self == Self::full(width, height)
    }

    /// Whether pixel `(x, y)` lies inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// Checks that the bounds are non-empty and inside the frame.
    pub fn check(self, width: u32, height: u32) -> Result<Self, BoundsError> {
        if self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= width && self.y1 <= height {
            Ok(self)
        } else {
            Err(BoundsError::Outside { bounds: self, width, height })
        }
    }

    /// Tile `index` of `count` (`--tile index/count`): the frame split into
    /// `count` bands of whole rows, band i covering rows
    /// ⌊i·H/count⌋ .. ⌊(i+1)·H/count⌋ (heights differ by at most one row).
    pub fn tile(index: u32, count: u32, width: u32, height: u32) -> Result<Self, BoundsError> {
        if count == 0 || index >= count {
            return Err(BoundsError::TileSyntax(format!("{index}/{count}")));
        }
        if count > height {
            return Err(BoundsError::TooManyTiles { tiles: count, height });
        }
        let row = |i: u32| (i as u64 * height as u64 / count as u64) as u32;
        Ok(Self { x0: 0, x1: width, y0: row(index), y1: row(index + 1) })
    }

    /// Copies the pixels inside `self` out of a row-major full-frame array
    /// `frame_width` pixels wide.
    pub fn extract<T: Copy>(&self, frame: &[T], frame_width: u32) -> Vec<T> {
        let w = frame_width as usize;
        (self.y0 as usize..self.y1 as usize)
            .flat_map(|y| frame[y * w + self.x0 as usize..y * w + self.x1 as usize].iter().copied())
            .collect()
    }

    /// Writes `part` (row-major, `self`'s size) into a full-frame array
    /// `frame_width` pixels wide: the inverse of [`PixelBounds::extract`].
    pub fn insert<T: Copy>(&self, part: &[T], frame: &mut [T], frame_width: u32) {
        let (w, cw) = (frame_width as usize, self.width() as usize);
        for (row, y) in (self.y0 as usize..self.y1 as usize).enumerate() {
            let at = y * w + self.x0 as usize;
            frame[at..at + cw].copy_from_slice(&part[row * cw..(row + 1) * cw]);
        }
    }
}

impl fmt::Display for PixelBounds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.x1, self.y0, self.y1)
    }
}

impl FromStr for PixelBounds {
    type Err = BoundsError;

    /// `x0,x1,y0,y1` (pbrt-v4's `--pixelbounds` order).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let v: Vec<u32> = s
            .split(',')
            .map(|p| p.trim().parse())
            .collect::<Result<_, _>>()
            .map_err(|_| BoundsError::CropSyntax(s.into()))?;
        match v[..] {
            [x0, x1, y0, y1] => Ok(Self { x0, x1, y0, y1 }),
            _ => Err(BoundsError::CropSyntax(s.into())),
        }
    }
}

/// `i/N`: tile i of N ([`PixelBounds::tile`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileIndex {
    /// Which tile, from 0.
    pub index: u32,
    /// How many tiles.
    pub count: u32,
}

impl FromStr for TileIndex {
    type Err = BoundsError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || BoundsError::TileSyntax(s.into());
        let (i, n) = s.split_once('/').ok_or_else(err)?;
        let (index, count) = (i.trim().parse().map_err(|_| err())?, n.trim().parse().map_err(|_| err())?);
        if count == 0 || index >= count {
            return Err(err());
        }
        Ok(Self { index, count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_frame_once() {
        for (h, n) in [(768, 4), (7, 3), (5, 5), (1000, 7)] {
            let mut rows = vec![0u32; h as usize];
            for i in 0..n {
                let t = PixelBounds::tile(i, n, 16, h).unwrap();
                assert!(t.height() >= h / n && t.height() <= h.div_ceil(n), "{t}");
                (t.y0..t.y1).for_each(|y| rows[y as usize] += 1);
            }
            assert!(rows.iter().all(|&c| c == 1), "{h} rows in {n} tiles");
        }
        assert_eq!(PixelBounds::tile(0, 9, 4, 8), Err(BoundsError::TooManyTiles { tiles: 9, height: 8 }));
    }

    #[test]
    fn parses_and_checks() {
        assert_eq!("1,5,2,3".parse::<PixelBounds>(), Ok(PixelBounds { x0: 1, x1: 5, y0: 2, y1: 3 }));
        assert!("1,5,2".parse::<PixelBounds>().is_err());
        assert!("a,5,2,3".parse::<PixelBounds>().is_err());
        assert!(PixelBounds { x0: 4, x1: 4, y0: 0, y1: 1 }.check(8, 8).is_err());
        assert!(PixelBounds { x0: 0, x1: 9, y0: 0, y1: 1 }.check(8, 8).is_err());
        assert_eq!("2/4".parse::<TileIndex>(), Ok(TileIndex { index: 2, count: 4 }));
        assert!("4/4".parse::<TileIndex>().is_err());
        assert!("1/0".parse::<TileIndex>().is_err());
        assert!("x".parse::<TileIndex>().is_err());
    }

    #[test]
    fn extract_and_insert_are_inverse() {
        let frame: Vec<u32> = (0..6 * 4).collect();
        let b = PixelBounds { x0: 1, x1: 4, y0: 1, y1: 3 };
        let part = b.extract(&frame, 6);
        assert_eq!(part, vec![7, 8, 9, 13, 14, 15]);
        let mut back = vec![0; 24];
        b.insert(&part, &mut back, 6);
        assert_eq!(back.iter().filter(|&&v| v != 0).count(), 6);
        assert_eq!(b.extract(&back, 6), part);
    }
}
