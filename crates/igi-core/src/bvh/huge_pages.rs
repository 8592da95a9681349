//! Transparent huge pages for the build's large buffers (Linux), so that a build in a new
//! process (what `igi render` pays) maps its fresh memory 2 MiB at a time instead of
//! 4 KiB at a time. Not part of the paper: its acceleration structure was built by OptiX;
//! this serves the build target of docs/PERFORMANCE.md (attempt 128).
//!
//! The build asks with `madvise(MADV_HUGEPAGE)` for the 2 MiB-aligned inside of each
//! large buffer before it first writes it. Where the kernel's `defrag` setting is
//! `madvise` (the default), such a region may make a page fault wait for the kernel to
//! compact memory when no free 2 MiB block is left: attempt 113 measured 198-273 ms
//! stalls then. So the build asks only while the kernel has free blocks of 2 MiB or more
//! to spare ([`HugePages::free_now`], from `/proc/buddyinfo`): at most half of them, so
//! that its own faults find blocks without compaction. Advice changes where memory comes
//! from, never what is in it: the tree is the same.

use std::mem::MaybeUninit;

/// The size of a transparent huge page on x86-64 and on most arm64 kernels.
pub(super) const HUGE_PAGE: usize = 2 << 20;

/// How many more 2 MiB pages the build may ask for (see the module's doc).
#[derive(Debug)]
pub(super) struct HugePages {
    budget: usize,
    /// Bytes advised so far.
    advised: usize,
}

impl HugePages {
    /// A budget of half the free blocks of 2 MiB (or larger) that the kernel reports now;
    /// none where it reports none, or off Linux.
    pub(super) fn free_now() -> HugePages {
        let free = if cfg!(target_os = "linux") {
            std::fs::read_to_string("/proc/buddyinfo")
                .map(|text| free_huge_blocks(&text))
                .unwrap_or(0)
        } else {
            0
        };
        HugePages {
            budget: free / 2,
            advised: 0,
        }
    }

    /// A budget of nothing: no advice (tests of the build's parts).
    #[cfg(test)]
    pub(super) fn none() -> HugePages {
        HugePages {
            budget: 0,
            advised: 0,
        }
    }

    /// Bytes advised so far ([`super::BuildStats::huge_page_bytes`]).
    pub(super) fn advised_bytes(&self) -> usize {
        self.advised
    }

    /// Asks for huge pages over the aligned inside of `buf` (memory not yet written, so
    /// that its first writes map it 2 MiB at a time), if the budget still holds them.
    pub(super) fn advise<T>(&mut self, buf: &[MaybeUninit<T>]) {
        let start = buf.as_ptr() as usize;
        let Some((lo, len)) = huge_span(start, std::mem::size_of_val(buf)) else {
            return;
        };
        let pages = len / HUGE_PAGE;
        if pages > self.budget {
            return;
        }
        self.budget -= pages;
        self.advised += len;
        #[cfg(target_os = "linux")]
        // SAFETY: advice on whole pages inside `buf`'s allocation, which the caller owns;
        // MADV_HUGEPAGE changes how its pages are mapped, not their contents or validity.
        // A kernel without transparent huge pages answers EINVAL, which changes nothing.
        unsafe {
            libc::madvise(lo as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
        }
        #[cfg(not(target_os = "linux"))]
        let _ = lo;
    }
}

/// The 2 MiB-aligned span (start, length) inside `len` bytes from `start`, if there is
/// one.
pub(super) fn huge_span(start: usize, len: usize) -> Option<(usize, usize)> {
    let lo = start.checked_next_multiple_of(HUGE_PAGE)?;
    let hi = start.checked_add(len)? / HUGE_PAGE * HUGE_PAGE;
    (hi > lo).then(|| (lo, hi - lo))
}

/// Free blocks of 2 MiB in `/proc/buddyinfo`'s text (a zone per line: its free block
/// counts of order 0, 1, ... after the zone's name; a block of order k is 2^k pages of
/// 4 KiB, so order 9 is 2 MiB and order 10 two of them). Lines it cannot read count
/// nothing.
pub(super) fn free_huge_blocks(buddyinfo: &str) -> usize {
    const ORDER: usize = 9; // 2^9 pages of 4 KiB = 2 MiB
    buddyinfo
        .lines()
        .map(|line| {
            let Some((_, counts)) = line.split_once("zone") else {
                return 0;
            };
            counts
                .split_whitespace()
                .skip(1) // the zone's name
                .enumerate()
                .skip(ORDER)
                .map(|(order, count)| {
                    count.parse::<usize>().unwrap_or(0) << (order - ORDER).min(16)
                })
                .sum::<usize>()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_span_is_the_aligned_inside() {
        const H: usize = HUGE_PAGE;
        assert_eq!(huge_span(0, 2 * H), Some((0, 2 * H)));
        assert_eq!(huge_span(H + 1, 3 * H), Some((2 * H, 2 * H)));
        assert_eq!(huge_span(H - 4096, H + 8192), Some((H, H)));
        // No whole aligned page inside.
        assert_eq!(huge_span(H + 1, 2 * H - 2), None);
        assert_eq!(huge_span(4096, H), None);
        assert_eq!(huge_span(0, 0), None);
        assert_eq!(huge_span(usize::MAX - 10, 5), None);
    }

    #[test]
    fn free_blocks_of_2_mib_are_counted_from_order_9() {
        let text = "\
Node 0, zone      DMA      0      0      0      0      0      0      0      0      1      1      3 
Node 0, zone    DMA32      1      1      4      2      5      4      3      3      4      2    752 
Node 0, zone   Normal   9368   7228   4695   3026   1810   1097    664    388    190    190   3340 
";
        // Order 9 counts once, order 10 twice: (1 + 6) + (2 + 1504) + (190 + 6680).
        assert_eq!(free_huge_blocks(text), 8383);
        // Fewer orders (a kernel with a smaller largest order), text it cannot read.
        assert_eq!(
            free_huge_blocks("Node 0, zone Normal 1 2 3 4 5 6 7 8 9 5\n"),
            5
        );
        assert_eq!(free_huge_blocks("Node 0, zone Normal 1 2 3\n"), 0);
        assert_eq!(free_huge_blocks("no zones here\n"), 0);
        assert_eq!(
            free_huge_blocks("Node 0, zone Normal 0 0 0 0 0 0 0 0 0 x 4\n"),
            8
        );
    }

    #[test]
    fn advice_is_given_only_within_the_budget() {
        // 10 MiB holds at least four aligned 2 MiB pages wherever it starts.
        let buf: Box<[MaybeUninit<u8>]> = Box::new_uninit_slice(5 * HUGE_PAGE);
        let (_, len) = huge_span(buf.as_ptr() as usize, buf.len()).expect("an aligned span");
        let pages = len / HUGE_PAGE;
        assert!(pages >= 4);
        let mut small = HugePages {
            budget: pages - 1,
            advised: 0,
        };
        small.advise(&buf);
        assert_eq!(small.budget, pages - 1, "advice beyond the budget");
        assert_eq!(small.advised_bytes(), 0);
        let mut enough = HugePages {
            budget: pages + 3,
            advised: 0,
        };
        enough.advise(&buf);
        assert_eq!(enough.budget, 3);
        assert_eq!(enough.advised_bytes(), len);
        // A buffer smaller than a huge page takes nothing from the budget.
        let tiny: Box<[MaybeUninit<u8>]> = Box::new_uninit_slice(4096);
        enough.advise(&tiny);
        assert_eq!(enough.budget, 3);
        assert_eq!(enough.advised_bytes(), len);
    }
}
