//! Why a particle's shape functions could not be evaluated (outside the
//! grid, or an LME solve that failed); shared by every shape, so each
//! shape's file names it without naming `shape/mod.rs`.

/// Why a shape function could not be evaluated at a particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeFault {
    /// The particle is outside the part of the grid where the shape function is defined.
    OutsideGrid,
    /// LME: fewer than 3 nodes inside the support radius (how many, when known).
    LmeTooFewNodes { nodes: Option<usize> },
    /// LME: Newton on λ did not reach the tolerance within the iteration cap
    /// (the residual |r|/h, when known).
    LmeNotConverged {
        iterations: u32,
        residual: Option<f64>,
    },
    /// LME: the Hessian J became singular (the particle is on or outside the nodes' hull).
    LmeSingular { iterations: u32 },
    /// GMM-MLS: the moment matrix of the particle's node cloud is singular
    /// (fewer than 3 nodes with weight, or all on a line).
    MlsSingular { nodes: usize },
}

impl std::fmt::Display for ShapeFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ShapeFault::OutsideGrid => write!(f, "particle left the grid"),
            ShapeFault::LmeTooFewNodes { nodes: Some(n) } => {
                write!(f, "LME support holds only {n} node(s); 3 are needed")
            }
            ShapeFault::LmeTooFewNodes { nodes: None } => {
                write!(f, "LME support holds fewer than 3 nodes")
            }
            ShapeFault::LmeNotConverged {
                iterations,
                residual: Some(r),
            } => write!(
                f,
                "LME Newton did not converge in {iterations} iterations (|r| = {r:.3e} of h)"
            ),
            ShapeFault::LmeNotConverged {
                iterations,
                residual: None,
            } => {
                write!(f, "LME Newton did not converge in {iterations} iterations")
            }
            ShapeFault::MlsSingular { nodes } => write!(
                f,
                "MLS moment matrix singular over a cloud of {nodes} weighted node(s)"
            ),
            ShapeFault::LmeSingular { iterations } => {
                write!(
                    f,
                    "LME Newton: Hessian J singular after {iterations} iterations"
                )
            }
        }
    }
}
