//! The sorted resolve's plan (shaders/common/sweep*.wgsl): what it keeps a pixel, what its steps
//! cost where the adapter has a loop limit, and the strategy chosen from the adapter's profile:
//! budgeted sweeps resumed over several dispatches, or the plain resolve in one.

use crate::consts::{Const, RUN, SWEEP_BLOCK, SWEEP_PIXEL_WORDS, SWEEP_SAMPLE_WORDS};
use crate::context::{DeviceProfile, SweepSteps};
use crate::error::{OitError, Result};

const BLOCK: u64 = SWEEP_BLOCK as u64;

/// The local array of a frame whose deepest pixel has n fragments: the smallest power of two
/// from BLOCK to RUN that holds it (a smaller array is cheaper to keep: it is zeroed at every
/// invocation).
pub fn run_length(n: u64) -> u32 {
    (n.next_power_of_two() as u32).clamp(SWEEP_BLOCK, RUN)
}

/// How the sorted resolve runs the pixels deeper than one run, chosen from the adapter's profile
/// (`choose`); the image does not depend on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResolveStrategy {
    /// Where a loop limiter ends long invocations: a deep pixel's work is a state machine that
    /// pauses after `budget` steps and resumes in the next dispatch, and each deep phase (runs,
    /// merge, composite) is dispatched as often as the deepest pixel needs (`resolve_dispatches`).
    Budgeted { budget: u64 },
    /// Where loops run to their end: the first dispatch (cs_sort) takes every pixel through its
    /// runs, merges and composite in one go, with no budget and no later dispatch.
    Plain,
}

impl ResolveStrategy {
    /// The constants of a pipeline whose constants do not change its code: a shader without a
    /// sorted resolve, or a capture.
    pub const UNUSED: Self = Self::Budgeted { budget: 1 };

    /// Budgeted sweeps where `profile` has a loop limit, else the plain resolve.
    pub fn choose(profile: &DeviceProfile, costs: StepCosts) -> Result<Self> {
        match profile.loop_limit {
            Some(limit) => Ok(Self::Budgeted { budget: step_budget(limit.iterations, costs)? }),
            None => Ok(Self::Plain),
        }
    }

    /// Dispatches of each deep phase after cs_sort (runs, merge, composite) for a frame whose
    /// deepest pixel has n fragments.
    pub fn dispatches(self, n: u64, costs: StepCosts) -> [u32; 3] {
        match self {
            Self::Budgeted { budget } => resolve_dispatches(n, costs, budget),
            Self::Plain => [0; 3],
        }
    }

    /// The shader's constants: the budget, and whether it is kept (BUDGETED).
    pub fn consts(self) -> [Const; 2] {
        let (budget, budgeted) = match self {
            Self::Budgeted { budget } => (budget as u32, 1),
            Self::Plain => (0, 0),
        };
        [Const::U32("STEP_BUDGET", budget), Const::U32("BUDGETED", budgeted)]
    }
}

/// Words of per-pixel sweep state at one sample a pixel (STATE_WORDS in
/// shaders/common/sweep.wgsl).
pub(crate) const STATE_WORDS: u64 = state_words(1);

pub(crate) const fn state_words(samples: u32) -> u64 {
    SWEEP_PIXEL_WORDS as u64 + SWEEP_SAMPLE_WORDS as u64 * samples as u64
}

/// Bytes a pixel of a sorted-resolve method keeps besides its pool: its head, its sweep state
/// and its entries of the two pixel lists.
pub(crate) const fn pixel_bytes(samples: u32) -> u64 {
    4 + 4 * (state_words(samples) + 2)
}

pub(crate) const PIXEL_BYTES: u64 = pixel_bytes(1);

/// The same with the count a capture keeps where it counts its own fragments in place of the
/// census (abuffer, compact_abuffer: `ListLayout::counts_in_capture`).
pub(crate) const COUNTED_PIXEL_BYTES: u64 = PIXEL_BYTES + 4;

/// What one step of the sorted resolve costs in the adapter's loop limiter (`steps`, from its
/// profile; the constants of shaders/common/sweep.wgsl, which this mirrors): `frag` is what turning a node into a
/// fragment adds (nothing, for every method today); `shade` what compositing a fragment adds
/// (compact_abuffer shades it there: its lights and the shading-cost loop); `run` the fragments a run holds in this frame (RUN, or
/// the deepest list when shorter).
/// The array a run is sorted in is [`run_length`] of the deepest list.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepCosts {
    pub steps: SweepSteps,
    pub samples: u64,
    pub frag: u64,
    pub shade: u64,
    pub run: u64,
}

impl StepCosts {
    fn load(self) -> u64 {
        self.steps.load as u64 + self.frag
    }
    fn link(self) -> u64 {
        self.steps.link as u64
    }
    fn merge(self) -> u64 {
        self.steps.merge as u64 + 2 * self.frag
    }
    fn composite(self) -> u64 {
        self.steps.composite as u64 + self.samples + self.frag + self.shade
    }

    /// Whether runs hold sort keys, not whole fragments (sweep.wgsl's KEYED): where turning a
    /// node into a fragment costs nothing beyond its load.
    pub(crate) fn keyed(self) -> bool {
        self.frag == 0
    }

    /// Steps of sweep.wgsl's `sort_keys` on n entries: the blocks' insertion sorts (at most
    /// (BLOCK - 1)(BLOCK + 2) / 2 a block), the walk that looks for equal depths in a run of one
    /// block, then each merge level (a step a pair, an entry and the level) and the copy back
    /// when the levels end in the upper half.
    fn sort_keys(n: u64) -> u64 {
        let blocks = n.div_ceil(BLOCK);
        let full = (BLOCK - 1) * (BLOCK + 2) / 2;
        let mut steps = blocks * (1 + full) + 1 + if n <= BLOCK { n } else { 0 };
        let (mut width, mut levels) = (BLOCK, 0);
        while width < n {
            steps += n + n.div_ceil(2 * width) + 1;
            width *= 2;
            levels += 1;
        }
        steps + if levels % 2 == 1 { n } else { 0 }
    }

    /// A run loaded, sorted and relinked or composited: the largest unit of work between two
    /// checks of the budget. A run of one block is sorted by insertion in frag_less's order
    /// (keyed: two nodes loaded at each comparison of equal depths); a longer one by its keys,
    /// then keyed runs order equal depths by insertion, at worst every entry of the run at one
    /// depth, a node loaded each comparison. Keyed runs load each node again to composite it.
    fn run(self) -> u64 {
        let run = self.run;
        let compares = run.saturating_sub(1) * (run + 2) / 2;
        let keyed = self.keyed() as u64;
        let sort = if run <= BLOCK {
            compares * (1 + keyed * 2 * self.load())
        } else {
            Self::sort_keys(run) + keyed * (run.saturating_sub(1) * self.load() + compares * (1 + self.load()))
        };
        self.load() * (run + 1) + sort + run * (self.link().max(2 + self.samples + self.shade) + keyed * self.load())
    }

    fn largest_unit(self) -> u64 {
        self.run().max(self.merge()).max(self.composite())
    }
}

/// Steps one invocation of the sorted resolve takes before it pauses until the next dispatch,
/// under a loop limiter of `limit` iterations: the limit less the largest unit of work.
fn step_budget(limit: u64, costs: StepCosts) -> Result<u64> {
    // The first dispatch does one unit; a deeper frame's later dispatches each do units while
    // their steps are below the budget, so a budget of at least MIN_BUDGET keeps their count
    // (the steps over the budget) within a few times the work's.
    const MIN_BUDGET: u64 = 8192;
    let unit = costs.largest_unit();
    let room = if costs.run < RUN as u64 { limit } else { limit.saturating_sub(MIN_BUDGET) };
    if unit > room {
        return Err(OitError::Unsupported(format!(
            "the exact resolve needs {unit} loop iterations for one unit of work here (a fragment shaded at resolve with \
             {} iterations), and this adapter ends a shader's loops after {limit}: lower shading_cost or use \
             abuffer, which shades at capture",
            costs.shade
        )));
    }
    Ok(limit - unit)
}

/// Steps of each phase of the sorted resolve after its first dispatch, on a pixel of n
/// fragments, at most: the further runs of RUN; ceil(log2(runs)) merge passes of two steps a
/// node and two a pair; the composite walk. Zero for a list of one run, which the first
/// dispatch composites.
pub fn resolve_steps(n: u64, costs: StepCosts) -> [u64; 3] {
    let run = run_length(n) as u64;
    if n <= run {
        return [0; 3];
    }
    let runs = n.div_ceil(run);
    let passes = runs.next_power_of_two().ilog2() as u64;
    [(runs - 1) * costs.run(), passes * costs.merge() * (2 * n + 2 * runs), (n + 1) * costs.composite()]
}

/// Dispatches of each phase after `cs_sort` (runs, merge, composite) that finish a frame
/// whose deepest pixel has n fragments.
pub fn resolve_dispatches(n: u64, costs: StepCosts, budget: u64) -> [u32; 3] {
    resolve_steps(n, costs).map(|steps| steps.div_ceil(budget) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::context::LLVMPIPE_SWEEP;

    const UNSHADED: StepCosts = StepCosts { steps: LLVMPIPE_SWEEP, samples: 1, frag: 0, shade: 0, run: RUN as u64 };
    const LIMIT: u64 = 65_535;

    #[test]
    fn the_profile_chooses_the_strategy() {
        // A loop limit: budgeted sweeps, the limit less the largest unit a dispatch.
        let budgeted = ResolveStrategy::choose(&DeviceProfile::LLVMPIPE, UNSHADED).unwrap();
        assert_eq!(budgeted, ResolveStrategy::Budgeted { budget: LIMIT - UNSHADED.largest_unit() });
        assert!(budgeted.dispatches(300, UNSHADED).iter().all(|&n| n > 0));
        // None: the plain resolve, no budget and no dispatch after cs_sort at any depth.
        let plain = ResolveStrategy::choose(&DeviceProfile::UNLIMITED, UNSHADED).unwrap();
        assert_eq!(plain, ResolveStrategy::Plain);
        assert_eq!(plain.dispatches(1 << 20, UNSHADED), [0; 3]);
        assert!(matches!(plain.consts(), [_, Const::U32("BUDGETED", 0)]));
        // A unit past a small limit is refused, with the limit in the message.
        let tiny = DeviceProfile { loop_limit: Some(crate::context::LoopLimit { iterations: 1000, sweep: LLVMPIPE_SWEEP }) };
        let e = ResolveStrategy::choose(&tiny, UNSHADED).unwrap_err().to_string();
        assert!(e.contains("after 1000"), "{e}");
    }

    #[test]
    fn a_list_of_one_run_needs_no_dispatch_after_the_first() {
        assert_eq!(resolve_steps(RUN as u64, UNSHADED), [0; 3]);
        assert_eq!(resolve_dispatches(1, UNSHADED, 1000), [0; 3]);
    }

    #[test]
    fn deeper_lists_take_the_runs_merges_and_composite_the_shader_counts() {
        // 300 fragments: 3 runs of 128 (2 after the first), 2 merge passes, 301 composite steps.
        let n = 300;
        let [runs, merge, composite] = resolve_steps(n, UNSHADED);
        assert_eq!(runs, 2 * UNSHADED.run());
        assert_eq!(merge, 2 * (LLVMPIPE_SWEEP.merge as u64) * (2 * n + 2 * 3));
        assert_eq!(composite, (n + 1) * (LLVMPIPE_SWEEP.composite as u64 + 1));
        let budget = 1000;
        assert_eq!(resolve_dispatches(n, UNSHADED, budget), [runs, merge, composite].map(|s| s.div_ceil(budget) as u32));
    }

    #[test]
    fn the_local_sort_counts_its_blocks_levels_and_copy() {
        // 8 entries: one block of at most 35 shifts, no merge; the walk for equal depths (a
        // step, and one an entry).
        assert_eq!(StepCosts::sort_keys(8), 36 + 1 + 8);
        // 20 entries: 3 blocks, a step for the walk no lane enters, then levels of width 8
        // (2 pairs) and 16 (1 pair), ending in the lower half (no copy).
        assert_eq!(StepCosts::sort_keys(20), 3 * 36 + 1 + (20 + 2 + 1) + (20 + 1 + 1));
        // 128 entries: 16 blocks, 4 levels (8, 16, 32, 64), no copy.
        assert_eq!(StepCosts::sort_keys(128), 16 * 36 + 1 + (128 + 8 + 1) + (128 + 4 + 1) + (128 + 2 + 1) + (128 + 1 + 1));
        // 64: 3 levels, so the result is copied back.
        assert_eq!(StepCosts::sort_keys(64), 8 * 36 + 1 + (64 + 4 + 1) + (64 + 2 + 1) + (64 + 1 + 1) + 64);
    }

    #[test]
    fn a_keyed_run_counts_its_worst_ties() {
        // Every entry at one depth: the tie pass is a whole insertion sort, a node loaded each
        // comparison, besides the entry's own load; and each node loaded again to composite it.
        let load = LLVMPIPE_SWEEP.load as u64;
        let n = RUN as u64;
        let compares = (n - 1) * (n + 2) / 2;
        let ties = (n - 1) * load + compares * (1 + load);
        assert_eq!(UNSHADED.run(), load * (n + 1) + StepCosts::sort_keys(n) + ties + n * ((LLVMPIPE_SWEEP.link as u64).max(2 + 1) + load));
        // A run of one block: one insertion sort, each comparison with the tie's two loads.
        let short = StepCosts { run: BLOCK, ..UNSHADED };
        let compares = (BLOCK - 1) * (BLOCK + 2) / 2;
        assert_eq!(short.run(), load * (BLOCK + 1) + compares * (1 + 2 * load) + BLOCK * (3 + load));
        // The worst unit still leaves llvmpipe's limit room for more than one a dispatch.
        assert!(UNSHADED.largest_unit() < LIMIT / 2);
    }

    #[test]
    fn shading_at_composite_costs_the_composite_alone() {
        // compact_abuffer unlit: its nodes cost their load alone, so runs stay keyed, and a
        // composited fragment adds its shading.
        let n = RUN as u64;
        let deferred = StepCosts { shade: 12, ..UNSHADED };
        assert!(deferred.keyed());
        assert_eq!(deferred.composite(), UNSHADED.composite() + 12);
        assert_eq!(deferred.run(), UNSHADED.run() + n * 12);
        // A node whose fragment costs more (none today) makes runs keep whole fragments.
        let whole = StepCosts { frag: 1, ..deferred };
        assert!(!whole.keyed());
        assert_eq!(whole.run(), (LLVMPIPE_SWEEP.load as u64 + 1) * (n + 1) + StepCosts::sort_keys(n) + n * (2 + 1 + 12));
    }

    #[test]
    fn the_array_is_the_smallest_power_of_two_that_holds_the_deepest_list() {
        assert_eq!(run_length(1), BLOCK as u32);
        assert_eq!(run_length(9), 16);
        assert_eq!(run_length(46), 64);
        assert_eq!(run_length(128), 128);
        assert_eq!(run_length(388), RUN);
    }
}
