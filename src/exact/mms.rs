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
    /// `rms_displacement` divided by the field's own RMS |u| over the square
    /// and one period, A / √2: 1 means an error as large as the field.
    pub rms_displacement_relative: f64,
    /// `rms_velocity` divided by the field's RMS |v|, A ω / √2 (ω = c π / L).
    pub rms_velocity_relative: f64,
    /// `rms_stress` divided by the field's RMS stress norm (`stress_scale`).
    pub rms_stress_relative: f64,
}

/// RMS of sqrt(σxx² + σyy² + 2σxy²) of the exact field (Pa) over the
/// square and one period: the midpoint rule on 32 × 32 points and 32
/// instants (the same norm as `rms_stress`, so the ratio reads as "error
/// per field"). Not the peak: a Neo-Hookean peak in deep compression
/// (ln J / J) can be 20 times the typical stress and would hide errors.
pub fn stress_scale(field: &AlignedVibration) -> f64 {
    const N: usize = 32;
    let period = 2.0 * field.length / field.c;
    let mut sum = 0.0;
    for it in 0..N {
        let t = period * (it as f64 + 0.5) / N as f64;
        for j in 0..N {
            for i in 0..N {
                let x = [
                    field.origin[0] + field.length * (i as f64 + 0.5) / N as f64,
                    field.origin[1] + field.length * (j as f64 + 0.5) / N as f64,
                ];
                let s = field.cauchy(x, t);
                sum += s[0] * s[0] + s[1] * s[1] + 2.0 * s[2] * s[2];
            }
        }
    }
    (sum / (N * N * N) as f64).sqrt()
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
    let (du, dv, ds) = ((du / n).sqrt(), (dv / n).sqrt(), (ds / n).sqrt());
    let rel = |e: f64, scale: f64| if scale > 0.0 { e / scale } else { e };
    // RMS over space and one period of A sin(kX) sin(ωt) per component.
    let u_rms = field.amplitude / std::f64::consts::SQRT_2;
    let omega = field.c * std::f64::consts::PI / field.length;
    MmsErrors {
        rms_displacement: du,
        rms_velocity: dv,
        rms_stress: ds,
        rms_displacement_relative: rel(du, u_rms),
        rms_velocity_relative: rel(dv, u_rms * omega),
        rms_stress_relative: rel(ds, stress_scale(field)),
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

    /// Particles at rest in their reference place at t = 0, where the field
    /// moves at A ω (sin kX, −sin kY): the RMS over a cell-centred lattice
    /// is A ω exactly, √2 times the field's RMS speed over space and time.
    #[test]
    fn relative_errors_use_the_fields_rms() {
        let f = case();
        let n = 64;
        let mut p = Particles::default();
        for j in 0..n {
            for i in 0..n {
                let x = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
                p.x.push(x);
                p.x0.push(x);
                p.v.push([0.0; 2]);
                p.stress.push(f.cauchy(x, 0.0));
            }
        }
        let e = score(&f, &p, 0.0);
        assert!(e.rms_displacement < 1e-15 && e.rms_stress < 1e-9, "{e:?}");
        let omega = f.c * std::f64::consts::PI / f.length;
        assert!((e.rms_velocity - f.amplitude * omega).abs() < 1e-12 * e.rms_velocity);
        assert!(
            (e.rms_velocity_relative - 2f64.sqrt()).abs() < 1e-12,
            "{e:?}"
        );
        // At a small amplitude the stress scale is the linear field's RMS:
        // σxx = (λ + 2μ) εxx + λ εyy with εxx = A k cos kX sin ωt, εyy =
        // −A k cos kY sin ωt, so RMS sqrt(σxx² + σyy²) = A k sqrt(((λ + 2μ)²
        // + λ²) / 2); the midpoint rule is exact for these products, and the
        // Neo-Hookean terms of order A k = 6e-4 stay below 1e-3.
        let small = AlignedVibration {
            amplitude: 1e-4,
            ..case()
        };
        let (m, k) = (&small.material, 2.0 * std::f64::consts::PI / small.length);
        let linear = small.amplitude
            * k
            * (((m.lame + 2.0 * m.shear).powi(2) + m.lame.powi(2)) / 2.0).sqrt();
        let rel = stress_scale(&small) / linear - 1.0;
        assert!(rel.abs() < 1e-3, "{rel}");
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
