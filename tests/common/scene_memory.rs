//! What the memory tests of the planning scene read: a process's resident bytes, and the bytes of
//! the cells and trees a pipeline's scene holds.

use thickness_collision::pipeline::Pipeline;
use thickness_collision::thickness::ThicknessCell;

/// Resident bytes of process `pid` (`"self"` for this one), 0 when unknown.
pub fn resident_bytes(pid: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status.lines().find(|l| l.starts_with("VmRSS:")).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse::<u64>().ok()).unwrap_or(0) * 1024
}

/// Bytes of the cells and trees of the scene's thin surfaces (each object's own).
pub fn cells_bytes(p: &Pipeline) -> u64 {
    p.checker()
        .scene()
        .objects()
        .iter()
        .map(|o| o.area().map_or(0, |a| a.cells.capacity() * std::mem::size_of::<ThicknessCell>()) + o.bvh_memory())
        .sum::<usize>() as u64
}
