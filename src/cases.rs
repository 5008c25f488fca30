//! The scene files in `cases/`, compiled into the binary so studies run
//! from any folder. Each is also an ordinary file users can copy and edit.

pub const DYKA_BAR: &str = include_str!("../cases/dyka_bar.toml");
pub const ELASTIC_BLOCK: &str = include_str!("../cases/elastic_block.toml");
pub const PLATE_IMPACT: &str = include_str!("../cases/plate_impact.toml");
pub const ALIGNED_VIBRATION: &str = include_str!("../cases/aligned_vibration.toml");
pub const ROLLING_DISK: &str = include_str!("../cases/rolling_disk.toml");
pub const COLUMN_COLLAPSE: &str = include_str!("../cases/column_collapse.toml");
pub const GRANULAR_COLLAPSE: &str = include_str!("../cases/granular_collapse.toml");
pub const CANTILEVER: &str = include_str!("../cases/cantilever.toml");
pub const CLAY_BIAXIAL: &str = include_str!("../cases/clay_biaxial.toml");
pub const CONTACT_BLOCK: &str = include_str!("../cases/contact_block.toml");
pub const CONTACT_DISKS: &str = include_str!("../cases/contact_disks.toml");
pub const CONTACT_ROLLING: &str = include_str!("../cases/contact_rolling.toml");
pub const FOOTING: &str = include_str!("../cases/footing.toml");
pub const TERZAGHI: &str = include_str!("../cases/terzaghi.toml");
pub const MANDEL: &str = include_str!("../cases/mandel.toml");

/// The cohesionless case for shape `shape`: its `bspline_knots` line
/// (which only B-splines accept) dropped for the other shapes.
pub fn granular_case(shape: &str) -> std::borrow::Cow<'static, str> {
    if shape.starts_with("bspline") {
        GRANULAR_COLLAPSE.into()
    } else {
        GRANULAR_COLLAPSE
            .lines()
            .filter(|l| !l.trim_start().starts_with("bspline_knots"))
            .collect::<Vec<_>>()
            .join("\n")
            .into()
    }
}

/// Dyka's bar length (m), as in `cases/dyka_bar.toml`.
pub const DYKA_L: f64 = 0.1333;
