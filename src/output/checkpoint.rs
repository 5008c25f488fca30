//! `checkpoint.lmeck`: everything a run needs to continue exactly where it
//! stopped (the particles with every per-particle state, the time, the step
//! count, the driver's counters, the resolved scene, the samples and
//! snapshots written so far, the implicit integrator's Newton counters
//! and held wall contact states, and a GMM run's node cloud). Binary,
//! little-endian:
//!
//! ```text
//! "LMEMPMCK"  magic (8 bytes)
//! u32         format version (FORMAT)
//! str         lme-mpm version that wrote it
//! ...         payload (see `encode`)
//! u64         FNV-1a 64 of every byte before it
//! ```
//! `str` is a u64 length and UTF-8 bytes; a list is a u64 count and its
//! items; f64 are stored bit for bit, so a resumed run starts from the exact
//! state. A file from another version or with a wrong checksum is refused.

use crate::backend::{CloudState, NewtonSample, NewtonSeconds, NewtonStats, ProbeState, Sample};
use crate::error::{Error, Result};
use crate::model::Particles;
use crate::model::energy::Energy;
use crate::solver::Cursor;
use std::path::Path;

/// File name in the output folder.
pub const FILE: &str = "checkpoint.lmeck";
const MAGIC: &[u8; 8] = b"LMEMPMCK";
/// Bumped whenever the payload changes (2: the plastic state; 3: the
/// implicit integrator's Newton statistics and per-sample Newton figures;
/// 4: its held wall contact states; 5: a GMM run's node cloud; 6: the
/// Newton factorizations' count; 7: the pore pressure of saturated soil,
/// per particle and per probe).
pub const FORMAT: u32 = 7;

/// A run's state at a step boundary.
#[derive(Debug, Clone)]
pub struct Checkpoint {
    /// Scene name (the default output folder's name).
    pub scene_name: String,
    /// The resolved scene as TOML, `output.sample_interval` explicit.
    pub scene_toml: String,
    pub particles: Particles,
    /// Time reached (s).
    pub t: f64,
    /// Δt of the last step (s).
    pub dt: f64,
    pub steps: u64,
    pub cursor: Cursor,
    /// The samples written so far (the CSV rows).
    pub samples: Vec<Sample>,
    /// The snapshots written so far: (time, path in the folder).
    pub snapshots: Vec<(f64, String)>,
    /// The implicit integrator's Newton statistics so far (None for the
    /// explicit integrators).
    pub newton: Option<NewtonStats>,
    /// The implicit integrator's held wall contact states, per node then
    /// wall (`backend::State::held_contacts`); empty otherwise.
    pub held_contacts: Vec<u8>,
    /// A GMM run's node cloud (`backend::State::cloud`); None otherwise.
    pub cloud: Option<CloudState>,
}

impl Checkpoint {
    pub fn encode(&self) -> Vec<u8> {
        let mut e = Enc(Vec::with_capacity(self.particles.len() * 200 + 4096));
        e.0.extend_from_slice(MAGIC);
        e.u32(FORMAT);
        e.str(env!("CARGO_PKG_VERSION"));
        e.str(&self.scene_name);
        e.str(&self.scene_toml);
        e.f64(self.t);
        e.f64(self.dt);
        e.u64(self.steps);
        let c = &self.cursor;
        e.u64(c.k_sample);
        e.u64(c.k_vtk);
        e.u64(c.k_checkpoint);
        e.energy(&c.e0);
        e.f64(c.supplied);
        e.f64(c.floor);
        let p = &self.particles;
        e.pairs(&p.x);
        e.pairs(&p.v);
        e.pairs(&p.a);
        e.f64s(&p.mass);
        e.f64s(&p.rho);
        e.list(&p.stress, |e, s| s.iter().for_each(|v| e.f64(*v)));
        e.pairs(&p.lambda);
        e.list(&p.f, |e, f| f.iter().for_each(|v| e.f64(*v)));
        e.list(&p.plastic, |e, q| q.iter().for_each(|v| e.f64(*v)));
        e.f64s(&p.pore_pressure);
        e.list(&p.body, |e, b| e.u32(*b));
        e.pairs(&p.x0);
        e.list(&self.samples, |e, s| {
            e.f64(s.t);
            e.list(&s.probes, |e, pr| {
                pr.x.iter()
                    .chain(&pr.v)
                    .chain(&pr.stress)
                    .for_each(|v| e.f64(*v));
                e.option(pr.pore_pressure.as_ref(), |e, p| e.f64(*p));
            });
            e.energy(&s.energy);
            e.pairs(&s.reactions);
            e.option(s.newton.as_ref(), |e, n| {
                e.u32(n.iterations);
                e.f64(n.residual);
                e.f64(n.dt);
            });
        });
        e.list(&self.snapshots, |e, (t, name)| {
            e.f64(*t);
            e.str(name);
        });
        e.option(self.newton.as_ref(), |e, n| {
            e.u64(n.steps);
            e.u64(n.iterations);
            e.u32(n.max_iterations);
            e.u32(n.last_iterations);
            e.f64s(&n.last_residuals);
            e.f64s(&n.last_corrections);
            e.u64(n.cuts);
            e.u64(n.factorizations);
            let s = &n.seconds;
            for v in [
                s.map, s.symbolic, s.residual, s.jacobian, s.factor, s.solve, s.convect,
            ] {
                e.f64(v);
            }
        });
        e.list(&self.held_contacts, |e, c| e.u32(u32::from(*c)));
        e.option(self.cloud.as_ref(), |e, c| {
            for v in [&c.x, &c.u, &c.v, &c.a, &c.lambda] {
                e.pairs(v);
            }
        });
        let sum = fnv1a(&e.0);
        e.u64(sum);
        e.0
    }

    pub fn decode(bytes: &[u8]) -> Result<Checkpoint> {
        if bytes.len() < MAGIC.len() + 12 || &bytes[..8] != MAGIC {
            return Err(bad("is not an lme-mpm checkpoint (no LMEMPMCK header)"));
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        let mut d = Dec(&body[8..]);
        let format = d.u32()?;
        if format != FORMAT {
            return Err(bad(&format!(
                "has format {format}; this lme-mpm ({}) reads format {FORMAT}",
                env!("CARGO_PKG_VERSION")
            )));
        }
        let stored = u64::from_le_bytes(sum.try_into().expect("8 bytes"));
        if fnv1a(body) != stored {
            return Err(bad("is corrupted (checksum mismatch)"));
        }
        let version = d.str()?;
        if version != env!("CARGO_PKG_VERSION") {
            return Err(bad(&format!(
                "was written by lme-mpm {version}; this is {}: rerun the scene",
                env!("CARGO_PKG_VERSION")
            )));
        }
        let scene_name = d.str()?;
        let scene_toml = d.str()?;
        let (t, dt, steps) = (d.f64()?, d.f64()?, d.u64()?);
        let cursor = Cursor {
            k_sample: d.u64()?,
            k_vtk: d.u64()?,
            k_checkpoint: d.u64()?,
            e0: d.energy()?,
            supplied: d.f64()?,
            floor: d.f64()?,
        };
        let particles = Particles {
            x: d.pairs()?,
            v: d.pairs()?,
            a: d.pairs()?,
            mass: d.list(|d| d.f64())?,
            rho: d.list(|d| d.f64())?,
            stress: d.list(|d| Ok([d.f64()?, d.f64()?, d.f64()?]))?,
            lambda: d.pairs()?,
            f: d.list(|d| Ok([d.f64()?, d.f64()?, d.f64()?, d.f64()?]))?,
            plastic: d.list(|d| Ok([d.f64()?, d.f64()?, d.f64()?, d.f64()?]))?,
            pore_pressure: d.list(|d| d.f64())?,
            body: d.list(|d| d.u32())?,
            x0: d.pairs()?,
        };
        let samples = d.list(|d| {
            Ok(Sample {
                t: d.f64()?,
                probes: d.list(|d| {
                    Ok(ProbeState {
                        x: [d.f64()?, d.f64()?],
                        v: [d.f64()?, d.f64()?],
                        stress: [d.f64()?, d.f64()?, d.f64()?],
                        pore_pressure: d.option(|d| d.f64())?,
                    })
                })?,
                energy: d.energy()?,
                reactions: d.pairs()?,
                newton: d.option(|d| {
                    Ok(NewtonSample {
                        iterations: d.u32()?,
                        residual: d.f64()?,
                        dt: d.f64()?,
                    })
                })?,
            })
        })?;
        let snapshots = d.list(|d| Ok((d.f64()?, d.str()?)))?;
        let newton = d.option(|d| {
            Ok(NewtonStats {
                steps: d.u64()?,
                iterations: d.u64()?,
                max_iterations: d.u32()?,
                last_iterations: d.u32()?,
                last_residuals: d.list(|d| d.f64())?,
                last_corrections: d.list(|d| d.f64())?,
                cuts: d.u64()?,
                factorizations: d.u64()?,
                seconds: NewtonSeconds {
                    map: d.f64()?,
                    symbolic: d.f64()?,
                    residual: d.f64()?,
                    jacobian: d.f64()?,
                    factor: d.f64()?,
                    solve: d.f64()?,
                    convect: d.f64()?,
                },
            })
        })?;
        let held_contacts =
            d.list(|d| u8::try_from(d.u32()?).map_err(|_| bad("holds an invalid contact state")))?;
        let cloud = d.option(|d| {
            Ok(CloudState {
                x: d.pairs()?,
                u: d.pairs()?,
                v: d.pairs()?,
                a: d.pairs()?,
                lambda: d.pairs()?,
            })
        })?;
        if !d.0.is_empty() {
            return Err(bad("has trailing bytes"));
        }
        let n = particles.len();
        let optional_ok = [particles.a.len(), particles.lambda.len()]
            .into_iter()
            .chain([particles.f.len(), particles.plastic.len()])
            .chain([particles.pore_pressure.len()])
            .all(|l| l == 0 || l == n);
        let fields_ok = optional_ok
            && [particles.v.len(), particles.mass.len(), particles.rho.len()]
                .into_iter()
                .chain([
                    particles.stress.len(),
                    particles.body.len(),
                    particles.x0.len(),
                ])
                .all(|l| l == n);
        if !fields_ok {
            return Err(bad("holds particle fields of different lengths"));
        }
        if let Some(c) = &cloud {
            let nodes = c.x.len();
            if [c.u.len(), c.v.len(), c.a.len()]
                .iter()
                .any(|&l| l != nodes)
                || c.lambda.len() != n
            {
                return Err(bad("holds a node cloud whose fields differ in length"));
            }
        }
        Ok(Checkpoint {
            scene_name,
            scene_toml,
            particles,
            t,
            dt,
            steps,
            cursor,
            samples,
            snapshots,
            newton,
            held_contacts,
            cloud,
        })
    }

    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = std::fs::read(path)
            .map_err(|e| Error::Checkpoint(format!("{}: cannot read: {e}", path.display())))?;
        Checkpoint::decode(&bytes).map_err(|e| match e {
            Error::Checkpoint(m) => Error::Checkpoint(format!("{} {m}", path.display())),
            other => other,
        })
    }
}

fn bad(what: &str) -> Error {
    Error::Checkpoint(what.to_string())
}

/// FNV-1a, 64 bits: catches truncation and flipped bytes (not tampering).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

struct Enc(Vec<u8>);

impl Enc {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.0.extend_from_slice(s.as_bytes());
    }
    fn list<T>(&mut self, items: &[T], mut each: impl FnMut(&mut Enc, &T)) {
        self.u64(items.len() as u64);
        for it in items {
            each(self, it);
        }
    }
    fn f64s(&mut self, v: &[f64]) {
        self.list(v, |e, x| e.f64(*x));
    }
    fn pairs(&mut self, v: &[[f64; 2]]) {
        self.list(v, |e, x| {
            e.f64(x[0]);
            e.f64(x[1]);
        });
    }
    /// A u32 flag (0 = none, 1 = some) and the value.
    fn option<T>(&mut self, v: Option<&T>, each: impl FnOnce(&mut Enc, &T)) {
        self.u32(u32::from(v.is_some()));
        if let Some(v) = v {
            each(self, v);
        }
    }
    fn energy(&mut self, en: &Energy) {
        self.f64(en.kinetic);
        self.f64(en.strain);
        self.f64(en.gravity_work_bound);
    }
}

struct Dec<'a>(&'a [u8]);

impl Dec<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8]> {
        if self.0.len() < n {
            return Err(bad("is truncated"));
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4")))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8")))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().expect("8")))
    }
    fn str(&mut self) -> Result<String> {
        let n = self.u64()? as usize;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| bad("holds invalid text"))
    }
    fn list<T>(&mut self, mut each: impl FnMut(&mut Self) -> Result<T>) -> Result<Vec<T>> {
        let n = self.u64()?;
        // Every item takes at least 4 bytes: a count beyond that is corruption.
        if n > self.0.len() as u64 / 4 {
            return Err(bad("is truncated"));
        }
        (0..n).map(|_| each(self)).collect()
    }
    fn pairs(&mut self) -> Result<Vec<[f64; 2]>> {
        self.list(|d| Ok([d.f64()?, d.f64()?]))
    }
    fn option<T>(&mut self, each: impl FnOnce(&mut Self) -> Result<T>) -> Result<Option<T>> {
        match self.u32()? {
            0 => Ok(None),
            1 => each(self).map(Some),
            _ => Err(bad("holds an invalid flag")),
        }
    }
    fn energy(&mut self) -> Result<Energy> {
        Ok(Energy {
            kinetic: self.f64()?,
            strain: self.f64()?,
            gravity_work_bound: self.f64()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_checkpoint() -> Checkpoint {
        let mut particles = Particles::default();
        for i in 0..3 {
            let x = [i as f64 * 0.1 + 1e-17, 0.3];
            particles.x.push(x);
            particles.x0.push(x);
            particles.v.push([1.0 / 3.0, -2.0]);
            particles.a.push([0.5, f64::MIN_POSITIVE]);
            particles.mass.push(7.0);
            particles.rho.push(7833.0);
            particles.stress.push([1.0, 2.0, 3.0]);
            particles.f.push([1.0, 0.0, 0.0, 1.0]);
            particles
                .plastic
                .push([-4.5e4, 0.0123 + i as f64, -1e-19, 5.0]);
            particles.pore_pressure.push(1.5e4 - 1e-12 * i as f64);
            particles.body.push(i);
        }
        Checkpoint {
            scene_name: "s".into(),
            scene_toml: "name = \"s\"\n".into(),
            particles,
            t: 1.25e-4,
            dt: 3e-7,
            steps: 417,
            cursor: Cursor {
                k_sample: 3,
                k_vtk: 1,
                k_checkpoint: 2,
                e0: Energy {
                    kinetic: 1.0,
                    strain: 0.0,
                    gravity_work_bound: 0.0,
                },
                supplied: 0.0,
                floor: 1e-12,
            },
            samples: vec![Sample {
                t: 0.0,
                probes: vec![ProbeState {
                    x: [0.1, 0.2],
                    v: [0.0; 2],
                    stress: [0.0; 3],
                    pore_pressure: Some(-1.5e3),
                }],
                energy: Energy::default(),
                reactions: vec![[1.0, -1.0]],
                newton: Some(NewtonSample {
                    iterations: 3,
                    residual: 2.5e-11,
                    dt: 1e-3,
                }),
            }],
            snapshots: vec![(0.0, "vtk/particles_00000.vtu".into())],
            newton: Some(NewtonStats {
                steps: 12,
                iterations: 31,
                max_iterations: 4,
                last_iterations: 2,
                last_residuals: vec![1.0, 3e-4, 1e-9],
                last_corrections: vec![1.0, 2e-6],
                cuts: 1,
                factorizations: 29,
                seconds: NewtonSeconds {
                    map: 0.1,
                    symbolic: 0.2,
                    residual: 0.3,
                    jacobian: 0.4,
                    factor: 0.5,
                    solve: 0.6,
                    convect: 0.7,
                },
            }),
            held_contacts: vec![0, 1, 2, 3, 1],
            cloud: Some(CloudState {
                x: vec![[0.0, 0.1], [0.1 + 1e-17, 0.1]],
                u: vec![[1e-300, -0.0], [2e-3, 0.0]],
                v: vec![[0.25, -1.0 / 3.0], [0.0; 2]],
                a: vec![[-9.81, f64::MIN_POSITIVE], [0.5, 0.5]],
                lambda: vec![[1.5, -2.0]; 3],
            }),
        }
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let c = sample_checkpoint();
        let d = Checkpoint::decode(&c.encode()).unwrap();
        assert_eq!(d.particles.x, c.particles.x);
        assert_eq!(d.particles.v, c.particles.v);
        assert_eq!(d.particles.a, c.particles.a);
        assert_eq!(d.particles.f, c.particles.f);
        assert_eq!(d.particles.plastic, c.particles.plastic);
        assert_eq!(d.particles.pore_pressure, c.particles.pore_pressure);
        assert_eq!(d.particles.body, c.particles.body);
        assert!(d.particles.lambda.is_empty());
        assert_eq!((d.t, d.dt, d.steps), (c.t, c.dt, c.steps));
        assert_eq!(d.cursor, c.cursor);
        assert_eq!(d.samples, c.samples);
        assert_eq!(d.snapshots, c.snapshots);
        assert_eq!(d.scene_toml, c.scene_toml);
        assert_eq!(d.newton, c.newton);
        assert_eq!(d.held_contacts, c.held_contacts);
        assert_eq!(d.cloud, c.cloud);
        // Without a cloud (every run but GMM's) it reads back as none.
        let c = Checkpoint {
            cloud: None,
            ..sample_checkpoint()
        };
        assert_eq!(Checkpoint::decode(&c.encode()).unwrap().cloud, None);
    }

    #[test]
    fn a_cloud_of_mismatched_lengths_is_refused() {
        let mut c = sample_checkpoint();
        c.cloud.as_mut().unwrap().lambda.pop();
        let e = Checkpoint::decode(&c.encode()).unwrap_err().to_string();
        assert!(e.contains("node cloud"), "{e}");
    }

    #[test]
    fn corruption_truncation_and_other_formats_are_refused() {
        let bytes = sample_checkpoint().encode();
        let mut flipped = bytes.clone();
        flipped[100] ^= 1;
        let msg = |b: &[u8]| Checkpoint::decode(b).unwrap_err().to_string();
        assert!(msg(&flipped).contains("checksum"), "{}", msg(&flipped));
        assert!(msg(&bytes[..bytes.len() / 2]).contains("checksum"));
        assert!(msg(b"hello world, not a checkpoint").contains("not an lme-mpm checkpoint"));
        let mut other = bytes.clone();
        other[8..12].copy_from_slice(&(FORMAT + 1).to_le_bytes());
        assert!(msg(&other).contains("format"), "{}", msg(&other));
    }
}
