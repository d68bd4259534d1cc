//! Screen tiles: a frame whose storage (the method's, and the frame's own targets and readbacks)
//! would pass a storage binding or the memory budget is rendered as several tiles of the same
//! projection. A tile's targets are tile-sized: each pass draws with the frame's viewport moved
//! by the tile's origin, scissored to the tile, and the method's per-pixel storage is indexed
//! within it (shaders/common/scene.wgsl, `pixel_index`), so a tile rasterizes the fragments it
//! has in the whole frame. Tiles are planned from the census: bands of whole rows while they
//! fit, a row cut into runs of pixels where one row does not (docs/methods.md, "Tiles").

use crate::error::{OitError, Result};

/// A rectangle of pixels of a `frame.0` x `frame.1` frame: columns x .. x + width, rows
/// y .. y + height, drawn into targets whose pixel (0, 0) is the frame's pixel `origin`: (0, 0)
/// for frame-sized targets, the tile's own first pixel for tile-sized ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub frame: (u32, u32),
    pub origin: (u32, u32),
}

impl Tile {
    pub fn frame(width: u32, height: u32) -> Self {
        Self { x: 0, y: 0, width, height, frame: (width, height), origin: (0, 0) }
    }

    /// The tile drawn into targets of its own size.
    pub fn own_targets(self) -> Self {
        Self { origin: (self.x, self.y), ..self }
    }

    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }

    /// Whether the tile is the whole frame.
    pub fn is_whole(&self) -> bool {
        (self.width, self.height) == self.frame
    }

    /// The tile's rectangle in its targets' pixels.
    pub fn local(&self) -> Tile {
        Tile { x: self.x - self.origin.0, y: self.y - self.origin.1, ..*self }
    }

    /// Restricts `pass` to the tile: the frame's viewport moved by the targets' origin (so every
    /// fragment lands where it does in the whole frame, less the origin), scissored to the
    /// tile's pixels.
    pub fn scissor(&self, pass: &mut wgpu::RenderPass<'_>) {
        let (ox, oy) = self.origin;
        pass.set_viewport(-(ox as f32), -(oy as f32), self.frame.0 as f32, self.frame.1 as f32, 0.0, 1.0);
        pass.set_scissor_rect(self.x - ox, self.y - oy, self.width, self.height);
    }

    /// The values of `frame` (row-major, `frame_width` a row) that lie in the tile, row-major.
    pub fn crop<T: Copy>(&self, frame: &[T], frame_width: u32) -> Vec<T> {
        let (w, x) = (frame_width as usize, self.x as usize);
        (self.y as usize..(self.y + self.height) as usize)
            .flat_map(|r| frame[r * w + x..r * w + x + self.width as usize].iter().copied())
            .collect()
    }
}

/// What one tile may hold: `per_pixel` bytes for each of its pixels and `per_fragment` bytes for
/// each of its fragments, at most `budget` bytes in all, at most `max_pixels` pixels and
/// `max_fragments` fragments (what the method's bindings hold), and at most `max_rows` rows (the
/// frame's targets are sized to the tallest tile).
#[derive(Clone, Copy, Debug)]
pub struct Footprint {
    pub per_pixel: u64,
    pub per_fragment: u64,
    pub budget: u64,
    pub max_pixels: u64,
    pub max_fragments: u64,
    pub max_rows: u32,
}

impl Footprint {
    fn fits(&self, pixels: u64, fragments: u64) -> bool {
        pixels <= self.max_pixels
            && fragments <= self.max_fragments
            && pixels.saturating_mul(self.per_pixel).saturating_add(fragments.saturating_mul(self.per_fragment)) <= self.budget
    }
}

/// The tiles of a `width` x `height` frame whose pixels have `counts` fragments (row-major),
/// each within `fp`: bands of whole rows, greedily as tall as fit; a row that does not fit alone
/// is cut into runs of pixels. Fails only where one pixel alone does not fit.
pub fn plan(width: u32, height: u32, counts: &[u32], fp: &Footprint) -> Result<Vec<Tile>> {
    // No census (a method that keeps nothing per fragment): every pixel counts as empty.
    assert!(!counts.is_empty() || fp.per_fragment == 0, "a footprint with per-fragment storage is planned from the census");
    let count = |i: u32| counts.get(i as usize).map_or(0, |&c| c as u64);
    let row_fragments: Vec<u64> = match counts.is_empty() {
        true => vec![0; height as usize],
        false => counts.chunks(width as usize).map(|r| r.iter().map(|&c| c as u64).sum()).collect(),
    };
    if height <= fp.max_rows && fp.fits(width as u64 * height as u64, row_fragments.iter().sum()) {
        return Ok(vec![Tile::frame(width, height)]);
    }
    let mut tiles = Vec::new();
    let mut y = 0;
    while y < height {
        let (mut rows, mut fragments) = (0u32, 0u64);
        while y + rows < height
            && rows < fp.max_rows
            && fp.fits((rows as u64 + 1) * width as u64, fragments + row_fragments[(y + rows) as usize])
        {
            fragments += row_fragments[(y + rows) as usize];
            rows += 1;
        }
        if rows > 0 {
            tiles.push(Tile { x: 0, y, width, height: rows, frame: (width, height), origin: (0, 0) });
            y += rows;
            continue;
        }
        // One row does not fit: runs of pixels along it.
        let at = |x: u32| count(y * width + x);
        let mut x = 0;
        while x < width {
            let (mut n, mut fragments) = (0u32, 0u64);
            while x + n < width && fp.fits(n as u64 + 1, fragments + at(x + n)) {
                fragments += at(x + n);
                n += 1;
            }
            if n == 0 {
                let c = at(x);
                return Err(OitError::OutOfMemory(format!(
                    "pixel ({x}, {y}) has {c} transparent fragments, more than one tile can hold ({} bytes of storage, at most \
                     {} fragments a tile on this adapter and budget): raise memory_budget or use a bounded method (e.g. hybrid)",
                    fp.per_pixel + c * fp.per_fragment,
                    fp.max_fragments.min(fp.budget.saturating_sub(fp.per_pixel) / fp.per_fragment.max(1))
                )));
            }
            tiles.push(Tile { x, y, width: n, height: 1, frame: (width, height), origin: (0, 0) });
            x += n;
        }
        y += 1;
    }
    Ok(tiles)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(per_pixel: u64, per_fragment: u64, budget: u64) -> Footprint {
        Footprint { per_pixel, per_fragment, budget, max_pixels: u64::MAX, max_fragments: u64::MAX, max_rows: u32::MAX }
    }

    fn covers_once(tiles: &[Tile], w: u32, h: u32) {
        let mut seen = vec![0u8; (w * h) as usize];
        for t in tiles {
            for y in t.y..t.y + t.height {
                for x in t.x..t.x + t.width {
                    seen[(y * w + x) as usize] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1), "{tiles:?}");
    }

    #[test]
    fn one_tile_when_the_frame_fits() {
        assert_eq!(plan(4, 3, &[1; 12], &fp(10, 10, 1000)).unwrap(), vec![Tile::frame(4, 3)]);
    }

    #[test]
    fn bands_of_rows_then_runs_of_pixels() {
        // 4 x 3, 10 bytes a pixel: two rows fit in 80 bytes, one row of 40 plus fragments may not.
        let tiles = plan(4, 3, &[0; 12], &fp(10, 0, 80)).unwrap();
        let band = |y, height| Tile { x: 0, y, width: 4, height, frame: (4, 3), origin: (0, 0) };
        assert_eq!(tiles, vec![band(0, 2), band(2, 1)]);
        // At most one row a tile: three bands.
        let tiles = plan(4, 3, &[0; 12], &Footprint { max_rows: 1, ..fp(10, 0, 1000) }).unwrap();
        assert_eq!(tiles, vec![band(0, 1), band(1, 1), band(2, 1)]);
        let counts = [0, 0, 0, 0, 9, 1, 1, 9, 0, 0, 0, 0];
        let tiles = plan(4, 3, &counts, &fp(1, 10, 100)).unwrap();
        covers_once(&tiles, 4, 3);
        for t in &tiles {
            let f: u64 = t.crop(&counts, 4).iter().map(|&c| c as u64).sum();
            assert!(t.pixels() + 10 * f <= 100, "{t:?}");
        }
        assert!(tiles.iter().any(|t| t.height == 1 && t.width < 4));
    }

    #[test]
    fn a_pixel_past_a_whole_tile_is_refused_by_name() {
        let e = plan(2, 1, &[3, 500], &fp(1, 10, 1000)).unwrap_err().to_string();
        assert!(e.contains("pixel (1, 0) has 500 transparent fragments"), "{e}");
    }

    #[test]
    fn crop_takes_the_tile_row_major() {
        let frame: Vec<u32> = (0..12).collect();
        assert_eq!(Tile { x: 1, y: 1, width: 2, height: 2, frame: (4, 3), origin: (0, 0) }.crop(&frame, 4), vec![5, 6, 9, 10]);
    }
}
