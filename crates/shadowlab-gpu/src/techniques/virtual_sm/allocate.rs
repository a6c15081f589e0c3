//! `virtual`'s pages on the CPU, `prepare`'s half after the readback: the resident pages a
//! moving chunk swept over dropped, the requested pages (with fallbacks where a full pool
//! leaves fine pages out) allocated in priority order, the page table and the rendered pages'
//! view-projections, and which pages are built from a static copy.

use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{with_fallbacks, Allocation, Build, Clipmap, Demand, PageCache, PageKey, StaticCopies};

use super::draw::{moving_over, Chunks};
use super::setup::Setup;

/// The pages' state across frames, and the last frame's counters (the report's).
pub(super) struct Pages {
    /// The clipmap of the last frame.
    pub clipmap: Option<Clipmap>,
    pub cache: PageCache,
    pub alloc: Allocation,
    /// Requested pages of the last frame (priority order).
    pub requested: Vec<PageKey>,
    /// The static copies (UE5's static/dynamic split) and how each rendered page of the last
    /// frame was built (`alloc.render`'s order).
    pub statics: StaticCopies,
    pub builds: Vec<Build>,
    pub frames: u64,
    pub rendered_total: u64,
    pub invalidated: usize,
    /// Fallback pages (one level coarser) the last frame added for pages a full pool left out.
    pub fallback_added: usize,
    pub invalidated_total: u64,
    /// Triangles the last frame drew into pages (static pool and atlas).
    pub triangles_drawn: u64,
}

/// What the allocation writes to the GPU: the page table (slot + 1 per entry, 0 unmapped), the
/// rendered pages' view-projections, and their static copies' offsets (copy.wgsl).
pub(super) struct PageWrites {
    pub table: Vec<u32>,
    pub mats: Vec<[[f32; 4]; 4]>,
    pub offsets: Vec<[i32; 4]>,
}

impl Pages {
    pub fn new(s: &Setup) -> Pages {
        let p = &s.pool;
        Pages {
            clipmap: None,
            cache: PageCache::new(p.cols * p.rows),
            alloc: Allocation::default(),
            requested: Vec::new(),
            statics: StaticCopies::new(p.static_cols * p.static_rows),
            builds: Vec::new(),
            frames: 0,
            rendered_total: 0,
            invalidated: 0,
            fallback_added: 0,
            invalidated_total: 0,
            triangles_drawn: 0,
        }
    }

    /// Drops the resident pages of clipmap `c` under each `swept` box (a moving chunk's old and
    /// new box).
    pub fn invalidate_swept(&mut self, c: &Clipmap, swept: &[Bounds]) {
        self.invalidated = 0;
        for b in swept {
            self.invalidated += self.cache.invalidate_if(|k| c.page_overlaps(k, b));
        }
        self.invalidated_total += self.invalidated as u64;
    }

    /// Allocates the pages `flags` (mark.wgsl's, per page-table entry of `c`) request and
    /// assigns the static copies; returns what to write.
    pub fn allocate(&mut self, s: &Setup, c: &Clipmap, flags: &[u32], chunks: &Chunks) -> PageWrites {
        // mark.wgsl: flags in bits 0-1 (1 requested, 2 a fallback candidate), samples above
        let pages = |keep: fn(u32) -> bool| -> Vec<PageKey> {
            flags.iter().enumerate().filter(|(_, f)| keep(**f)).map(|(i, _)| c.key_of_index(i)).collect()
        };
        let mut req = pages(|f| f & 1 != 0);
        req.sort();
        let cand = pages(|f| f & 3 == 2);
        let counts: Vec<(PageKey, u32)> =
            flags.iter().enumerate().filter(|(_, f)| **f >> 2 != 0).map(|(i, f)| (c.key_of_index(i), f >> 2)).collect();
        let demand = Demand::up_the_chain(&counts, c.levels, s.faces);
        let all = with_fallbacks(&req, &cand, self.cache.slots() as usize, s.faces, &demand);
        self.fallback_added = all.len() - req.len();
        self.alloc = self.cache.allocate_by(&all, &demand);
        self.requested = req;
        let mut table = vec![0u32; c.table_len()];
        for (k, slot) in &self.alloc.mapped {
            table[c.table_index(k.level, glam::IVec2::new(k.x, k.y))] = slot + 1;
        }
        let mats = self.alloc.render.iter().map(|(k, _)| c.page_view_proj(*k).to_cols_array_2d()).collect();
        let keys: Vec<PageKey> = self.alloc.render.iter().map(|(k, _)| *k).collect();
        self.builds = self.statics.assign(&keys, |k| moving_over(&chunks.list, chunks.moving0, c, k));
        PageWrites { table, mats, offsets: self.copy_offsets(s) }
    }

    /// Per rendered page: its static slot's origin minus its atlas slot's (texels; 0 drawn whole).
    fn copy_offsets(&self, s: &Setup) -> Vec<[i32; 4]> {
        let pr = s.page_res as i32;
        self.alloc
            .render
            .iter()
            .zip(&self.builds)
            .map(|((_, slot), b)| match b {
                Build::Fill(st) | Build::Copy(st) => {
                    let (sc, c) = (s.pool.static_cols, s.pool.cols);
                    [((st % sc) as i32 - (slot % c) as i32) * pr, ((st / sc) as i32 - (slot / c) as i32) * pr, 0, 0]
                }
                Build::Full => [0; 4],
            })
            .collect()
    }

    /// The frame is allocated: `c` becomes the last frame's clipmap.
    pub fn finish(&mut self, c: Clipmap) {
        self.clipmap = Some(c);
        self.frames += 1;
        self.rendered_total += self.alloc.render.len() as u64;
    }

    /// Forgets the pages over world box `b` at each of `levels`; returns how many resident
    /// pages were dropped.
    pub fn invalidate_box(&mut self, levels: u32, b: &Bounds) -> usize {
        let Some(c) = &self.clipmap else { return 0 };
        let keys: Vec<PageKey> = (0..levels).flat_map(|k| c.pages_touching(k, b)).collect();
        self.cache.invalidate(&keys)
    }
}
