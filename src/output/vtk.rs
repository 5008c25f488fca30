//! VTK XML unstructured-grid files (.vtu) of the particles as vertex cells,
//! with binary appended data (Float32 fields, UInt64 block headers), and a
//! ParaView collection (.pvd) listing the snapshots with their times.
//! The format is small enough that a dependency would add more than it saves.
//! `read_vtu` reads such a file back (`lme-mpm render`).

use crate::model::Particles;
use crate::output::state::StateLayout;
use std::fmt::Write;

/// The .vtu file for the particle state at time `t`; `state` gives the
/// out-of-plane stress of the symmetric `stress` tensor and the arrays of
/// the materials' state columns.
pub fn particles_vtu(p: &Particles, state: &StateLayout, t: f64) -> Vec<u8> {
    let n = p.len();
    let mut arrays: Vec<(&str, &str, usize, Vec<u8>)> = Vec::new();
    let f32s = |it: &mut dyn Iterator<Item = f64>| {
        it.flat_map(|v| (v as f32).to_le_bytes())
            .collect::<Vec<u8>>()
    };
    let mut pos = (0..n).flat_map(|i| [p.x[i][0], p.x[i][1], 0.0]);
    let points = f32s(&mut pos);
    let mut vel = (0..n).flat_map(|i| [p.v[i][0], p.v[i][1], 0.0]);
    arrays.push(("velocity", "Float32", 3, f32s(&mut vel)));
    let mut disp = (0..n).flat_map(|i| [p.x[i][0] - p.x0[i][0], p.x[i][1] - p.x0[i][1], 0.0]);
    arrays.push(("displacement", "Float32", 3, f32s(&mut disp)));
    // The Cauchy stress as ParaView's symmetric tensor: xx, yy, zz, xy, yz, xz.
    let mut tensor = (0..n).flat_map(|i| {
        let s = p.stress[i];
        [s[0], s[1], state.szz(p, i), s[2], 0.0, 0.0]
    });
    arrays.push(("stress", "Float32", 6, f32s(&mut tensor)));
    let mut sig = (0..n).flat_map(|i| p.stress[i]);
    arrays.push(("stress_xx_yy_xy", "Float32", 3, f32s(&mut sig)));
    if !p.plastic.is_empty() {
        // σzz, the state's two fields and the last return's active surfaces (0 = elastic).
        let mut szz = p.plastic.iter().map(|q| q[0]);
        arrays.push(("stress_zz", "Float32", 1, f32s(&mut szz)));
        // Each array holds what it names (its material's `STATE_COLUMNS`);
        // a particle of a law without that column has 0 there.
        for (c, col) in state.columns().enumerate() {
            let mut v = (0..n).map(|i| state.value(c, p, i));
            arrays.push((col.array, "Float32", 1, f32s(&mut v)));
        }
        let ret: Vec<u8> = p
            .plastic
            .iter()
            .flat_map(|q| (q[3] as i32).to_le_bytes())
            .collect();
        arrays.push(("plastic", "Int32", 1, ret));
    }
    if !p.pore_pressure.is_empty() {
        // Saturated soil: p (Pa, compression positive); `stress` is σ'.
        let mut pw = p.pore_pressure.iter().copied();
        arrays.push(("pore_pressure", "Float32", 1, f32s(&mut pw)));
    }
    let mut rho = p.rho.iter().copied();
    arrays.push(("density", "Float32", 1, f32s(&mut rho)));
    let mut vol = (0..n).map(|i| p.mass[i] / p.rho[i]);
    arrays.push(("volume", "Float32", 1, f32s(&mut vol)));
    let mut speed = (0..n).map(|i| p.v[i][0].hypot(p.v[i][1]));
    arrays.push(("speed", "Float32", 1, f32s(&mut speed)));
    let body: Vec<u8> = p
        .body
        .iter()
        .flat_map(|b| (*b as i32).to_le_bytes())
        .collect();
    arrays.push(("body", "Int32", 1, body));
    let conn: Vec<u8> = (0..n as i64).flat_map(|i| i.to_le_bytes()).collect();
    let offs: Vec<u8> = (1..=n as i64).flat_map(|i| i.to_le_bytes()).collect();
    let types: Vec<u8> = vec![1u8; n]; // VTK_VERTEX

    let mut xml = String::new();
    let mut blocks: Vec<Vec<u8>> = Vec::new();
    let mut offset = 0usize;
    let mut add = |xml: &mut String, name: &str, ty: &str, comps: usize, data: Vec<u8>| {
        let _ = writeln!(
            xml,
            r#"<DataArray type="{ty}" Name="{name}" NumberOfComponents="{comps}" format="appended" offset="{offset}"/>"#
        );
        offset += 8 + data.len();
        blocks.push(data);
    };
    xml.push_str("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(xml, "<!-- lme-mpm particles, scene time t = {t} s -->");
    xml.push_str(r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#);
    xml.push_str("\n<UnstructuredGrid>\n<FieldData>\n");
    let _ = writeln!(
        xml,
        r#"<DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{t}</DataArray>"#
    );
    xml.push_str("</FieldData>\n");
    let _ = writeln!(xml, r#"<Piece NumberOfPoints="{n}" NumberOfCells="{n}">"#);
    xml.push_str("<PointData Scalars=\"density\" Vectors=\"velocity\" Tensors=\"stress\">\n");
    for (name, ty, comps, data) in arrays {
        add(&mut xml, name, ty, comps, data);
    }
    xml.push_str("</PointData>\n<Points>\n");
    add(&mut xml, "position", "Float32", 3, points);
    xml.push_str("</Points>\n<Cells>\n");
    add(&mut xml, "connectivity", "Int64", 1, conn);
    add(&mut xml, "offsets", "Int64", 1, offs);
    add(&mut xml, "types", "UInt8", 1, types);
    xml.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_");
    let mut out = xml.into_bytes();
    for b in blocks {
        out.extend_from_slice(&(b.len() as u64).to_le_bytes());
        out.extend_from_slice(&b);
    }
    out.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    out
}

/// A .vtu file read back: its time and its arrays as f32 (Int32 ones
/// converted), the points under the name `position`.
#[derive(Debug, Clone, Default)]
pub struct Vtu {
    pub t: f64,
    pub n: usize,
    /// (name, components, values).
    pub arrays: Vec<(String, usize, Vec<f32>)>,
}

impl Vtu {
    /// The array `name` and its number of components.
    pub fn get(&self, name: &str) -> Option<(&[f32], usize)> {
        self.arrays
            .iter()
            .find(|a| a.0 == name)
            .map(|a| (a.2.as_slice(), a.1))
    }
}

/// Reads a .vtu that `particles_vtu` wrote (raw appended data, UInt64
/// headers). Errors say what is missing.
pub fn read_vtu(bytes: &[u8]) -> std::result::Result<Vtu, String> {
    let marker = b"<AppendedData encoding=\"raw\">";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .ok_or("no raw appended data (not a file lme-mpm wrote)")?;
    let header = std::str::from_utf8(&bytes[..at]).map_err(|_| "header is not UTF-8")?;
    let data = at
        + marker.len()
        + bytes[at + marker.len()..]
            .iter()
            .position(|&b| b == b'_')
            .ok_or("appended data without its '_' mark")?
        + 1;
    let attr = |tag: &str, key: &str| -> Option<String> {
        let k = tag.find(&format!("{key}=\""))? + key.len() + 2;
        let end = tag[k..].find('"')? + k;
        Some(tag[k..end].to_string())
    };
    let mut out = Vtu::default();
    if let Some(k) = header.find("NumberOfPoints=\"") {
        let rest = &header[k + 16..];
        out.n = rest[..rest.find('"').unwrap_or(0)]
            .parse()
            .map_err(|_| "bad NumberOfPoints")?;
    }
    if let Some(k) = header.find("Name=\"TimeValue\"") {
        let rest = &header[k..];
        let (a, b) = (rest.find('>'), rest.find("</DataArray>"));
        if let (Some(a), Some(b)) = (a, b) {
            out.t = rest[a + 1..b].trim().parse().unwrap_or(0.0);
        }
    }
    for tag in header.split("<DataArray ").skip(1) {
        let tag = &tag[..tag.find("/>").unwrap_or(tag.len())];
        let (Some(ty), Some(name), Some(off)) =
            (attr(tag, "type"), attr(tag, "Name"), attr(tag, "offset"))
        else {
            continue;
        };
        let comps: usize = attr(tag, "NumberOfComponents")
            .map_or(Ok(1), |c| c.parse())
            .map_err(|_| "bad NumberOfComponents")?;
        let off: usize = off.parse().map_err(|_| "bad offset")?;
        let start = data + off;
        let len_bytes = bytes.get(start..start + 8).ok_or("array past the end")?;
        let len = u64::from_le_bytes(len_bytes.try_into().expect("8 bytes")) as usize;
        let raw = bytes
            .get(start + 8..start + 8 + len)
            .ok_or("array past the end")?;
        let values: Vec<f32> = match ty.as_str() {
            "Float32" => raw
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect(),
            "Int32" => raw
                .chunks_exact(4)
                .map(|c| i32::from_le_bytes(c.try_into().expect("4 bytes")) as f32)
                .collect(),
            _ => continue,
        };
        out.arrays.push((name, comps, values));
    }
    match out.get("position") {
        Some((v, 3)) if v.len() == 3 * out.n => Ok(out),
        _ => Err("no position array of NumberOfPoints points".into()),
    }
}

/// Reads a .pvd collection: its (time, file) entries, files relative to it.
pub fn read_pvd(text: &str) -> Vec<(f64, String)> {
    text.split("<DataSet ")
        .skip(1)
        .filter_map(|tag| {
            let get = |key: &str| {
                let k = tag.find(&format!("{key}=\""))? + key.len() + 2;
                Some(tag[k..k + tag[k..].find('"')?].to_string())
            };
            Some((get("timestep")?.parse().ok()?, get("file")?))
        })
        .collect()
}

/// ParaView collection listing `(time, file)` snapshots.
pub fn pvd(entries: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (t, f) in entries {
        let _ = writeln!(
            s,
            r#"<DataSet timestep="{t}" group="" part="0" file="{f}"/>"#
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}
