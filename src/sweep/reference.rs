//! Error without an exact solution: each run against the finest completed
//! run of its series (same values of every varied key but the resolution).
//! Probe histories are compared at the run's sample times, the reference
//! interpolated linearly in time; final particle fields are compared one by
//! one when both runs hold the same particles (same count, same reference
//! positions: a sweep of Δt or CFL, not of h).

use std::collections::BTreeMap;

/// One probe's history: (t, [ux, uy, vx, vy, sxx, syy, sxy]), u measured
/// from the probe's first sample (so probes that landed on different
/// particles at different h compare by motion, not by position).
pub type History = Vec<(f64, [f64; 7])>;

/// Final particles: (x0, [ux, uy, vx, vy, sxx, syy, sxy]) per particle.
pub type Fields = Vec<([f64; 2], [f64; 7])>;

/// Reference positions closer than this fraction of the largest coordinate
/// are the same particle (the seeding is deterministic: equal sets match to
/// round-off of the CSV's shortest round-trip form, i.e. exactly).
const SAME_PARTICLE_REL: f64 = 1e-9;

/// Reads `probes.csv` (`t,probe,x,y,vx,vy,sxx,syy,sxy`) into histories by probe name.
pub fn read_probes(text: &str) -> Result<BTreeMap<String, History>, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("probes.csv has no `{name}` column"))
    };
    let idx = [
        col("t")?,
        col("probe")?,
        col("x")?,
        col("y")?,
        col("vx")?,
        col("vy")?,
        col("sxx")?,
        col("syy")?,
        col("sxy")?,
    ];
    let mut out: BTreeMap<String, History> = BTreeMap::new();
    for (n, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| -> Result<f64, String> {
            f.get(idx[k])
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or_else(|| format!("probes.csv line {}: not a number", n + 2))
        };
        let name = f.get(idx[1]).copied().unwrap_or("").to_string();
        let row = [
            num(2)?,
            num(3)?,
            num(4)?,
            num(5)?,
            num(6)?,
            num(7)?,
            num(8)?,
        ];
        out.entry(name).or_default().push((num(0)?, row));
    }
    for h in out.values_mut() {
        let (x0, y0) = (h[0].1[0], h[0].1[1]);
        for (_, r) in h.iter_mut() {
            r[0] -= x0;
            r[1] -= y0;
        }
    }
    Ok(out)
}

/// Reads `particles.csv` (`id,body,x0,y0,x,y,vx,vy,sxx,syy,sxy,…`).
pub fn read_particles(text: &str) -> Result<Fields, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let idx: Vec<usize> = ["x0", "y0", "x", "y", "vx", "vy", "sxx", "syy", "sxy"]
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == n)
                .ok_or_else(|| format!("particles.csv has no `{n}` column"))
        })
        .collect::<Result<_, _>>()?;
    lines
        .enumerate()
        .map(|(n, line)| {
            let f: Vec<&str> = line.split(',').collect();
            let mut v = [0.0; 9];
            for (k, &i) in idx.iter().enumerate() {
                v[k] = f
                    .get(i)
                    .and_then(|s| s.parse().ok())
                    .ok_or_else(|| format!("particles.csv line {}: not a number", n + 2))?;
            }
            Ok((
                [v[0], v[1]],
                [v[2] - v[0], v[3] - v[1], v[4], v[5], v[6], v[7], v[8]],
            ))
        })
        .collect()
}

/// |u|², |v|², and the stress norm σxx² + σyy² + 2σxy² of a row (or of a difference).
fn norms(r: &[f64; 7]) -> [f64; 3] {
    [
        r[0] * r[0] + r[1] * r[1],
        r[2] * r[2] + r[3] * r[3],
        r[4] * r[4] + r[5] * r[5] + 2.0 * r[6] * r[6],
    ]
}

fn diff(a: &[f64; 7], b: &[f64; 7]) -> [f64; 7] {
    std::array::from_fn(|k| a[k] - b[k])
}

/// The history at time `t`, linear between samples; None outside it.
fn at(h: &History, t: f64) -> Option<[f64; 7]> {
    let (first, last) = (h.first()?, h.last()?);
    if t < first.0 || t > last.0 * (1.0 + 1e-12) {
        return None;
    }
    let k = h.partition_point(|s| s.0 < t);
    if k == 0 {
        return Some(first.1);
    }
    let Some(b) = h.get(k) else {
        return Some(last.1);
    };
    let a = &h[k - 1];
    let w = if b.0 > a.0 {
        (t - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    Some(std::array::from_fn(|i| a.1[i] + w * (b.1[i] - a.1[i])))
}

/// RMS of (run − reference) over every probe both have and every sample
/// time of the run inside the reference's history, for u (m), v (m/s) and
/// σ (Pa), and the same relative to the reference's own RMS there. None
/// when no probe and time are shared.
pub fn probe_errors(
    run: &BTreeMap<String, History>,
    reference: &BTreeMap<String, History>,
) -> Option<Vec<(String, f64)>> {
    let (mut d, mut r, mut n) = ([0.0; 3], [0.0; 3], 0usize);
    for (name, h) in run {
        let Some(rh) = reference.get(name) else {
            continue;
        };
        for (t, row) in h {
            let Some(rv) = at(rh, *t) else { continue };
            let dn = norms(&diff(row, &rv));
            let rn = norms(&rv);
            for k in 0..3 {
                d[k] += dn[k];
                r[k] += rn[k];
            }
            n += 1;
        }
    }
    (n > 0).then(|| figures("ref_probe", d, r, n))
}

/// RMS of (run − reference) over the final particles, when both hold the
/// same particles; None otherwise.
pub fn particle_errors(run: &Fields, reference: &Fields) -> Option<Vec<(String, f64)>> {
    if run.len() != reference.len() || run.is_empty() {
        return None;
    }
    let scale = reference
        .iter()
        .map(|(x0, _)| x0[0].abs().max(x0[1].abs()))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let (mut d, mut r) = ([0.0; 3], [0.0; 3]);
    for ((xa, a), (xb, b)) in run.iter().zip(reference) {
        if (xa[0] - xb[0]).abs().max((xa[1] - xb[1]).abs()) > SAME_PARTICLE_REL * scale {
            return None;
        }
        let dn = norms(&diff(a, b));
        let rn = norms(b);
        for k in 0..3 {
            d[k] += dn[k];
            r[k] += rn[k];
        }
    }
    Some(figures("ref_particles", d, r, run.len()))
}

/// Every figure name a reference comparison can report, in order.
pub fn figure_names() -> Vec<String> {
    ["ref_probe", "ref_particles"]
        .iter()
        .flat_map(|p| figures(p, [1.0; 3], [1.0; 3], 1))
        .map(|(k, _)| k)
        .collect()
}

/// `{prefix}_u_rms`, `_v_rms`, `_stress_rms`, then each `_relative` (over
/// the reference's RMS; left out where the reference's is zero).
fn figures(prefix: &str, d: [f64; 3], r: [f64; 3], n: usize) -> Vec<(String, f64)> {
    let names = ["u", "v", "stress"];
    let mut out: Vec<(String, f64)> = names
        .iter()
        .zip(d)
        .map(|(q, s)| (format!("{prefix}_{q}_rms"), (s / n as f64).sqrt()))
        .collect();
    for (k, q) in names.iter().enumerate() {
        if r[k] > 0.0 {
            out.push((format!("{prefix}_{q}_rms_relative"), (d[k] / r[k]).sqrt()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hist(f: impl Fn(f64) -> f64, dt: f64, n: usize) -> History {
        (0..=n)
            .map(|k| {
                let t = k as f64 * dt;
                (t, [f(t), 0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
            })
            .collect()
    }

    #[test]
    fn a_linear_history_interpolates_exactly_and_an_offset_shows() {
        // Reference sampled every 0.1, run every 0.03: a linear history
        // interpolates without error; a constant offset of 0.5 in u is the RMS.
        let reference = BTreeMap::from([("p".to_string(), hist(|t| 2.0 * t, 0.1, 10))]);
        let same = BTreeMap::from([("p".to_string(), hist(|t| 2.0 * t, 0.03, 33))]);
        let e = probe_errors(&same, &reference).unwrap();
        assert!(e[0].1 < 1e-12, "{e:?}");
        let off = BTreeMap::from([("p".to_string(), hist(|t| 2.0 * t + 0.5, 0.03, 33))]);
        let e = probe_errors(&off, &reference).unwrap();
        assert!((e[0].1 - 0.5).abs() < 1e-12, "{e:?}");
        let slower = BTreeMap::from([("p".to_string(), hist(|t| t, 0.5, 2))]);
        let e = probe_errors(&slower, &reference).unwrap();
        // Differences t at t = 0, 0.5, 1: RMS sqrt((0 + 0.25 + 1) / 3).
        assert!((e[0].1 - (1.25f64 / 3.0).sqrt()).abs() < 1e-12, "{e:?}");
    }

    #[test]
    fn probes_csv_reads_as_displacement_from_the_first_sample() {
        let csv = "t,probe,x,y,vx,vy,sxx,syy,sxy\n0,a,1,2,0,0,0,0,0\n0,b,5,5,0,0,0,0,0\n\
                   1,a,1.5,2,1,0,-3,0,0\n1,b,5,4,0,-1,0,0,0\n";
        let h = read_probes(csv).unwrap();
        assert_eq!(h["a"][1], (1.0, [0.5, 0.0, 1.0, 0.0, -3.0, 0.0, 0.0]));
        assert_eq!(h["b"][1].1[1], -1.0);
        assert!(read_probes("t,probe,x\n").is_err());
    }

    #[test]
    fn particle_fields_compare_only_the_same_particles() {
        let a: Fields = vec![([0.0, 0.0], [1.0; 7]), ([1.0, 0.0], [1.0; 7])];
        let mut b = a.clone();
        b[1].1[2] = 3.0; // v_x differs by 2 on one of two particles
        let e = particle_errors(&b, &a).unwrap();
        let v = e
            .iter()
            .find(|(k, _)| k == "ref_particles_v_rms")
            .unwrap()
            .1;
        assert!((v - 2f64.sqrt()).abs() < 1e-12);
        let mut c = a.clone();
        c[1].0[0] = 1.5;
        assert!(particle_errors(&c, &a).is_none());
        assert!(particle_errors(&a[..1].to_vec(), &a).is_none());
    }
}
