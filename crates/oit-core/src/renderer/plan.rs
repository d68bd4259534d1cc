//! The planner: the screen tiles a frame renders in, from the method's declared storage
//! (`MethodInfo::tiling`), the census, the frame's own targets and readbacks, and the memory
//! budget (docs/methods.md, "Tiles"). Everything it plans is allocated by the executor.

use super::{Renderer, COVERAGE_SAMPLES};
use crate::error::{OitError, Result};
use crate::method::{MethodInfo, Params, Tiling};
use crate::targets::{SampleTargets, Targets};
use crate::tiles::{self, Footprint, Tile};

/// A frame's tiles and the size of the targets they are drawn into.
pub(super) struct Plan {
    pub tiles: Vec<Tile>,
    pub targets: (u32, u32),
}

impl Renderer {
    /// Bytes of the frame's own targets and readbacks at `width` x `height` (and, for a
    /// coverage-mask frame, its per-sample targets).
    pub(super) fn target_bytes(width: u32, height: u32, coverage: bool) -> u64 {
        Targets::bytes_for(width, height) + if coverage { SampleTargets::bytes_for(width, height, COVERAGE_SAMPLES) } else { 0 }
    }

    /// Whether the frame's targets can be frame-sized: without a budget, or where they fit in it.
    /// Tiles then only divide the method's storage, and every fragment is rasterized and
    /// interpolated exactly as in the untiled frame. Tile-sized targets rasterize with the
    /// viewport moved by the tile's origin: coverage is the same, interpolated depth and color
    /// may differ by float32 rounding (docs/methods.md, "Tiles").
    pub(super) fn frame_targets(&self, coverage: bool) -> bool {
        self.memory_budget.is_none_or(|b| Self::target_bytes(self.width, self.height, coverage) < b)
    }

    /// Rows of the census's bands: the whole frame, or as many whole rows of tile-sized targets
    /// as the memory budget holds. The census allocates targets alone: no method storage is kept
    /// while it runs under a budget (`Renderer::render_sample`).
    pub(super) fn census_rows(&self, coverage: bool) -> Result<u32> {
        let (w, h) = (self.width, self.height);
        let Some(budget) = self.memory_budget.filter(|_| !self.frame_targets(coverage)) else { return Ok(h) };
        let row = Self::target_bytes(w, 1, coverage);
        if row > budget {
            return Err(self.row_refused(budget, row));
        }
        let mut rows = h.min((budget / row).max(1) as u32);
        while rows > 1 && Self::target_bytes(w, rows, coverage) > budget {
            rows -= 1;
        }
        Ok(rows)
    }

    /// Why a frame into a caller's texture cannot render: its targets must be the frame's (the
    /// caller's depth and picture are copied whole), and the budget cannot hold them beside the
    /// method.
    pub(super) fn target_refused(&self) -> OitError {
        let (w, h) = (self.width, self.height);
        OitError::OutOfMemory(format!(
            "render_into draws into frame-sized targets ({} bytes at {w} x {h}), which the memory_budget of {} bytes \
             cannot hold beside the method: raise memory_budget, or render() in tiles",
            Self::target_bytes(w, h, false),
            self.memory_budget.unwrap_or(0)
        ))
    }

    fn row_refused(&self, budget: u64, row: u64) -> OitError {
        OitError::OutOfMemory(format!(
            "a memory_budget of {budget} bytes cannot hold one row of the frame's own targets and readbacks ({} pixels: \
             {row} bytes), the smallest tile: raise memory_budget above {row} bytes, or render a narrower frame",
            self.width
        ))
    }

    /// The screen tiles `info`'s method renders this frame in (one unless its storage and the
    /// frame's targets would pass a binding or the memory budget), and the size of the targets:
    /// the frame's where the method's tiles fit beside them, else the largest tile's. With
    /// `self_counted` (no census: the method counts its fragments in its own capture and reports
    /// where they do not fit), the plan holds the per-pixel storage alone.
    pub(super) fn plan_tiles(
        &self,
        info: &MethodInfo,
        params: &Params,
        counts: &[u32],
        coverage: bool,
        squeeze: f64,
        self_counted: bool,
    ) -> Result<Plan> {
        let (w, h) = (self.width, self.height);
        let budget = self.memory_budget.unwrap_or(u64::MAX);
        // The method's share of the budget (beside the targets), divided by `squeeze` when a
        // first plan proved too loose.
        let variable = |rest: u64| if rest == u64::MAX { rest } else { (rest as f64 / squeeze) as u64 };
        let binding = self.limits.max_binding_bytes;
        let mut fp = match info.tiling() {
            Tiling::Formula => {
                let one = info.memory_bytes(1, params, None).unwrap_or(0);
                let per_pixel = info.memory_bytes(2, params, None).unwrap_or(0) - one;
                Footprint {
                    per_pixel,
                    per_fragment: 0,
                    budget: budget.saturating_sub(one - per_pixel),
                    // Every buffer of the method within one binding: at most all of a tile's bytes.
                    max_pixels: binding / per_pixel.max(1),
                    max_fragments: u64::MAX,
                    max_rows: h,
                }
            }
            Tiling::Storage { per_pixel, per_fragment, per_triangle } => {
                // A coverage-mask frame keeps sweep state per sample and a mask per node.
                let (per_pixel, per_fragment) = if coverage {
                    (crate::method::lists::pixel_bytes(COVERAGE_SAMPLES), per_fragment + 8)
                } else {
                    (per_pixel, per_fragment)
                };
                let pool = crate::method::lists::POOL_BINDINGS * (binding / per_fragment);
                let fixed = per_triangle * self.scene.as_ref().map_or(0, |(_, s)| s.transparent.triangles as u64);
                if fixed >= budget {
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' keeps {per_triangle} bytes for each transparent triangle, {fixed} bytes in all, which no tile \
                         can make smaller and which pass the memory_budget of {budget} bytes: raise memory_budget or use \
                         abuffer or sbuffer, which keep nothing per triangle",
                        info.name
                    )));
                }
                Footprint {
                    per_pixel,
                    per_fragment: if self_counted { 0 } else { per_fragment },
                    budget: budget - fixed,
                    max_pixels: binding / per_pixel,
                    max_fragments: (pool as f64 / squeeze) as u64,
                    max_rows: h,
                }
            }
        };
        if self.frame_targets(coverage) {
            let whole = Footprint { budget: variable(fp.budget.saturating_sub(Self::target_bytes(w, h, coverage).min(budget))), ..fp };
            match tiles::plan(w, h, counts, &whole) {
                Ok(tiles) => return Ok(Plan { tiles, targets: (w, h) }),
                Err(e) if self.memory_budget.is_none() => return Err(e),
                Err(_) => {} // tile-sized targets leave the method more
            }
        }
        // The frame's targets are sized to the tallest tile: bands of at most `rows` rows
        // leave the method what targets of `rows` full rows do not take.
        let row = Self::target_bytes(w, 1, coverage);
        if row >= budget {
            return Err(self.row_refused(budget, row));
        }
        let method_budget = fp.budget;
        let mut rows = h.min((budget / (row + fp.per_pixel * w as u64).max(1)).max(1) as u32);
        loop {
            let targets = Self::target_bytes(w, rows, coverage);
            fp.max_rows = rows;
            fp.budget = variable(method_budget.saturating_sub(targets));
            match tiles::plan(w, h, counts, &fp) {
                Ok(tiles) if targets < budget => {
                    let size = tiles.iter().fold((1, 1), |(a, b), t| (t.width.max(a), t.height.max(b)));
                    return Ok(Plan { tiles: tiles.into_iter().map(Tile::own_targets).collect(), targets: size });
                }
                Err(e) if rows == 1 => return Err(e),
                _ if rows == 1 => return Err(self.row_refused(budget, row)),
                _ => rows = rows.div_ceil(2).min(rows - 1),
            }
        }
    }
}
