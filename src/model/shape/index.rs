//! Cell indices from positions, shared by the shape functions (a leaf:
//! the shapes name it, not `shape/mod.rs`, which names them).

/// `v.floor() as i64`, by truncation where `v` is not negative (a point
/// inside the grid): `floor` is a library call in baseline x86-64 code.
#[inline(always)]
pub fn floor_i64(v: f64) -> i64 {
    if v >= 0.0 { v as i64 } else { v.floor() as i64 }
}
