//! Giving freed memory back to the system. glibc's malloc keeps what a burst freed (a 10,000-state
//! burst, a refused 10 MB joint state) in its arenas, so the node's resident size stays at its
//! high-water mark, and the next large message (a 50 MB description, refused) lands on top of it:
//! `tests/node_robustness.rs` measured that stacking as the one way past the bound of
//! start + 50 MiB + the largest message. `malloc_trim` returns the free pages, but walks every
//! arena, so it runs only when the resident size grew by [`GROWTH`] since it last ran: never in a
//! steady stream, once after a burst.

/// Resident growth past which freed memory is handed back.
const GROWTH: u64 = 16 << 20;

/// Resident size at the last trim (or at start).
pub(super) struct MemoryReturn {
    baseline: u64,
}

impl MemoryReturn {
    /// Starts measuring growth from the resident size now. The node also fixes the allocator's
    /// thresholds first ([`fix_allocator_thresholds`]), or freed blocks may stay where no trim
    /// reaches them.
    pub(super) fn new() -> MemoryReturn {
        MemoryReturn { baseline: resident_bytes().unwrap_or(0) }
    }

    /// Called from the loop's housekeeping; returns the bytes handed back, if it trimmed.
    pub(super) fn tick(&mut self) -> Option<u64> {
        let now = resident_bytes()?;
        if now < self.baseline.saturating_add(GROWTH) {
            // A shrink lowers the mark, so growth is measured from the lowest point since.
            self.baseline = self.baseline.min(now);
            return None;
        }
        trim();
        let after = resident_bytes().unwrap_or(now);
        self.baseline = after;
        Some(now.saturating_sub(after))
    }
}

/// `VmRSS` of this process, from `/proc/self/statm` (pages).
fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    Some(pages * u64::try_from(page).ok().filter(|p| *p > 0)?)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn trim() {
    // SAFETY: malloc_trim only releases free memory; it takes the arenas' own locks.
    let _ = unsafe { libc::malloc_trim(0) };
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn trim() {}

/// glibc raises its mmap threshold to the size of every mmap'd block freed (up to 32 MiB), and
/// its trim threshold to twice that: after one refused 10 MB joint state, blocks up to 10 MB come
/// from the arenas and up to 20 MB of free space at an arena's top is kept, where `malloc_trim`
/// does not reach it (it trims only the main arena's top). Fixed thresholds keep large blocks
/// in mmaps of their own, given back when freed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub(super) fn fix_allocator_thresholds() {
    // SAFETY: mallopt only sets the allocator's tunables; called before the node's threads
    // allocate much, and safe at any time.
    unsafe {
        let _ = libc::mallopt(libc::M_MMAP_THRESHOLD, 256 << 10);
        let _ = libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 20);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub(super) fn fix_allocator_thresholds() {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_freed_burst_is_handed_back() {
        // As the node starts.
        fix_allocator_thresholds();
        let mut m = MemoryReturn::new();
        let before = resident_bytes().expect("statm");
        // Blocks below glibc's mmap threshold (so they live in an arena), touched, each followed
        // by a small one that stays: the freed blocks are holes in the middle of the heap, which
        // glibc keeps until trimmed (a free at the top would be returned on its own).
        let mut blocks = Vec::new();
        let mut pins = Vec::new();
        // 256 MiB: the other unit tests run beside this one in the same process, and their own
        // memory moves the resident size by tens of MiB.
        for _ in 0..8192 {
            blocks.push(vec![1u8; 32 << 10]);
            pins.push(vec![1u8; 64]);
        }
        let grown = resident_bytes().expect("statm");
        assert!(grown >= before + (192 << 20), "the burst did not show in the resident size: {before} -> {grown}");
        drop(blocks);
        let kept = resident_bytes().expect("statm");
        let returned = m.tick().expect("a trim after 256 MiB of growth");
        let after = resident_bytes().expect("statm");
        assert!(after + (128 << 20) < kept, "resident {kept} -> {after} after the trim ({returned} bytes returned)");
        drop(pins);
    }
}
