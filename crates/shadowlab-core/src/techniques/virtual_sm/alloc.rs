//! The physical page pool of `virtual`: which requested pages get a slot this frame, which keep
//! the slot (and content) they had, which are rendered, and which fall back to a coarser level
//! when the pool is full. Deterministic: the outcome depends only on the requested set and the
//! cache's history, never on the order the GPU marked pages in.
//!
//! Priority: coarser levels first; inside a level, the pages more view samples would read first
//! ([`Demand`]), then row-major (y, x) page order; the first `slots` requested pages in that
//! order get a slot, the rest fall back (their samples use the nearest coarser level whose pages
//! are mapped). A requested page still resident (rendered in
//! an earlier frame and not invalidated since) keeps its slot and is not rendered again. New
//! pages take free slots in ascending order, then evict the resident pages not requested this
//! frame, least recently requested first (ties: page order).

use std::collections::BTreeMap;

/// A page of one level, by its global page coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PageKey {
    pub level: u32,
    pub x: i32,
    pub y: i32,
}

impl PageKey {
    /// Page order (the priority order without sample counts): coarser level first, then (y, x).
    fn priority(&self) -> (std::cmp::Reverse<u32>, i32, i32) {
        (std::cmp::Reverse(self.level), self.y, self.x)
    }
}

impl PartialOrd for PageKey {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for PageKey {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.priority().cmp(&other.priority())
    }
}

/// View samples per page: how many samples chose each page at their own level (mark.wgsl
/// counts the page under each sample), added up the chain of coarser levels of the same face,
/// so that a coarser page counts the samples that read it when their finer pages fall back.
/// Exact integer sums: the same for any marking order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Demand(BTreeMap<PageKey, u64>);

impl Demand {
    /// From `(page, samples)` at the samples' own levels; `levels` level indices in all, `step`
    /// from a level to the next coarser one of its face (`Clipmap::faces()`).
    pub fn up_the_chain(counts: &[(PageKey, u32)], levels: u32, step: u32) -> Demand {
        let mut d = BTreeMap::new();
        for &(k, n) in counts {
            let mut p = k;
            loop {
                *d.entry(p).or_insert(0) += n as u64;
                if p.level + step >= levels {
                    break;
                }
                p = PageKey { level: p.level + step, x: p.x.div_euclid(2), y: p.y.div_euclid(2) };
            }
        }
        Demand(d)
    }

    /// Samples that would read page `k` (0 if none counted).
    pub fn of(&self, k: &PageKey) -> u64 {
        self.0.get(k).copied().unwrap_or(0)
    }

    /// Sorts `pages` into priority order: coarser level first, then more samples, then (y, x).
    /// Without counts this is [`PageKey`]'s order.
    pub fn sort(&self, pages: &mut [PageKey]) {
        pages.sort_by_key(|k| (std::cmp::Reverse(k.level), std::cmp::Reverse(self.of(k)), k.y, k.x));
    }
}

/// The requested pages plus the fallback pages a full pool needs: while the first `slots`
/// pages in priority order leave some requested pages out, each left-out page of level k adds
/// the `candidates` of level k + `step` (one level coarser: `Clipmap::faces()`, 1 unless a
/// cube) within one page of its parent (the pages its samples would read one level coarser:
/// mark.wgsl flags them as candidates), until nothing more is added. Without a full pool this
/// is `requested`. In `demand`'s priority order, without duplicates.
pub fn with_fallbacks(requested: &[PageKey], candidates: &[PageKey], slots: usize, step: u32, demand: &Demand) -> Vec<PageKey> {
    let mut req: Vec<PageKey> = requested.to_vec();
    req.sort();
    req.dedup();
    demand.sort(&mut req);
    let mut pending: std::collections::BTreeSet<PageKey> = candidates.iter().copied().collect();
    for k in &req {
        pending.remove(k);
    }
    let mut done_from = slots;
    while req.len() > slots && !pending.is_empty() {
        // parents (with their neighbours) of the pages left out
        let wanted: std::collections::BTreeSet<(u32, i32, i32)> = req[slots.min(done_from)..]
            .iter()
            .flat_map(|f| {
                let (px, py) = (f.x.div_euclid(2), f.y.div_euclid(2));
                (-1..=1).flat_map(move |dy| (-1..=1).map(move |dx| (f.level + step, px + dx, py + dy)))
            })
            .collect();
        let add: Vec<PageKey> = pending.iter().filter(|c| wanted.contains(&(c.level, c.x, c.y))).copied().collect();
        if add.is_empty() {
            break;
        }
        for a in &add {
            pending.remove(a);
        }
        req.extend(add);
        demand.sort(&mut req);
        done_from = slots;
    }
    req
}

/// One frame's outcome.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Allocation {
    /// Every requested page that has a slot, with the slot, in priority order.
    pub mapped: Vec<(PageKey, u32)>,
    /// The mapped pages to render this frame (not resident before), in priority order.
    pub render: Vec<(PageKey, u32)>,
    /// Requested pages that were resident and valid: not rendered again.
    pub cached: usize,
    /// Requested pages without a slot (pool full), in priority order.
    pub fallen_back: Vec<PageKey>,
}

/// The pool's slots and the pages they hold across frames.
#[derive(Clone, Debug)]
pub struct PageCache {
    slots: u32,
    /// Resident pages: slot and the frame they were last requested in.
    resident: BTreeMap<PageKey, (u32, u64)>,
    frame: u64,
}

impl PageCache {
    pub fn new(slots: u32) -> PageCache {
        PageCache { slots, resident: BTreeMap::new(), frame: 0 }
    }

    pub fn slots(&self) -> u32 {
        self.slots
    }

    /// Pages whose content is kept.
    pub fn resident(&self) -> usize {
        self.resident.len()
    }

    pub fn is_resident(&self, k: &PageKey) -> bool {
        self.resident.contains_key(k)
    }

    /// Forgets every page (the light moved, or the geometry changed everywhere).
    pub fn clear(&mut self) {
        self.resident.clear();
    }

    /// Forgets the pages in `keys` (their content is stale); returns how many were resident.
    pub fn invalidate<'a>(&mut self, keys: impl IntoIterator<Item = &'a PageKey>) -> usize {
        keys.into_iter().filter(|k| self.resident.remove(k).is_some()).count()
    }

    /// Forgets the resident pages for which `stale` holds; returns how many.
    pub fn invalidate_if(&mut self, mut stale: impl FnMut(&PageKey) -> bool) -> usize {
        let before = self.resident.len();
        self.resident.retain(|k, _| !stale(k));
        before - self.resident.len()
    }

    /// The resident pages, in [`PageKey`] order.
    pub fn resident_pages(&self) -> impl Iterator<Item = &PageKey> {
        self.resident.keys()
    }

    /// Assigns slots to `requested` (any order, duplicates allowed) for a new frame, in
    /// [`PageKey`] order (no sample counts).
    pub fn allocate(&mut self, requested: &[PageKey]) -> Allocation {
        self.allocate_by(requested, &Demand::default())
    }

    /// Assigns slots to `requested` in `demand`'s priority order.
    pub fn allocate_by(&mut self, requested: &[PageKey], demand: &Demand) -> Allocation {
        self.frame += 1;
        let mut req: Vec<PageKey> = requested.to_vec();
        req.sort();
        req.dedup();
        demand.sort(&mut req);
        let n = (self.slots as usize).min(req.len());
        let (chosen, rest) = req.split_at(n);
        let chosen_set: std::collections::BTreeSet<PageKey> = chosen.iter().copied().collect();
        // slots for new pages: free ones ascending, then evictions (least recently requested)
        let used: std::collections::BTreeSet<u32> = self.resident.values().map(|v| v.0).collect();
        let mut evictable: Vec<(u64, PageKey, u32)> =
            self.resident.iter().filter(|(k, _)| !chosen_set.contains(k)).map(|(k, &(s, f))| (f, *k, s)).collect();
        evictable.sort();
        let mut free = (0..self.slots).filter(|s| !used.contains(s)).chain(evictable.iter().map(|e| e.2));
        let mut evict = evictable.iter();
        let mut out = Allocation { fallen_back: rest.to_vec(), ..Default::default() };
        let mut free_left = self.slots as usize - used.len();
        for &k in chosen {
            if let Some(v) = self.resident.get_mut(&k) {
                v.1 = self.frame;
                out.cached += 1;
                out.mapped.push((k, v.0));
                continue;
            }
            let s = free.next().expect("at most `slots` pages are chosen");
            if free_left > 0 {
                free_left -= 1;
            } else {
                let e = evict.next().expect("an evicted page per taken slot");
                self.resident.remove(&e.1);
            }
            self.resident.insert(k, (s, self.frame));
            out.mapped.push((k, s));
            out.render.push((k, s));
        }
        out
    }
}
