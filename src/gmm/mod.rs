//! The Galerkin meshfree method (GMM) of the implicit-MPM paper (§4.2,
//! Algorithm 2): a discretisation beside the grid. Its nodes are a cloud
//! that belongs to the body and moves with it (`cloud`); each step every
//! material point gathers the nodes within the search radius and
//! evaluates a meshfree basis over them (`basis`: LME or MLS). The step
//! itself is the implicit MPM's Newton step (`cpu::implicit`), run over
//! the cloud's nodes instead of the grid's: Newmark's predictor reads the
//! nodes' own velocity and acceleration, and after convergence nodes and
//! material points move with the nodal solution.
//!
//! This module holds what is backend-neutral (the cloud, its neighbour
//! search, the bases); it imports the model layer only.

pub mod basis;
pub mod cloud;

pub use basis::Basis;
pub use cloud::Cloud;
