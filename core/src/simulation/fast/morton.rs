//! The order the fast solver numbers particles in: along a Morton (Z-order) curve, so that
//! particles close in space are close in memory.

use glam::DVec3;

/// The particles sorted along a Morton (Z-order) curve through their bounding box: new number →
/// old number. Deterministic; ties keep the old order.
pub(crate) fn morton_order(positions: &[DVec3]) -> Vec<u32> {
    let (lo, hi) = crate::scene::mesh::bounds(positions);
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let code = |p: DVec3| -> u64 {
        let cell = ((p - lo) / extent * 1023.0).clamp(DVec3::ZERO, DVec3::splat(1023.0));
        let spread = |v: f64| -> u64 {
            let mut x = v as u64 & 0x3ff;
            x = (x | (x << 16)) & 0x0300_00ff;
            x = (x | (x << 8)) & 0x0300_f00f;
            x = (x | (x << 4)) & 0x030c_30c3;
            (x | (x << 2)) & 0x0924_9249
        };
        spread(cell.x) | (spread(cell.y) << 1) | (spread(cell.z) << 2)
    };
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_by_key(|&i| code(positions[i as usize]));
    order
}
