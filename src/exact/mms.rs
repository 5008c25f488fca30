//! Scoring a run of the manufactured 2D aligned vibration (B-spline paper,
//! eq. 43) against its exact field, `model::loads::AlignedVibration`
//! (which holds the field, its derivation and the body force).

use crate::model::Particles;
pub use crate::model::loads::AlignedVibration;
use serde::Serialize;

/// Figures for `summary.json`: RMS over particles at t_end (paper eq. 43).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MmsErrors {
    /// RMS |u − u_exact| (m).
    pub rms_displacement: f64,
    /// RMS |v − v_exact| (m/s).
    pub rms_velocity: f64,
    /// RMS of the Cauchy stress difference, sqrt(Δσxx² + Δσyy² + 2Δσxy²) (Pa).
    pub rms_stress: f64,
}

/// Paper eq. 43 at time `t`, each particle against the exact field at
/// its reference position.
pub fn score(field: &AlignedVibration, p: &Particles, t: f64) -> MmsErrors {
    let n = p.len().max(1) as f64;
    let (mut du, mut dv, mut ds) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let x0 = p.x0[i];
        let u = field.displacement(x0, t);
        let v = field.velocity(x0, t);
        let s = field.cauchy(x0, t);
        du += (p.x[i][0] - x0[0] - u[0]).powi(2) + (p.x[i][1] - x0[1] - u[1]).powi(2);
        dv += (p.v[i][0] - v[0]).powi(2) + (p.v[i][1] - v[1]).powi(2);
        ds += (p.stress[i][0] - s[0]).powi(2)
            + (p.stress[i][1] - s[1]).powi(2)
            + 2.0 * (p.stress[i][2] - s[2]).powi(2);
    }
    MmsErrors {
        rms_displacement: (du / n).sqrt(),
        rms_velocity: (dv / n).sqrt(),
        rms_stress: (ds / n).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::NeoHookean;

    fn case() -> AlignedVibration {
        AlignedVibration {
            amplitude: 0.1,
            length: 1.0,
            c: (1e7f64 / 1000.0).sqrt(),
            origin: [0.0, 0.0],
            material: NeoHookean::new(1e7, 0.3, 1000.0),
        }
    }

    /// ρ0 ü = Div_X P + ρ0 b at random points and times, with ü and Div P
    /// from central differences of the exact displacement and of P(F).
    #[test]
    fn momentum_balance_holds() {
        let m = case();
        let rho0 = m.material.density;
        let piola_xx_yy = |x: [f64; 2], t: f64| {
            // P = σ J F^{-T}; diagonal F, so P_xx = σ_xx J / F_xx.
            let f = m.def_grad(x, t);
            let s = m.cauchy(x, t);
            let j = f[0] * f[3];
            [s[0] * j / f[0], s[1] * j / f[3]]
        };
        let mut rng = crate::rng::SplitMix64::new(5);
        for _ in 0..50 {
            let x = [rng.range(0.05, 0.95), rng.range(0.05, 0.95)];
            let t = rng.range(0.0, 0.2);
            // ht: ωt reaches ~60 rad, so sin(ωt) carries ~1e-14 absolute
            // roundoff; a step of 1e-5 s keeps that below 1e-7 of ü while
            // the truncation error ω⁴ u ht²/12 stays below 1e-6 of it.
            let (hx, ht) = (1e-5, 1e-5);
            let acc = |d: usize| {
                (m.displacement(x, t + ht)[d] - 2.0 * m.displacement(x, t)[d]
                    + m.displacement(x, t - ht)[d])
                    / (ht * ht)
            };
            let div_x = (piola_xx_yy([x[0] + hx, x[1]], t)[0]
                - piola_xx_yy([x[0] - hx, x[1]], t)[0])
                / (2.0 * hx);
            let div_y = (piola_xx_yy([x[0], x[1] + hx], t)[1]
                - piola_xx_yy([x[0], x[1] - hx], t)[1])
                / (2.0 * hx);
            let b = m.body_force(x, t);
            for (d, div) in [(0, div_x), (1, div_y)] {
                let lhs = rho0 * acc(d);
                let rhs = div + rho0 * b[d];
                let scale = (rho0 * acc(d)).abs().max(div.abs()).max(1.0);
                assert!(
                    (lhs - rhs).abs() < 1e-5 * scale,
                    "x {x:?} t {t} dir {d}: {lhs} vs {rhs}"
                );
            }
        }
    }

    #[test]
    fn boundaries_hold_still_in_the_normal_direction() {
        let m = case();
        for t in [0.013, 0.05, 0.17] {
            for s in [0.1, 0.5, 0.9] {
                assert!(m.displacement([0.0, s], t)[0].abs() < 1e-15);
                assert!(m.displacement([1.0, s], t)[0].abs() < 1e-15);
                assert!(m.displacement([s, 0.0], t)[1].abs() < 1e-15);
                assert!(m.displacement([s, 1.0], t)[1].abs() < 1e-15);
            }
        }
    }
}
