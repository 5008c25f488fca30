//! What every CPU stage reads besides the model: the particles' shape
//! functions for the step (`ShapeCache`) and the body force per unit mass
//! (`body_force`). A leaf, so the stage files name it and not the backend
//! (`cpu/mod.rs`) that calls them.

/// N and ∇N of every particle for the current step: `stride` slots per
/// particle, `count[p]` of them used.
#[derive(Debug, Clone)]
pub struct ShapeCache {
    pub stride: usize,
    pub count: Vec<u16>,
    pub nodes: Vec<u32>,
    /// [N, ∂N/∂x, ∂N/∂y] per slot.
    pub w: Vec<[f64; 3]>,
}

impl ShapeCache {
    pub fn new(particles: usize, stride: usize) -> Self {
        ShapeCache {
            stride,
            count: vec![0; particles],
            nodes: vec![0; particles * stride],
            w: vec![[0.0; 3]; particles * stride],
        }
    }

    /// The nodes and weights of particle `p`.
    #[inline]
    pub fn particle(&self, p: usize) -> (&[u32], &[[f64; 3]]) {
        let (o, n) = (p * self.stride, self.count[p] as usize);
        (&self.nodes[o..o + n], &self.w[o..o + n])
    }
}

/// Body force per unit mass on particle `i` at time `t` (m/s²): gravity
/// with its ramp, plus a manufactured solution's load at the particle's
/// reference position, plus the particle's share of the tractions and
/// point loads divided by its mass (the stages multiply by m_p again).
pub(crate) fn body_force<'a>(
    gravity: Option<crate::model::Gravity>,
    mms: &'a Option<crate::model::AlignedVibration>,
    ext: &'a Option<crate::model::ExternalForces>,
    x0: &'a [[f64; 2]],
    mass: &'a [f64],
    t: f64,
) -> impl Fn(usize) -> [f64; 2] + Sync + 'a {
    let g = gravity.map_or([0.0; 2], |g| g.at(t));
    move |i: usize| {
        let mut b = g;
        if let Some(s) = mms {
            let s = s.body_force(x0[i], t);
            b = [b[0] + s[0], b[1] + s[1]];
        }
        if let Some(e) = ext {
            let f = e.at(i, t);
            b = [b[0] + f[0] / mass[i], b[1] + f[1] / mass[i]];
        }
        b
    }
}
