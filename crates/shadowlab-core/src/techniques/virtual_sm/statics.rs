//! Static copies of `virtual`'s pages (UE5's static/dynamic split): a page that moving geometry
//! covers keeps a second copy holding only its static geometry, in a separate, smaller pool.
//! When the moving geometry sweeps over the page again, the page is rebuilt from that copy plus
//! the moving chunks alone ("refreshed") instead of drawing all its static geometry again.
//! The static content of a page never goes stale here (the light never moves and static
//! geometry never changes), so a copy is only ever evicted for room.
//!
//! Per frame, for each page the frame renders (in the allocation's priority order):
//! - it has a copy: `Copy` (the page is the copy plus the moving chunks);
//! - it has none and moving geometry covers it: `Fill` with a slot, if one is free or held by a
//!   copy no page of this frame uses (least recently used first; ties: page order); the copy
//!   is drawn first (static chunks), then the page from it;
//! - otherwise `Full`: the page drawn whole, as without copies.
//!
//! Deterministic: the outcome depends only on the pages rendered, the predicate and the history.

use std::collections::{BTreeMap, BTreeSet};

use super::alloc::PageKey;

/// How one rendered page is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Build {
    /// Drawn whole (cleared, every chunk over it).
    Full,
    /// Its static copy is drawn into `slot` of the static pool first (static chunks), then the
    /// page is built from it as for `Copy`.
    Fill(u32),
    /// Built from the resident static copy in `slot` plus the moving chunks over it.
    Copy(u32),
}

/// The static pool: which pages have a copy, in which slot, last used when.
#[derive(Clone, Debug)]
pub struct StaticCopies {
    slots: u32,
    resident: BTreeMap<PageKey, (u32, u64)>,
    frame: u64,
}

impl StaticCopies {
    pub fn new(slots: u32) -> StaticCopies {
        StaticCopies { slots, resident: BTreeMap::new(), frame: 0 }
    }

    pub fn slots(&self) -> u32 {
        self.slots
    }

    /// Pages with a resident static copy.
    pub fn resident(&self) -> usize {
        self.resident.len()
    }

    pub fn has_copy(&self, k: &PageKey) -> bool {
        self.resident.contains_key(k)
    }

    /// How each page of `render` (one frame's rendered pages, in order) is built; `moving`
    /// says whether moving geometry covers a page now (only those get a new copy).
    pub fn assign(&mut self, render: &[PageKey], mut moving: impl FnMut(&PageKey) -> bool) -> Vec<Build> {
        self.frame += 1;
        let frame = self.frame;
        let in_use: BTreeSet<PageKey> = render.iter().filter(|k| self.resident.contains_key(k)).copied().collect();
        let used: BTreeSet<u32> = self.resident.values().map(|v| v.0).collect();
        let mut free: Vec<u32> = (0..self.slots).filter(|s| !used.contains(s)).rev().collect();
        let mut evictable: Vec<(u64, PageKey, u32)> =
            self.resident.iter().filter(|(k, _)| !in_use.contains(k)).map(|(k, &(s, f))| (f, *k, s)).collect();
        evictable.sort();
        let mut evict = evictable.into_iter();
        render
            .iter()
            .map(|k| {
                if let Some(v) = self.resident.get_mut(k) {
                    v.1 = frame;
                    return Build::Copy(v.0);
                }
                if !moving(k) {
                    return Build::Full;
                }
                let slot = match free.pop() {
                    Some(s) => s,
                    None => match evict.next() {
                        Some((_, old, s)) => {
                            self.resident.remove(&old);
                            s
                        }
                        None => return Build::Full,
                    },
                };
                self.resident.insert(*k, (slot, frame));
                Build::Fill(slot)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(x: i32) -> PageKey {
        PageKey { level: 0, x, y: 0 }
    }

    #[test]
    fn moving_pages_get_a_copy_and_reuse_it() {
        let mut s = StaticCopies::new(2);
        let pages = [key(0), key(1), key(2)];
        // pages 0 and 2 are under moving geometry
        let first = s.assign(&pages, |k| k.x != 1);
        assert_eq!(first, vec![Build::Fill(0), Build::Full, Build::Fill(1)]);
        // the moving geometry swept over 0 and 2 again: both rebuilt from their copies
        assert_eq!(s.assign(&[key(0), key(2)], |_| true), vec![Build::Copy(0), Build::Copy(1)]);
        assert_eq!(s.resident(), 2);
    }

    #[test]
    fn a_full_pool_evicts_the_least_recently_used_copy_not_in_use() {
        let mut s = StaticCopies::new(2);
        s.assign(&[key(0)], |_| true); // frame 1: copy of 0 in slot 0
        s.assign(&[key(1)], |_| true); // frame 2: copy of 1 in slot 1
                                       // frame 3: 1 uses its copy; 5 is new and takes 0's slot (0 is older and unused)
        assert_eq!(s.assign(&[key(1), key(5)], |_| true), vec![Build::Copy(1), Build::Fill(0)]);
        assert!(!s.has_copy(&key(0)) && s.has_copy(&key(5)));
        // frame 4: both copies in use, a third moving page is drawn whole
        assert_eq!(s.assign(&[key(1), key(5), key(7)], |_| true), vec![Build::Copy(1), Build::Copy(0), Build::Full]);
    }

    #[test]
    fn an_empty_pool_draws_everything_whole() {
        let mut s = StaticCopies::new(0);
        assert_eq!(s.assign(&[key(0), key(1)], |_| true), vec![Build::Full, Build::Full]);
    }
}
