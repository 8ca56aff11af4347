//! In-house reader of Gmsh `.msh` meshes: format 4.1 (ASCII and binary) and 2.2 (ASCII).
//!
//! Sections read: `$MeshFormat`, `$PhysicalNames`, `$Entities` (4.1: maps entity tags to
//! physical tags), `$Nodes`, `$Elements`; any other section is skipped. Element types accepted:
//! 15 (point), 1 (2-node line), 8 (3-node line) and the continuum kinds' types (their
//! descriptors, `crate::fem::kinds`: 3 4-node quad, 16 8-node quad, 10 9-node quad, 9 6-node
//! triangle); any other type is an error naming the type. Node lists are returned in VTK order
//! (quads: corners counter-clockwise as in the file, mid-edges 0–1, 1–2, 2–3, 3–0, centre; T6:
//! corners, mid-edges 0–1, 1–2, 2–0; lines: start, end, middle), which for these types
//! coincides with Gmsh's order. Coordinates are in the
//! file's units (metres by project convention); z is ignored.
//!
//! Errors name the file, the line (ASCII) or byte offset (binary) and what is wrong; malformed
//! input never panics, and no allocation is sized by a count larger than the input itself.
//! See `docs/gmsh.md`.

use crate::model::ElementKind;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// Kinds of Gmsh elements accepted by the reader.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GmshElementKind {
    /// Type 15: 1-node point.
    Point,
    /// Type 1: 2-node line.
    Line2,
    /// Type 8: 3-node line (start, end, middle).
    Line3,
    /// A continuum element kind of the solver, by its descriptor's Gmsh type id
    /// ([`crate::fem::kinds`]: 3 Q4, 16 Q8, 10 Q9).
    Surface(ElementKind),
}

impl GmshElementKind {
    /// The kind of a Gmsh element type number, if supported.
    pub fn from_gmsh_type(t: i64) -> Option<Self> {
        Some(match t {
            15 => Self::Point,
            1 => Self::Line2,
            8 => Self::Line3,
            t => Self::Surface(ElementKind::from_gmsh(t)?),
        })
    }

    /// Gmsh element type number.
    pub fn gmsh_type(self) -> i64 {
        match self {
            Self::Point => 15,
            Self::Line2 => 1,
            Self::Line3 => 8,
            Self::Surface(k) => k.info().gmsh_type,
        }
    }

    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        match self {
            Self::Point => 1,
            Self::Line2 => 2,
            Self::Line3 => 3,
            Self::Surface(k) => k.n_nodes(),
        }
    }

    /// Topological dimension (0, 1 or 2).
    pub fn dim(self) -> i32 {
        match self {
            Self::Point => 0,
            Self::Line2 | Self::Line3 => 1,
            Self::Surface(_) => 2,
        }
    }

    /// The continuum element kind of the solver, for 2-D elements.
    pub fn element_kind(self) -> Option<ElementKind> {
        match self {
            Self::Surface(k) => Some(k),
            Self::Point | Self::Line2 | Self::Line3 => None,
        }
    }

    /// Position in the Gmsh node list of each VTK-ordered node: `vtk[i] = gmsh[perm[i]]`.
    /// Identity for all supported kinds (Gmsh and VTK agree; verified by tests against the
    /// geometry of the mid-edge nodes).
    pub fn gmsh_to_vtk(self) -> &'static [usize] {
        const ID: [usize; 9] = [0, 1, 2, 3, 4, 5, 6, 7, 8];
        &ID[..self.n_nodes()]
    }
}

/// Human-readable name of a Gmsh element type (for error messages).
pub fn gmsh_type_name(t: i64) -> &'static str {
    match t {
        1 => "2-node line",
        2 => "3-node triangle",
        3 => "4-node quadrangle",
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrangle",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        15 => "1-node point",
        16 => "8-node quadrangle",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        20 => "9-node incomplete triangle",
        21 => "10-node triangle",
        26 => "4-node line",
        36 => "16-node quadrangle",
        _ => "unknown element type",
    }
}

/// One element of the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshElement {
    /// Element kind.
    pub kind: GmshElementKind,
    /// Element tag (number) in the file.
    pub tag: u64,
    /// Node tags in VTK order.
    pub nodes: Vec<u64>,
    /// Physical tags of the element's entity (4.1: from `$Entities`; 2.2: the first element tag,
    /// omitted when 0). Empty if none.
    pub physical: Vec<i32>,
    /// Entity (dimension, tag) the element belongs to (2.2: dimension of the element, the
    /// elementary tag; 0 if absent).
    pub entity: (i32, i32),
}

/// A mesh as read from a `.msh` file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GmshMesh {
    /// Format version as written in the file ("4.1" or "2.2").
    pub version: String,
    /// True for a binary file.
    pub binary: bool,
    /// Nodes: (tag, [x, y]) [m], in file order.
    pub nodes: Vec<(u64, [f64; 2])>,
    /// Elements in file order.
    pub elements: Vec<GmshElement>,
    /// Physical names: (dimension, physical tag, name).
    pub physical_names: Vec<(i32, i32, String)>,
}

impl GmshMesh {
    /// Map node tag → index into `nodes`.
    pub fn node_index(&self) -> HashMap<u64, usize> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, (t, _))| (*t, i))
            .collect()
    }

    /// Physical tag of a physical name in dimension `dim`, if any.
    pub fn physical_tag(&self, dim: i32, name: &str) -> Option<i32> {
        self.physical_names
            .iter()
            .find(|(d, _, n)| *d == dim && n == name)
            .map(|(_, t, _)| *t)
    }
}

/// Where in the file an error occurred.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line (ASCII files).
    Line(usize),
    /// 0-based byte offset (binary files).
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte offset {b}"),
        }
    }
}

/// Errors of the reader.
#[derive(Debug, thiserror::Error)]
pub enum GmshError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// File name.
        file: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// Malformed or unsupported content.
    #[error("{file}, {location}: {message}")]
    Parse {
        /// File name.
        file: String,
        /// Position.
        location: Location,
        /// What is wrong.
        message: String,
    },
    /// An element type the solver does not support.
    #[error("{file}, {location}: element type {type_id} ({name}) is not supported; use quadrangles (types 3, 16, 10), 6-node triangles (9), lines (1, 8) and points (15) — e.g. Mesh.RecombineAll = 1, or Mesh.ElementOrder = 2 for 6-node triangles")]
    UnsupportedElement {
        /// File name.
        file: String,
        /// Position.
        location: Location,
        /// Gmsh type number.
        type_id: i64,
        /// Type name.
        name: &'static str,
    },
}

/// Read a `.msh` file (4.1 ASCII/binary or 2.2 ASCII).
pub fn read_msh(path: &Path) -> Result<GmshMesh, GmshError> {
    let label = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| GmshError::Io {
        file: label.clone(),
        source: e,
    })?;
    parse_msh(&bytes, &label)
}

/// Parse the bytes of a `.msh` file; `file_label` names the file in error messages.
pub fn parse_msh(bytes: &[u8], file_label: &str) -> Result<GmshMesh, GmshError> {
    let mut p = Parser {
        b: bytes,
        pos: 0,
        line: 1,
        file: file_label,
        binary: false,
        big_endian: false,
    };
    p.parse()
}

// ------------------------------------------------------------------------------------------

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V41,
}

struct Parser<'a> {
    b: &'a [u8],
    pos: usize,
    line: usize,
    file: &'a str,
    binary: bool,
    big_endian: bool,
}

type R<T> = Result<T, GmshError>;

/// A parsed element before physical tags are attached.
struct RawElement {
    el: GmshElement,
    loc: Location,
}

impl<'a> Parser<'a> {
    fn loc(&self) -> Location {
        if self.binary {
            Location::Byte(self.pos)
        } else {
            Location::Line(self.line)
        }
    }

    fn err<T>(&self, msg: impl Into<String>) -> R<T> {
        Err(self.err_at(self.loc(), msg))
    }

    fn err_at(&self, location: Location, msg: impl Into<String>) -> GmshError {
        GmshError::Parse {
            file: self.file.to_string(),
            location,
            message: msg.into(),
        }
    }

    fn remaining(&self) -> usize {
        self.b.len() - self.pos
    }

    /// Capacity for `n` items of at least `min_bytes` each: never more than the input allows.
    fn cap(&self, n: usize, min_bytes: usize) -> usize {
        n.min(self.remaining() / min_bytes.max(1))
    }

    fn skip_ws(&mut self) {
        while self.pos < self.b.len() {
            match self.b[self.pos] {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                b' ' | b'\t' | b'\r' => self.pos += 1,
                _ => break,
            }
        }
    }

    /// Next whitespace-delimited ASCII token.
    fn token(&mut self, what: &str) -> R<&'a str> {
        self.skip_ws();
        if self.pos >= self.b.len() {
            return self.err(format!("unexpected end of file (expected {what})"));
        }
        let start = self.pos;
        while self.pos < self.b.len() && !matches!(self.b[self.pos], b' ' | b'\t' | b'\r' | b'\n') {
            self.pos += 1;
        }
        std::str::from_utf8(&self.b[start..self.pos]).or_else(|_| {
            self.err(format!(
                "invalid (non-UTF-8) text where {what} was expected"
            ))
        })
    }

    fn parse_tok<T: std::str::FromStr>(&mut self, what: &str) -> R<T> {
        let loc0 = {
            self.skip_ws();
            self.loc()
        };
        let t = self.token(what)?;
        t.parse::<T>().map_err(|_| {
            let shown: String = t.chars().take(40).collect();
            self.err_at(loc0, format!("expected {what}, found '{shown}'"))
        })
    }

    fn expect_token(&mut self, want: &str) -> R<()> {
        self.skip_ws();
        let loc0 = self.loc();
        let t = self.token(want)?;
        if t != want {
            let shown: String = t.chars().take(40).collect();
            return Err(self.err_at(loc0, format!("expected '{want}', found '{shown}'")));
        }
        Ok(())
    }

    /// In binary files, the single newline that ends a section header line.
    fn newline_before_binary(&mut self) -> R<()> {
        if self.pos < self.b.len() && self.b[self.pos] == b'\r' {
            self.pos += 1;
        }
        if self.pos < self.b.len() && self.b[self.pos] == b'\n' {
            self.pos += 1;
            self.line += 1;
            Ok(())
        } else {
            self.err("expected a newline before binary data")
        }
    }

    fn raw<const N: usize>(&mut self, what: &str) -> R<[u8; N]> {
        if self.remaining() < N {
            return self.err(format!(
                "unexpected end of file in binary data (expected {what})"
            ));
        }
        let mut a = [0u8; N];
        a.copy_from_slice(&self.b[self.pos..self.pos + N]);
        self.pos += N;
        Ok(a)
    }

    fn bin_i32(&mut self, what: &str) -> R<i32> {
        let a = self.raw::<4>(what)?;
        Ok(if self.big_endian {
            i32::from_be_bytes(a)
        } else {
            i32::from_le_bytes(a)
        })
    }

    fn bin_u64(&mut self, what: &str) -> R<u64> {
        let a = self.raw::<8>(what)?;
        Ok(if self.big_endian {
            u64::from_be_bytes(a)
        } else {
            u64::from_le_bytes(a)
        })
    }

    fn bin_f64(&mut self, what: &str) -> R<f64> {
        let a = self.raw::<8>(what)?;
        Ok(if self.big_endian {
            f64::from_be_bytes(a)
        } else {
            f64::from_le_bytes(a)
        })
    }

    // Format-independent readers for 4.1 data (int / size_t / double).
    fn int(&mut self, what: &str) -> R<i32> {
        if self.binary {
            self.bin_i32(what)
        } else {
            self.parse_tok(what)
        }
    }

    fn size(&mut self, what: &str) -> R<u64> {
        if self.binary {
            self.bin_u64(what)
        } else {
            self.parse_tok(what)
        }
    }

    fn count(&mut self, what: &str) -> R<usize> {
        let loc0 = {
            self.skip_ws_if_ascii();
            self.loc()
        };
        let n = self.size(what)?;
        usize::try_from(n)
            .ok()
            .filter(|&n| n <= self.b.len())
            .ok_or_else(|| {
                self.err_at(loc0, format!("{what} = {n} exceeds what the file can hold"))
            })
    }

    fn real(&mut self, what: &str) -> R<f64> {
        let loc0 = {
            self.skip_ws_if_ascii();
            self.loc()
        };
        let v = if self.binary {
            self.bin_f64(what)?
        } else {
            self.parse_tok(what)?
        };
        if !v.is_finite() {
            return Err(self.err_at(loc0, format!("{what} is not a finite number")));
        }
        Ok(v)
    }

    fn skip_ws_if_ascii(&mut self) {
        if !self.binary {
            self.skip_ws();
        }
    }

    /// ASCII count (used by 2.2 and `$PhysicalNames`).
    fn ascii_count(&mut self, what: &str) -> R<usize> {
        self.skip_ws();
        let loc0 = self.loc();
        let n: u64 = self.parse_tok(what)?;
        usize::try_from(n)
            .ok()
            .filter(|&n| n <= self.b.len())
            .ok_or_else(|| {
                self.err_at(loc0, format!("{what} = {n} exceeds what the file can hold"))
            })
    }

    fn section_start(&mut self) -> R<()> {
        if self.binary {
            self.newline_before_binary()
        } else {
            Ok(())
        }
    }

    fn skip_section(&mut self, name: &str) -> R<()> {
        let end = format!("$End{}", &name[1..]);
        let hay = &self.b[self.pos..];
        match hay.windows(end.len()).position(|w| w == end.as_bytes()) {
            Some(i) => {
                self.line += hay[..i].iter().filter(|&&c| c == b'\n').count();
                self.pos += i + end.len();
                Ok(())
            }
            None => self.err(format!("section {name} has no {end}")),
        }
    }

    fn parse(&mut self) -> R<GmshMesh> {
        let mut mesh = GmshMesh::default();
        self.skip_ws();
        let loc0 = self.loc();
        let first = self.token("$MeshFormat")?;
        if first != "$MeshFormat" {
            return Err(self.err_at(
                loc0,
                "not a Gmsh mesh: the file must start with $MeshFormat",
            ));
        }
        let version = self.mesh_format(&mut mesh)?;
        let mut entities: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
        let mut raw: Vec<RawElement> = Vec::new();
        let mut node_set: HashMap<u64, usize> = HashMap::new();
        let (mut seen_nodes, mut seen_elements) = (false, false);
        loop {
            self.skip_ws();
            if self.pos >= self.b.len() {
                break;
            }
            let loc0 = self.loc();
            let name = self.token("a section header")?;
            if !name.starts_with('$') || name.len() < 2 {
                let shown: String = name.chars().take(40).collect();
                return Err(self.err_at(
                    loc0,
                    format!("expected a section header ($Name), found '{shown}'"),
                ));
            }
            match name {
                "$MeshFormat" => return Err(self.err_at(loc0, "second $MeshFormat section")),
                "$PhysicalNames" => {
                    self.physical_names(&mut mesh)?;
                    self.expect_token("$EndPhysicalNames")?;
                }
                "$Entities" if version == Version::V41 => {
                    self.section_start()?;
                    self.entities(&mut entities)?;
                    self.expect_token("$EndEntities")?;
                }
                "$Nodes" => {
                    if seen_nodes {
                        return Err(self.err_at(loc0, "second $Nodes section"));
                    }
                    seen_nodes = true;
                    match version {
                        Version::V41 => {
                            self.section_start()?;
                            self.nodes41(&mut mesh, &mut node_set)?
                        }
                        Version::V2 => self.nodes2(&mut mesh, &mut node_set)?,
                    }
                    self.expect_token("$EndNodes")?;
                }
                "$Elements" => {
                    if seen_elements {
                        return Err(self.err_at(loc0, "second $Elements section"));
                    }
                    seen_elements = true;
                    match version {
                        Version::V41 => {
                            self.section_start()?;
                            self.elements41(&mut raw)?
                        }
                        Version::V2 => self.elements2(&mut raw)?,
                    }
                    self.expect_token("$EndElements")?;
                }
                other => {
                    let other = other.to_string();
                    self.skip_section(&other)?;
                }
            }
        }
        if !seen_nodes {
            return self.err("no $Nodes section");
        }
        if !seen_elements {
            return self.err("no $Elements section");
        }
        mesh.elements.reserve(raw.len());
        for RawElement { mut el, loc } in raw {
            if let Some(bad) = el.nodes.iter().find(|t| !node_set.contains_key(t)) {
                return Err(self.err_at(
                    loc,
                    format!("element {} refers to unknown node {bad}", el.tag),
                ));
            }
            if version == Version::V41 {
                el.physical = entities.get(&el.entity).cloned().unwrap_or_default();
            }
            mesh.elements.push(el);
        }
        Ok(mesh)
    }

    fn mesh_format(&mut self, mesh: &mut GmshMesh) -> R<Version> {
        self.skip_ws();
        let loc0 = self.loc();
        let v = self.token("the format version")?;
        let version = match v {
            "4.1" => Version::V41,
            "2.2" | "2.1" | "2.0" | "2" => Version::V2,
            other => {
                let shown: String = other.chars().take(20).collect();
                return Err(self.err_at(
                    loc0,
                    format!(
                        "MSH format version '{shown}' is not supported (use 4.1 or 2.2; e.g. Mesh.MshFileVersion = 4.1)"
                    ),
                ));
            }
        };
        mesh.version = v.to_string();
        let ft: i32 = self.parse_tok("file-type (0 = ASCII, 1 = binary)")?;
        self.skip_ws();
        let loc_ds = self.loc();
        let ds: i32 = self.parse_tok("data-size")?;
        if ds != 8 {
            return Err(self.err_at(
                loc_ds,
                format!("data-size {ds} is not supported (size_t must be 8 bytes)"),
            ));
        }
        match (ft, version) {
            (0, _) => {}
            (1, Version::V41) => {
                self.binary = true;
                mesh.binary = true;
                self.newline_before_binary()?;
                let loc_m = self.loc();
                let a = self.raw::<4>("the endianness marker (int 1)")?;
                if i32::from_le_bytes(a) == 1 {
                    self.big_endian = false;
                } else if i32::from_be_bytes(a) == 1 {
                    self.big_endian = true;
                } else {
                    return Err(self.err_at(
                        loc_m,
                        format!("bad endianness marker: expected the int 1, found bytes {a:02x?}"),
                    ));
                }
            }
            (1, Version::V2) => {
                return Err(self.err_at(
                    loc0,
                    "binary MSH 2.2 is not supported (use ASCII 2.2 or 4.1)",
                ))
            }
            (other, _) => {
                return Err(self.err_at(
                    loc0,
                    format!("file-type {other} is not 0 (ASCII) or 1 (binary)"),
                ))
            }
        }
        self.expect_token("$EndMeshFormat")?;
        Ok(version)
    }

    fn physical_names(&mut self, mesh: &mut GmshMesh) -> R<()> {
        // Always ASCII, even in binary files.
        let n = self.ascii_count("number of physical names")?;
        mesh.physical_names.reserve(self.cap(n, 6));
        for _ in 0..n {
            let dim: i32 = self.parse_tok("physical dimension")?;
            if !(0..=3).contains(&dim) {
                return self.err(format!("physical dimension {dim} is not 0..=3"));
            }
            let tag: i32 = self.parse_tok("physical tag")?;
            self.skip_ws();
            if self.pos >= self.b.len() || self.b[self.pos] != b'"' {
                return self.err("expected a quoted physical name");
            }
            let start = self.pos + 1;
            let end = match self.b[start..]
                .iter()
                .position(|&c| c == b'"' || c == b'\n')
            {
                Some(i) if self.b[start + i] == b'"' => start + i,
                _ => return self.err("unterminated physical name (missing closing quote)"),
            };
            let name = std::str::from_utf8(&self.b[start..end])
                .map_err(|_| self.err_at(self.loc(), "physical name is not valid UTF-8"))?;
            mesh.physical_names.push((dim, tag, name.to_string()));
            self.pos = end + 1;
        }
        Ok(())
    }

    fn entities(&mut self, map: &mut HashMap<(i32, i32), Vec<i32>>) -> R<()> {
        let mut counts = [0usize; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = self.count(&format!("number of {}-D entities", d))?;
        }
        for (dim, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let tag = self.int("entity tag")?;
                let n_coord = if dim == 0 { 3 } else { 6 };
                for _ in 0..n_coord {
                    self.real("entity coordinate")?;
                }
                let np = self.count("number of physical tags")?;
                let mut phys = Vec::with_capacity(self.cap(np, 2));
                for _ in 0..np {
                    phys.push(self.int("physical tag")?);
                }
                if dim > 0 {
                    let nb = self.count("number of bounding entities")?;
                    for _ in 0..nb {
                        self.int("bounding entity tag")?;
                    }
                }
                map.insert((dim as i32, tag), phys);
            }
        }
        Ok(())
    }

    fn add_node(
        &mut self,
        mesh: &mut GmshMesh,
        set: &mut HashMap<u64, usize>,
        tag: u64,
        x: [f64; 2],
        loc: Location,
    ) -> R<()> {
        if set.insert(tag, mesh.nodes.len()).is_some() {
            return Err(self.err_at(loc, format!("node {tag} is defined twice")));
        }
        mesh.nodes.push((tag, x));
        Ok(())
    }

    fn nodes41(&mut self, mesh: &mut GmshMesh, set: &mut HashMap<u64, usize>) -> R<()> {
        let n_blocks = self.count("number of node blocks")?;
        self.skip_ws_if_ascii();
        let loc_n = self.loc();
        let n_nodes = self.count("number of nodes")?;
        self.size("minimum node tag")?;
        self.size("maximum node tag")?;
        mesh.nodes.reserve(self.cap(n_nodes, 8));
        let mut total = 0usize;
        for _ in 0..n_blocks {
            let dim = self.int("entity dimension")?;
            if !(0..=3).contains(&dim) {
                return self.err(format!("entity dimension {dim} is not 0..=3"));
            }
            self.int("entity tag")?;
            let param = self.int("parametric flag")?;
            if param != 0 && param != 1 {
                return self.err(format!("parametric flag {param} is not 0 or 1"));
            }
            let n = self.count("number of nodes in block")?;
            let mut tags = Vec::with_capacity(self.cap(n, 2));
            for _ in 0..n {
                self.skip_ws_if_ascii();
                tags.push((self.size("node tag")?, self.loc()));
            }
            let n_param = if param == 1 { dim as usize } else { 0 };
            for (tag, _) in tags {
                self.skip_ws_if_ascii();
                let loc = self.loc();
                let x = self.real("x coordinate")?;
                let y = self.real("y coordinate")?;
                self.real("z coordinate")?;
                for _ in 0..n_param {
                    self.real("parametric coordinate")?;
                }
                self.add_node(mesh, set, tag, [x, y], loc)?;
            }
            total = total.saturating_add(n);
        }
        if total != n_nodes {
            return Err(self.err_at(
                loc_n,
                format!("header declares {n_nodes} nodes but the blocks hold {total}"),
            ));
        }
        Ok(())
    }

    fn nodes2(&mut self, mesh: &mut GmshMesh, set: &mut HashMap<u64, usize>) -> R<()> {
        let n = self.ascii_count("number of nodes")?;
        mesh.nodes.reserve(self.cap(n, 8));
        for _ in 0..n {
            self.skip_ws();
            let loc = self.loc();
            let tag: u64 = self.parse_tok("node tag")?;
            let x = self.real("x coordinate")?;
            let y = self.real("y coordinate")?;
            self.real("z coordinate")?;
            self.add_node(mesh, set, tag, [x, y], loc)?;
        }
        Ok(())
    }

    fn kind_of(&self, t: i64, loc: Location) -> R<GmshElementKind> {
        GmshElementKind::from_gmsh_type(t).ok_or_else(|| GmshError::UnsupportedElement {
            file: self.file.to_string(),
            location: loc,
            type_id: t,
            name: gmsh_type_name(t),
        })
    }

    fn reorder(kind: GmshElementKind, gmsh_nodes: Vec<u64>) -> Vec<u64> {
        kind.gmsh_to_vtk().iter().map(|&i| gmsh_nodes[i]).collect()
    }

    fn elements41(&mut self, raw: &mut Vec<RawElement>) -> R<()> {
        let n_blocks = self.count("number of element blocks")?;
        self.skip_ws_if_ascii();
        let loc_n = self.loc();
        let n_el = self.count("number of elements")?;
        self.size("minimum element tag")?;
        self.size("maximum element tag")?;
        raw.reserve(self.cap(n_el, 8));
        let mut total = 0usize;
        for _ in 0..n_blocks {
            let dim = self.int("entity dimension")?;
            let etag = self.int("entity tag")?;
            self.skip_ws_if_ascii();
            let loc_t = self.loc();
            let t = self.int("element type")?;
            let kind = self.kind_of(t as i64, loc_t)?;
            if dim != kind.dim() {
                return Err(self.err_at(
                    loc_t,
                    format!(
                        "element type {t} ({}) in a block of dimension {dim}",
                        gmsh_type_name(t as i64)
                    ),
                ));
            }
            let n = self.count("number of elements in block")?;
            for _ in 0..n {
                self.skip_ws_if_ascii();
                let loc = self.loc();
                let tag = self.size("element tag")?;
                let mut nodes = Vec::with_capacity(kind.n_nodes());
                for _ in 0..kind.n_nodes() {
                    nodes.push(self.size("element node tag")?);
                }
                raw.push(RawElement {
                    el: GmshElement {
                        kind,
                        tag,
                        nodes: Self::reorder(kind, nodes),
                        physical: Vec::new(),
                        entity: (dim, etag),
                    },
                    loc,
                });
            }
            total = total.saturating_add(n);
        }
        if total != n_el {
            return Err(self.err_at(
                loc_n,
                format!("header declares {n_el} elements but the blocks hold {total}"),
            ));
        }
        Ok(())
    }

    fn elements2(&mut self, raw: &mut Vec<RawElement>) -> R<()> {
        let n = self.ascii_count("number of elements")?;
        raw.reserve(self.cap(n, 8));
        for _ in 0..n {
            self.skip_ws();
            let loc = self.loc();
            let tag: u64 = self.parse_tok("element tag")?;
            self.skip_ws();
            let loc_t = self.loc();
            let t: i64 = self.parse_tok("element type")?;
            let kind = self.kind_of(t, loc_t)?;
            let nt = self.ascii_count("number of element tags")?;
            let mut tags = Vec::with_capacity(self.cap(nt, 2));
            for _ in 0..nt {
                tags.push(self.parse_tok::<i32>("element tag value")?);
            }
            let mut nodes = Vec::with_capacity(kind.n_nodes());
            for _ in 0..kind.n_nodes() {
                nodes.push(self.parse_tok::<u64>("element node tag")?);
            }
            let physical = match tags.first() {
                Some(&p) if p != 0 => vec![p],
                _ => Vec::new(),
            };
            raw.push(RawElement {
                el: GmshElement {
                    kind,
                    tag,
                    nodes: Self::reorder(kind, nodes),
                    physical,
                    entity: (kind.dim(), tags.get(1).copied().unwrap_or(0)),
                },
                loc,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Mesh used by all format tests: a 5 × 3 lattice of nodes (tag 1 + i + 5j at
    // (0.5 i, 0.5 j)), two Q9, one Q8, one Q4, a 3-node and a 2-node line and a point.
    const V41: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
4
2 10 "concrete"
2 11 "other"
1 20 "bottom"
0 30 "support point"
$EndPhysicalNames
$Entities
1 2 2 0
1 0 0 0 1 30
1 0 0 0 1 0 0 1 20 2 1 -2
2 2 0 0 2 1 0 0 0
1 0 0 0 2 1 0 1 10 0
2 0 0 0 2 1 0 1 11 0
$EndEntities
$Nodes
2 15 1 15
1 1 1 3
1
2
3
0 0 0 0
0.5 0 0 0.25
1 0 0 0.5
2 1 0 12
4
5
6
7
8
9
10
11
12
13
14
15
1.5 0 0
2 0 0
0 0.5 0
0.5 0.5 0
1 0.5 0
1.5 0.5 0
2 0.5 0
0 1 0
0.5 1 0
1 1 0
1.5 1 0
2 1 0
$EndNodes
$Elements
6 7 1 7
2 1 10 2
1 1 3 13 11 2 8 12 6 7
2 3 5 15 13 4 10 14 8 9
2 2 16 1
3 3 5 15 13 4 10 14 8
2 2 3 1
4 1 3 13 11
1 1 8 1
5 1 3 2
1 2 1 1
6 5 15
0 1 15 1
7 1
$EndElements
$Comments
anything here is skipped
$EndComments
"#;

    const V22: &str = r#"$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
4
2 10 "concrete"
2 11 "other"
1 20 "bottom"
0 30 "support point"
$EndPhysicalNames
$Nodes
15
1 0 0 0
2 0.5 0 0
3 1 0 0
4 1.5 0 0
5 2 0 0
6 0 0.5 0
7 0.5 0.5 0
8 1 0.5 0
9 1.5 0.5 0
10 2 0.5 0
11 0 1 0
12 0.5 1 0
13 1 1 0
14 1.5 1 0
15 2 1 0
$EndNodes
$Elements
7
1 10 2 10 1 1 3 13 11 2 8 12 6 7
2 10 2 10 1 3 5 15 13 4 10 14 8 9
3 16 2 11 2 3 5 15 13 4 10 14 8
4 3 2 11 2 1 3 13 11
5 8 2 20 1 1 3 2
6 1 2 0 2 5 15
7 15 2 30 1 1
$EndElements
"#;

    /// Binary 4.1 encoding of the same mesh (`big` = big-endian, `marker` = endianness int).
    fn binary41(big: bool, marker: i32) -> Vec<u8> {
        let mut b: Vec<u8> = Vec::new();
        let i = |b: &mut Vec<u8>, v: i32| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let z = |b: &mut Vec<u8>, v: u64| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let d = |b: &mut Vec<u8>, v: f64| {
            b.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        b.extend(b"$MeshFormat\n4.1 1 8\n");
        i(&mut b, marker);
        b.extend(b"\n$EndMeshFormat\n$PhysicalNames\n4\n2 10 \"concrete\"\n2 11 \"other\"\n");
        b.extend(b"1 20 \"bottom\"\n0 30 \"support point\"\n$EndPhysicalNames\n$Entities\n");
        for n in [1u64, 2, 2, 0] {
            z(&mut b, n);
        }
        // point 1
        i(&mut b, 1);
        for _ in 0..3 {
            d(&mut b, 0.0);
        }
        z(&mut b, 1);
        i(&mut b, 30);
        // curves and surfaces: (tag, phys, bounding)
        let ents: [(i32, Vec<i32>, Vec<i32>); 4] = [
            (1, vec![20], vec![1, -2]),
            (2, vec![], vec![]),
            (1, vec![10], vec![]),
            (2, vec![11], vec![]),
        ];
        for (tag, phys, bnd) in ents.iter() {
            i(&mut b, *tag);
            for v in [0.0, 0.0, 0.0, 2.0, 1.0, 0.0] {
                d(&mut b, v);
            }
            z(&mut b, phys.len() as u64);
            for p in phys {
                i(&mut b, *p);
            }
            z(&mut b, bnd.len() as u64);
            for p in bnd {
                i(&mut b, *p);
            }
        }
        b.extend(b"\n$EndEntities\n$Nodes\n");
        for v in [2u64, 15, 1, 15] {
            z(&mut b, v);
        }
        let xy = |t: u64| [((t - 1) % 5) as f64 * 0.5, ((t - 1) / 5) as f64 * 0.5];
        // block 1: curve 1, parametric, nodes 1..3
        i(&mut b, 1);
        i(&mut b, 1);
        i(&mut b, 1);
        z(&mut b, 3);
        for t in 1..=3u64 {
            z(&mut b, t);
        }
        for t in 1..=3u64 {
            let p = xy(t);
            d(&mut b, p[0]);
            d(&mut b, p[1]);
            d(&mut b, 0.0);
            d(&mut b, 0.25 * (t - 1) as f64);
        }
        i(&mut b, 2);
        i(&mut b, 1);
        i(&mut b, 0);
        z(&mut b, 12);
        for t in 4..=15u64 {
            z(&mut b, t);
        }
        for t in 4..=15u64 {
            let p = xy(t);
            d(&mut b, p[0]);
            d(&mut b, p[1]);
            d(&mut b, 0.0);
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for v in [6u64, 7, 1, 7] {
            z(&mut b, v);
        }
        let blocks: [(i32, i32, i32, Vec<Vec<u64>>); 6] = [
            (
                2,
                1,
                10,
                vec![
                    vec![1, 1, 3, 13, 11, 2, 8, 12, 6, 7],
                    vec![2, 3, 5, 15, 13, 4, 10, 14, 8, 9],
                ],
            ),
            (2, 2, 16, vec![vec![3, 3, 5, 15, 13, 4, 10, 14, 8]]),
            (2, 2, 3, vec![vec![4, 1, 3, 13, 11]]),
            (1, 1, 8, vec![vec![5, 1, 3, 2]]),
            (1, 2, 1, vec![vec![6, 5, 15]]),
            (0, 1, 15, vec![vec![7, 1]]),
        ];
        for (dim, tag, ty, els) in blocks.iter() {
            i(&mut b, *dim);
            i(&mut b, *tag);
            i(&mut b, *ty);
            z(&mut b, els.len() as u64);
            for e in els {
                for v in e {
                    z(&mut b, *v);
                }
            }
        }
        b.extend(b"\n$EndElements\n");
        b
    }

    /// Nodes, elements and physical names: the version-independent content.
    type Content<'a> = (
        &'a [(u64, [f64; 2])],
        &'a [GmshElement],
        &'a [(i32, i32, String)],
    );

    /// Version-independent content.
    fn content(m: &GmshMesh) -> Content<'_> {
        (&m.nodes, &m.elements, &m.physical_names)
    }

    #[test]
    fn ascii41_ascii22_and_binary41_agree() {
        let a = parse_msh(V41.as_bytes(), "a.msh").unwrap();
        let b = parse_msh(V22.as_bytes(), "b.msh").unwrap();
        let c = parse_msh(&binary41(false, 1), "c.msh").unwrap();
        let d = parse_msh(&binary41(true, 1), "d.msh").unwrap();
        assert_eq!(content(&a), content(&b));
        assert_eq!(content(&a), content(&c));
        assert_eq!(content(&a), content(&d));
        assert!(c.binary && !a.binary && a.version == "4.1" && b.version == "2.2");
        assert_eq!(a.nodes.len(), 15);
        assert_eq!(a.elements.len(), 7);
        let kinds: Vec<_> = a.elements.iter().map(|e| e.kind).collect();
        use GmshElementKind::*;
        assert_eq!(
            kinds,
            [
                Surface(ElementKind::Q9),
                Surface(ElementKind::Q9),
                Surface(ElementKind::Q8),
                Surface(ElementKind::Q4),
                Line3,
                Line2,
                Point
            ]
        );
        assert_eq!(a.elements[0].physical, [10]);
        assert_eq!(a.elements[2].physical, [11]);
        assert_eq!(a.elements[4].physical, [20]);
        assert!(a.elements[5].physical.is_empty());
        assert_eq!(a.elements[6].physical, [30]);
        assert_eq!(a.elements[2].entity, (2, 2));
        assert_eq!(a.physical_tag(0, "support point"), Some(30));
        assert_eq!(a.physical_tag(1, "bottom"), Some(20));
    }

    /// Gmsh node order = VTK order for Q8/Q9/3-node lines: mid-edge node k lies at the
    /// midpoint of edge k of `ElementKind::edges`, the centre at the centroid, the element is
    /// counter-clockwise (positive Jacobian), and a 3-node line's middle node is the midpoint.
    #[test]
    fn node_order_is_vtk() {
        let m = parse_msh(V41.as_bytes(), "a.msh").unwrap();
        let idx = m.node_index();
        let x = |t: u64| m.nodes[idx[&t]].1;
        for el in &m.elements {
            let xs: Vec<[f64; 2]> = el.nodes.iter().map(|&t| x(t)).collect();
            if let Some(q) = el.kind.element_kind() {
                for en in q.edges() {
                    if en.len() == 3 {
                        for d in 0..2 {
                            let mid = 0.5 * (xs[en[0]][d] + xs[en[1]][d]);
                            assert!((xs[en[2]][d] - mid).abs() < 1e-15);
                        }
                    }
                }
                if q == ElementKind::Q9 {
                    for d in 0..2 {
                        let c = 0.25 * (xs[0][d] + xs[1][d] + xs[2][d] + xs[3][d]);
                        assert!((xs[8][d] - c).abs() < 1e-15);
                    }
                }
                let s = q.eval(0.1, 0.2);
                let (_, det, _) = crate::fem::shape::jacobian(&s, &xs);
                assert!(det > 0.0);
            }
            if el.kind == GmshElementKind::Line3 {
                assert_eq!(xs[2], [0.5, 0.0]);
                assert_eq!((xs[0], xs[1]), ([0.0, 0.0], [1.0, 0.0]));
            }
        }
    }

    fn err_of(bytes: &[u8]) -> String {
        match parse_msh(bytes, "bad.msh") {
            Ok(_) => panic!("expected an error"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn malformed_inputs_are_errors() {
        // Triangles are named.
        let tri = V22.replace("4 3 2 11 2 1 3 13 11", "4 2 2 11 2 1 3 13");
        let e = err_of(tri.as_bytes());
        assert!(
            e.contains("element type 2 (3-node triangle)") && e.contains("line 34"),
            "{e}"
        );
        let tri41 = V41.replace("2 2 3 1\n4 1 3 13 11", "2 2 2 1\n4 1 3 13");
        let e = err_of(tri41.as_bytes());
        assert!(
            e.contains("bad.msh") && e.contains("3-node triangle"),
            "{e}"
        );
        // Unknown node tag.
        let e = err_of(V22.replace("6 1 2 0 2 5 15", "6 1 2 0 2 5 99").as_bytes());
        assert!(
            e.contains("unknown node 99") && e.contains("line 36"),
            "{e}"
        );
        // Bad counts.
        let e = err_of(V41.replace("2 15 1 15", "2 16 1 15").as_bytes());
        assert!(e.contains("declares 16 nodes"), "{e}");
        let e = err_of(V41.replace("6 7 1 7", "6 8 1 7").as_bytes());
        assert!(e.contains("declares 8 elements"), "{e}");
        // Huge counts: no absurd allocation, clear error.
        let e = err_of(
            V22.replace("$Nodes\n15", "$Nodes\n18446744073709551615")
                .as_bytes(),
        );
        assert!(e.contains("exceeds"), "{e}");
        let e = err_of(V22.replace("$Nodes\n15", "$Nodes\n40").as_bytes());
        assert!(
            e.contains("expected node tag") || e.contains("end of file"),
            "{e}"
        );
        // Truncation at every length never panics and always errors.
        for cut in 0..V41.find("$EndElements").unwrap() + 11 {
            assert!(parse_msh(&V41.as_bytes()[..cut], "t.msh").is_err());
        }
        let bin = binary41(false, 1);
        for cut in 0..bin.len() - 16 {
            assert!(parse_msh(&bin[..cut], "t.msh").is_err(), "cut {cut}");
        }
        // Wrong endianness marker.
        let e = err_of(&binary41(false, 7));
        assert!(
            e.contains("endianness") && e.contains("byte offset 20"),
            "{e}"
        );
        // Unsupported versions / binary 2.2 / data size.
        assert!(err_of(V41.replace("4.1 0 8", "4.0 0 8").as_bytes()).contains("4.0"));
        assert!(err_of(V22.replace("2.2 0 8", "2.2 1 8").as_bytes()).contains("binary MSH 2.2"));
        assert!(err_of(V41.replace("4.1 0 8", "4.1 0 4").as_bytes()).contains("data-size"));
        // Not a mesh, bad numbers, duplicates, missing sections, unterminated names.
        assert!(err_of(b"hello").contains("$MeshFormat"));
        let e = err_of(V22.replace("3 1 0 0", "3 1 zero 0").as_bytes());
        assert!(
            e.contains("expected y coordinate, found 'zero'") && e.contains("line 15"),
            "{e}"
        );
        assert!(err_of(V22.replace("4 1.5 0 0", "3 1.5 0 0").as_bytes()).contains("twice"));
        assert!(err_of(V22.replace("\"bottom\"", "\"bottom").as_bytes()).contains("quote"));
        let no_el = &V22[..V22.find("$Elements").unwrap()];
        assert!(err_of(no_el.as_bytes()).contains("no $Elements"));
        assert!(err_of(V41.replace("$EndComments", "").as_bytes()).contains("$EndComments"));
        assert!(err_of(V22.replace("2 0.5 0 0", "2 nan 0 0").as_bytes()).contains("finite"));
    }

    #[test]
    fn reads_files_and_names_them() {
        let dir = std::env::temp_dir().join(format!("segfem-gmsh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("m.msh");
        std::fs::write(&p, binary41(false, 1)).unwrap();
        let m = read_msh(&p).unwrap();
        assert_eq!(m.elements.len(), 7);
        let e = read_msh(&dir.join("missing.msh")).unwrap_err().to_string();
        assert!(e.contains("missing.msh") && e.contains("cannot read"));
        std::fs::remove_dir_all(&dir).ok();
    }

    proptest::proptest! {
        // Fixed seed: the same cases on every run; failures persist in proptest-regressions/.
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: 300,
            rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5e6f_e025),
            ..proptest::prelude::ProptestConfig::default()
        })]
        /// Random byte mutations of valid ASCII and binary files never panic.
        #[test]
        fn mutations_never_panic(
            muts in proptest::collection::vec((0usize..100_000, 0u8..=255), 1..8),
            which in 0usize..3,
        ) {
            let mut b = match which {
                0 => V41.as_bytes().to_vec(),
                1 => V22.as_bytes().to_vec(),
                _ => binary41(false, 1),
            };
            for (pos, v) in muts {
                let n = b.len();
                b[pos % n] = v;
            }
            let _ = parse_msh(&b, "fuzz.msh");
        }
    }
}
