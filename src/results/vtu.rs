//! ParaView output: VTK XML UnstructuredGrid (.vtu) with base64 binary arrays, and the .pvd
//! collection that strings them into a timeline.

use base64::Engine;
use rayon::prelude::*;
use std::fmt::Write;

/// A data array for a .vtu file.
pub enum Array<'a> {
    /// Float64 values with `components` per tuple.
    F64 {
        /// Array name.
        name: &'a str,
        /// Components per tuple.
        components: usize,
        /// Flat values.
        values: &'a [f64],
    },
    /// Int32 values, one per tuple.
    I32 {
        /// Array name.
        name: &'a str,
        /// Values.
        values: &'a [i32],
    },
}

/// The geometry of a .vtu piece: points and cells (VTK node order and type ids).
pub struct Grid<'a> {
    /// Point coordinates (x, y); z is written as 0.
    pub points: &'a [[f64; 2]],
    /// Cell connectivity (0-based point indices).
    pub cells: &'a [Vec<usize>],
    /// VTK cell type per cell.
    pub types: &'a [u8],
}

fn b64_block(bytes: &[u8]) -> String {
    // VTK's binary inline format: a UInt32 byte count, then the data, base64 as one block.
    let mut buf = Vec::with_capacity(bytes.len() + 4);
    buf.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
    buf.extend_from_slice(bytes);
    // Large arrays are encoded in parallel pieces: base64 of a concatenation is the
    // concatenation of the pieces' base64 when each piece but the last is a multiple of
    // 3 bytes long.
    const PIECE: usize = 3 << 18;
    if buf.len() <= PIECE {
        return base64::engine::general_purpose::STANDARD.encode(buf);
    }
    let pieces: Vec<String> = buf
        .par_chunks(PIECE)
        .map(|c| base64::engine::general_purpose::STANDARD.encode(c))
        .collect();
    pieces.concat()
}

fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn write_array(out: &mut String, a: &Array) {
    match a {
        Array::F64 {
            name,
            components,
            values,
        } => {
            let _ = writeln!(
                out,
                r#"<DataArray type="Float64" Name="{name}" NumberOfComponents="{components}" format="binary">{}</DataArray>"#,
                b64_block(&f64_bytes(values))
            );
        }
        Array::I32 { name, values } => {
            let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
            let _ = writeln!(
                out,
                r#"<DataArray type="Int32" Name="{name}" NumberOfComponents="1" format="binary">{}</DataArray>"#,
                b64_block(&bytes)
            );
        }
    }
}

/// Render a .vtu document.
pub fn render(grid: &Grid, point_data: &[Array], cell_data: &[Array]) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n<UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        grid.points.len(),
        grid.cells.len()
    );
    s.push_str("<Points>\n");
    let xyz: Vec<f64> = grid.points.iter().flat_map(|p| [p[0], p[1], 0.0]).collect();
    write_array(
        &mut s,
        &Array::F64 {
            name: "Points",
            components: 3,
            values: &xyz,
        },
    );
    s.push_str("</Points>\n<Cells>\n");
    let conn: Vec<u8> = grid
        .cells
        .iter()
        .flatten()
        .flat_map(|&n| (n as i64).to_le_bytes())
        .collect();
    let mut off = 0i64;
    let offsets: Vec<u8> = grid
        .cells
        .iter()
        .flat_map(|c| {
            off += c.len() as i64;
            off.to_le_bytes()
        })
        .collect();
    let _ = writeln!(
        s,
        r#"<DataArray type="Int64" Name="connectivity" format="binary">{}</DataArray>"#,
        b64_block(&conn)
    );
    let _ = writeln!(
        s,
        r#"<DataArray type="Int64" Name="offsets" format="binary">{}</DataArray>"#,
        b64_block(&offsets)
    );
    let _ = writeln!(
        s,
        r#"<DataArray type="UInt8" Name="types" format="binary">{}</DataArray>"#,
        b64_block(grid.types)
    );
    s.push_str("</Cells>\n<PointData>\n");
    for a in point_data {
        write_array(&mut s, a);
    }
    s.push_str("</PointData>\n<CellData>\n");
    for a in cell_data {
        write_array(&mut s, a);
    }
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// Render a .pvd collection of (time, part, file name) entries; part 0 is the continuum,
/// part 1 the line cells (joints, tendons) of the same instant.
pub fn render_pvd(entries: &[(f64, usize, String)]) -> String {
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n");
    for (t, part, f) in entries {
        let _ = writeln!(
            s,
            r#"<DataSet timestep="{t}" group="" part="{part}" file="{f}"/>"#
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block encoded in parallel pieces equals the one-piece encoding.
    #[test]
    fn large_block_encodes_as_one_piece() {
        let v: Vec<f64> = (0..300_001).map(|i| (i as f64).sin()).collect();
        let bytes = f64_bytes(&v);
        let mut buf = (bytes.len() as u32).to_le_bytes().to_vec();
        buf.extend_from_slice(&bytes);
        assert_eq!(
            b64_block(&bytes),
            base64::engine::general_purpose::STANDARD.encode(buf)
        );
    }

    /// The binary block decodes to a little-endian byte count followed by the data.
    #[test]
    fn binary_block_round_trip() {
        let enc = b64_block(&f64_bytes(&[1.5, -2.0]));
        let dec = base64::engine::general_purpose::STANDARD
            .decode(enc)
            .unwrap();
        assert_eq!(u32::from_le_bytes(dec[..4].try_into().unwrap()), 16);
        assert_eq!(f64::from_le_bytes(dec[4..12].try_into().unwrap()), 1.5);
        assert_eq!(f64::from_le_bytes(dec[12..20].try_into().unwrap()), -2.0);
    }
}
