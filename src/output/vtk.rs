//! VTK XML unstructured-grid files (.vtu) of the particles as vertex cells,
//! with binary appended data (Float32 fields, UInt64 block headers), and a
//! ParaView collection (.pvd) listing the snapshots with their times.
//! The format is small enough that a dependency would add more than it saves.

use crate::model::Particles;
use std::fmt::Write;

/// The .vtu file for the particle state at time `t`.
pub fn particles_vtu(p: &Particles, t: f64) -> Vec<u8> {
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
    let mut sig = (0..n).flat_map(|i| p.stress[i]);
    arrays.push(("stress_xx_yy_xy", "Float32", 3, f32s(&mut sig)));
    if !p.plastic.is_empty() {
        // σzz, ε̄p, εp_v and the last return's active surfaces (0 = elastic).
        let mut szz = p.plastic.iter().map(|q| q[0]);
        arrays.push(("stress_zz", "Float32", 1, f32s(&mut szz)));
        let mut eq = p.plastic.iter().map(|q| q[1]);
        arrays.push(("plastic_strain_eq", "Float32", 1, f32s(&mut eq)));
        let mut vol = p.plastic.iter().map(|q| q[2]);
        arrays.push(("plastic_strain_vol", "Float32", 1, f32s(&mut vol)));
        let ret: Vec<u8> = p
            .plastic
            .iter()
            .flat_map(|q| (q[3] as i32).to_le_bytes())
            .collect();
        arrays.push(("plastic", "Int32", 1, ret));
    }
    let mut rho = p.rho.iter().copied();
    arrays.push(("density", "Float32", 1, f32s(&mut rho)));
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
    xml.push_str("<PointData Scalars=\"density\" Vectors=\"velocity\">\n");
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
