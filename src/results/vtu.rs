//! ParaView output: VTK XML UnstructuredGrid (.vtu) with base64 binary arrays, and the .pvd
//! collection that strings them into a timeline.

use base64::Engine;
use rayon::prelude::*;
use std::borrow::Cow;
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

/// The geometry of a .vtu piece: points and cells (VTK node order and type ids). A cell is
/// anything that lists its points (`Vec<usize>`, or `&[usize]` borrowed from the model).
pub struct Grid<'a, C: AsRef<[usize]> = Vec<usize>> {
    /// Point coordinates (x, y); z is written as 0.
    pub points: &'a [[f64; 2]],
    /// Cell connectivity (0-based point indices).
    pub cells: &'a [C],
    /// VTK cell type per cell.
    pub types: &'a [u8],
}

/// Append VTK's binary inline block of `bytes` to `out`: a UInt32 byte count, then the
/// data, base64 as one block. Large arrays are encoded in parallel pieces straight into
/// `out`: base64 of a concatenation is the concatenation of the pieces' base64 when each
/// piece but the last is a multiple of 3 bytes long.
fn b64_block(out: &mut Vec<u8>, bytes: &[u8]) {
    use base64::engine::general_purpose::STANDARD;
    const PIECE: usize = 3 << 18;
    const PIECE_OUT: usize = PIECE / 3 * 4;
    // The first piece: the count and the first PIECE − 4 data bytes.
    let k = bytes.len().min(PIECE - 4);
    let mut head = Vec::with_capacity(4 + k);
    head.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
    head.extend_from_slice(&bytes[..k]);
    let start = out.len();
    let len = (4 + bytes.len()).div_ceil(3) * 4;
    out.resize(start + len, 0);
    let (first, rest) = out[start..].split_at_mut(PIECE_OUT.min(len));
    let n = STANDARD
        .encode_slice(&head, first)
        .expect("output sized for the first piece");
    debug_assert_eq!(n, first.len());
    rest.par_chunks_mut(PIECE_OUT)
        .zip(bytes[k..].par_chunks(PIECE))
        .for_each(|(o, i)| {
            let n = STANDARD
                .encode_slice(i, o)
                .expect("output sized for the piece");
            debug_assert_eq!(n, o.len());
        });
}

/// An element of the document, UTF-8.
fn text(out: &mut Vec<u8>, args: std::fmt::Arguments) {
    use std::io::Write as _;
    let _ = out.write_fmt(args);
}

/// The little-endian bytes of `v`: the values' own memory on a little-endian machine (no
/// copy: at 5e5 dofs the .vtu arrays are 70 MB), a converted copy elsewhere.
#[cfg(target_endian = "little")]
fn le_bytes<T: LittleEndian>(v: &[T]) -> Cow<'_, [u8]> {
    // SAFETY: `T` is a plain number type (f64, i32 or i64: no padding, every byte
    // initialised), the slice covers exactly the values' memory, and u8 has alignment 1.
    Cow::Borrowed(unsafe {
        std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v))
    })
}

#[cfg(not(target_endian = "little"))]
fn le_bytes<T: LittleEndian>(v: &[T]) -> Cow<'_, [u8]> {
    Cow::Owned(v.iter().flat_map(|x| x.le()).collect())
}

/// The number types written into .vtu arrays.
trait LittleEndian: Copy {
    /// Little-endian bytes of one value.
    #[allow(dead_code)]
    fn le(self) -> Vec<u8>;
}

impl LittleEndian for f64 {
    fn le(self) -> Vec<u8> {
        self.to_le_bytes().to_vec()
    }
}

impl LittleEndian for i32 {
    fn le(self) -> Vec<u8> {
        self.to_le_bytes().to_vec()
    }
}

impl LittleEndian for i64 {
    fn le(self) -> Vec<u8> {
        self.to_le_bytes().to_vec()
    }
}

#[cfg(test)]
fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn write_array(out: &mut Vec<u8>, a: &Array) {
    match a {
        Array::F64 {
            name,
            components,
            values,
        } => {
            text(
                out,
                format_args!(
                    r#"<DataArray type="Float64" Name="{name}" NumberOfComponents="{components}" format="binary">"#
                ),
            );
            b64_block(out, &le_bytes(values));
        }
        Array::I32 { name, values } => {
            text(
                out,
                format_args!(
                    r#"<DataArray type="Int32" Name="{name}" NumberOfComponents="1" format="binary">"#
                ),
            );
            b64_block(out, &le_bytes(values));
        }
    }
    out.extend_from_slice(b"</DataArray>\n");
}

/// Bytes of the base64 blocks of `point_data` and `cell_data` and the grid, for reserving
/// the document at once (an estimate: the tags are not counted).
fn estimated_len<C: AsRef<[usize]>>(grid: &Grid<C>, arrays: &[&Array]) -> usize {
    let b64 = |bytes: usize| (4 + bytes).div_ceil(3) * 4 + 200;
    let cells: usize = grid.cells.iter().map(|c| c.as_ref().len()).sum();
    let data: usize = arrays
        .iter()
        .map(|a| match a {
            Array::F64 { values, .. } => b64(8 * values.len()),
            Array::I32 { values, .. } => b64(4 * values.len()),
        })
        .sum();
    data + b64(24 * grid.points.len()) + b64(8 * cells) + b64(9 * grid.cells.len()) + 1000
}

/// Render a .vtu document.
pub fn render<C: AsRef<[usize]>>(
    grid: &Grid<C>,
    point_data: &[Array],
    cell_data: &[Array],
) -> String {
    String::from_utf8(render_into(Vec::new(), grid, point_data, cell_data))
        .expect("tags and base64 are ASCII")
}

/// As [`render`], into `s` (emptied first), as bytes: a buffer reserved and faulted in
/// beforehand saves the page faults of a large document, and bytes the check of 70 MB of
/// ASCII for UTF-8 (at 5e5 dofs).
pub fn render_into<C: AsRef<[usize]>>(
    mut s: Vec<u8>,
    grid: &Grid<C>,
    point_data: &[Array],
    cell_data: &[Array],
) -> Vec<u8> {
    let all: Vec<&Array> = point_data.iter().chain(cell_data).collect();
    s.clear();
    s.reserve(estimated_len(grid, &all));
    s.extend_from_slice("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n<UnstructuredGrid>\n".as_bytes());
    text(
        &mut s,
        format_args!(
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
            grid.points.len(),
            grid.cells.len()
        ),
    );
    s.extend_from_slice(b"<Points>\n");
    let xyz: Vec<f64> = grid.points.iter().flat_map(|p| [p[0], p[1], 0.0]).collect();
    write_array(
        &mut s,
        &Array::F64 {
            name: "Points",
            components: 3,
            values: &xyz,
        },
    );
    s.extend_from_slice(b"</Points>\n<Cells>\n");
    // Int32 indices whenever they fit (every mesh this program can hold in memory): half
    // the bytes of Int64 for the largest arrays of a big mesh; ParaView reads both.
    let n_conn: usize = grid.cells.iter().map(|c| c.as_ref().len()).sum();
    let narrow = grid.points.len() <= i32::MAX as usize && n_conn <= i32::MAX as usize;
    let conn = grid.cells.iter().flat_map(|c| c.as_ref().iter().copied());
    let ends = grid.cells.iter().scan(0usize, |end, c| {
        *end += c.as_ref().len();
        Some(*end)
    });
    let (conn, offsets, ty): (Vec<u8>, Vec<u8>, _) = if narrow {
        (
            conn.flat_map(|n| (n as i32).to_le_bytes()).collect(),
            ends.flat_map(|n| (n as i32).to_le_bytes()).collect(),
            "Int32",
        )
    } else {
        (
            conn.flat_map(|n| (n as i64).to_le_bytes()).collect(),
            ends.flat_map(|n| (n as i64).to_le_bytes()).collect(),
            "Int64",
        )
    };
    let conn_head = format!(r#"<DataArray type="{ty}" Name="connectivity" format="binary">"#);
    let off_head = format!(r#"<DataArray type="{ty}" Name="offsets" format="binary">"#);
    for (head, bytes) in [
        (conn_head.as_bytes(), &conn[..]),
        (off_head.as_bytes(), &offsets[..]),
        (
            br#"<DataArray type="UInt8" Name="types" format="binary">"#,
            grid.types,
        ),
    ] {
        s.extend_from_slice(head);
        b64_block(&mut s, bytes);
        s.extend_from_slice(b"</DataArray>\n");
    }
    s.extend_from_slice(b"</Cells>\n<PointData>\n");
    for a in point_data {
        write_array(&mut s, a);
    }
    s.extend_from_slice(b"</PointData>\n<CellData>\n");
    for a in cell_data {
        write_array(&mut s, a);
    }
    s.extend_from_slice(b"</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
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

    /// The block of `bytes` alone, as text.
    fn block(bytes: &[u8]) -> String {
        let mut out = Vec::new();
        b64_block(&mut out, bytes);
        String::from_utf8(out).unwrap()
    }

    /// A block encoded in parallel pieces equals the one-piece encoding, for lengths at
    /// and around the piece boundaries, appended after earlier text.
    #[test]
    fn large_block_encodes_as_one_piece() {
        let piece = 3 << 18;
        let v: Vec<f64> = (0..300_001).map(|i| (i as f64).sin()).collect();
        let all = f64_bytes(&v);
        for len in [
            0,
            1,
            2,
            piece - 5,
            piece - 4,
            piece - 3,
            piece,
            2 * piece + 1,
            all.len(),
        ] {
            let bytes = &all[..len];
            let mut buf = (bytes.len() as u32).to_le_bytes().to_vec();
            buf.extend_from_slice(bytes);
            let mut out = b"<x>".to_vec();
            b64_block(&mut out, bytes);
            let expected = format!(
                "<x>{}",
                base64::engine::general_purpose::STANDARD.encode(buf)
            );
            assert_eq!(String::from_utf8(out).unwrap(), expected, "{len} bytes");
        }
    }

    /// The arrays' bytes are their values' little-endian bytes, for every type written.
    #[test]
    fn array_bytes_are_little_endian() {
        let f = [1.5, -2.0, f64::MIN_POSITIVE];
        assert_eq!(&*le_bytes(&f), &f64_bytes(&f)[..]);
        let i = [1i32, -7, i32::MAX];
        let ib: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(&*le_bytes(&i), &ib[..]);
        let l = [3i64, -1, i64::MIN];
        let lb: Vec<u8> = l.iter().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(&*le_bytes(&l), &lb[..]);
    }

    /// The binary block decodes to a little-endian byte count followed by the data.
    #[test]
    fn binary_block_round_trip() {
        let enc = block(&f64_bytes(&[1.5, -2.0]));
        let dec = base64::engine::general_purpose::STANDARD
            .decode(enc)
            .unwrap();
        assert_eq!(u32::from_le_bytes(dec[..4].try_into().unwrap()), 16);
        assert_eq!(f64::from_le_bytes(dec[4..12].try_into().unwrap()), 1.5);
        assert_eq!(f64::from_le_bytes(dec[12..20].try_into().unwrap()), -2.0);
    }
}
