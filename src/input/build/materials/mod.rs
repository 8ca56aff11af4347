//! `[[materials]]`: the table read once for every kind, and one file per kind owning its
//! schema (keys with type, unit, default and meaning; checks; default thermal expansion)
//! beside its builder: elastic, elastic_creep, concrete, rebar, prestressing_steel.
//!
//! The generic part is here: reading a table (every key typed by the kinds' key lists, so a
//! misspelt key or a wrong type is refused by the parser with its line), the `kind`
//! dispatch, and the refusal of a key that is not one of the table's kind. A new kind is a
//! file with its [`Schema`] (a `SCHEMA` constant) and one line in the `kinds!` list below.

use super::R;
use crate::input::error::{Ctx, InputError};
use crate::materials::point::Material;
use crate::materials::steel::SteelParams;
use crate::model::{NamedMaterial, Strength};
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;
use std::fmt;

/// The type of a key's value.
#[derive(Debug, Clone, Copy)]
pub enum KeyType {
    /// A number (a TOML float or integer).
    Number,
    /// A whole number ≥ 0.
    Count,
    /// A string.
    Text,
    /// A boolean.
    Flag,
    /// An inline table with these keys (`viscoplastic = { ... }`).
    Table(&'static [Key]),
}

/// One key of a material kind, as docs/input.md documents it.
#[derive(Debug, Clone, Copy)]
pub struct Key {
    /// TOML spelling (`E`, `fcm`).
    pub name: &'static str,
    /// Type of its value.
    pub ty: KeyType,
    /// Unit (`Pa`, `kg/m³`, `1/K`; `-` for a ratio or a choice).
    pub unit: &'static str,
    /// Default, as the user reads it (`required`, `0.2`, `MC90 from fcm`, `none`).
    pub default: &'static str,
    /// One-line meaning.
    pub doc: &'static str,
}

impl Key {
    /// A number.
    pub const fn number(
        name: &'static str,
        unit: &'static str,
        default: &'static str,
        doc: &'static str,
    ) -> Key {
        Key {
            name,
            ty: KeyType::Number,
            unit,
            default,
            doc,
        }
    }

    /// A key of another type.
    pub const fn typed(
        name: &'static str,
        ty: KeyType,
        default: &'static str,
        doc: &'static str,
    ) -> Key {
        Key {
            name,
            ty,
            unit: "-",
            default,
            doc,
        }
    }
}

/// `thermal_expansion`, a key of every kind (its default is the kind's
/// [`Schema::thermal_expansion`]); checked with the thermal actions (build/loads.rs).
pub const THERMAL_EXPANSION: Key = Key::number(
    "thermal_expansion",
    "1/K",
    "the kind's (Schema::thermal_expansion)",
    "coefficient of thermal expansion α of thermal actions, in [0, 1e-3)",
);

/// What a kind builds: a continuum law for regions (with the strength an elastic concrete
/// is checked against), or the uniaxial steel of bars.
pub enum Law {
    /// For `[[regions]]`.
    Region {
        /// The law.
        law: Material,
        /// Strengths checked against (elastic concrete), None when not checked.
        strength: Option<Strength>,
    },
    /// For `[[bars]]`, `[[bar_layers]]` and bonded tendons.
    Bar(SteelParams),
}

/// A material kind's schema: the one place its keys, checks and defaults are given.
pub struct Schema {
    /// The `kind` value in the model file.
    pub name: &'static str,
    /// The keys a table of this kind takes besides `name` and `kind`, in the order
    /// messages list them.
    pub keys: &'static [Key],
    /// Keys of other kinds refused with a message of their own (checked before the
    /// "not a key of kind" error): (key, message).
    pub refused: &'static [(&'static str, &'static str)],
    /// Coefficient of thermal expansion [1/K] when `thermal_expansion` is not given; None:
    /// a thermal load case heating the material requires the key.
    pub thermal_expansion: Option<f64>,
    /// Checks the table and builds its law.
    pub build: fn(&Table, &mut Vec<String>) -> R<Law>,
}

/// The kinds: one line each (a doc comment, the variant, its module's file). Generates
/// the `mod` lines, [`MaterialKind`], `ALL` and `schema`.
macro_rules! kinds {
    ($($(#[$doc:meta])* $variant:ident => $module:ident,)+) => {
        $(mod $module;)+

        /// The kinds of `[[materials]]` (`kind = "..."`), one per material law the model
        /// file offers; each owns its [`Schema`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum MaterialKind {
            $($(#[$doc])* $variant,)+
        }

        impl MaterialKind {
            /// Every kind, in the order messages list them.
            pub const ALL: &'static [MaterialKind] = &[$(MaterialKind::$variant,)+];

            /// The kind's schema.
            pub fn schema(self) -> &'static Schema {
                match self {
                    $(MaterialKind::$variant => &$module::SCHEMA,)+
                }
            }

            /// The source of the kind's file, for the test that its builder reads only
            /// keys its schema declares.
            #[cfg(test)]
            fn source(self) -> &'static str {
                match self {
                    $(MaterialKind::$variant => include_str!(concat!(stringify!($module), ".rs")),)+
                }
            }
        }
    };
}

kinds! {
    /// Linear elastic isotropic (regions).
    Elastic => elastic,
    /// Ageing linear viscoelastic concrete: MC90 creep and shrinkage (regions).
    ElasticCreep => elastic_creep,
    /// Plane-stress concrete: MC90/Ottosen plasticity and smeared cracking (regions).
    Concrete => concrete,
    /// Reinforcing steel, bilinear (bars and bar layers).
    Rebar => rebar,
    /// Prestressing steel (bars and bar layers).
    PrestressingSteel => prestressing_steel,
}

impl MaterialKind {
    /// The `kind` value in the model file.
    pub fn name(self) -> &'static str {
        self.schema().name
    }

    /// The names of the keys a table of this kind takes besides `name` and `kind` (schema
    /// spelling, in the order messages list them).
    pub fn keys(self) -> Vec<&'static str> {
        self.schema().keys.iter().map(|k| k.name).collect()
    }

    /// The kind named `s`, if any.
    pub fn from_name(s: &str) -> Option<MaterialKind> {
        MaterialKind::ALL.iter().copied().find(|k| k.name() == s)
    }

    /// The kind named `s` in `materials[i].kind`.
    fn parse(ctx: &Ctx, i: usize, s: &str) -> R<MaterialKind> {
        MaterialKind::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = MaterialKind::ALL.iter().map(|k| k.name()).collect();
            let (last, rest) = names.split_last().expect("kinds exist");
            ctx.err(
                format!("materials[{i}].kind"),
                format!(
                    "unknown material kind '{s}' (expected {} or {last})",
                    rest.join(", ")
                ),
            )
        })
    }
}

/// A value as read, typed by its key's [`KeyType`].
#[derive(Debug, Clone)]
enum Value {
    Number(f64),
    Count(usize),
    Text(String),
    Flag(bool),
    Table(BTreeMap<&'static str, Value>),
}

/// A `[[materials]]` table as read: its name, kind and the keys given (typed by the kinds'
/// schemas; a key of no kind is refused by the parser, a key of another kind by
/// [`build`]). Documented key by key in docs/input.md.
#[derive(Debug, Clone)]
pub struct MaterialIn {
    /// `name`.
    pub name: String,
    /// `kind`, as written.
    pub kind: String,
    values: BTreeMap<&'static str, Value>,
}

impl MaterialIn {
    /// A number given at `key` (top-level key of the table), None when absent.
    pub fn number(&self, key: &str) -> Option<f64> {
        match self.values.get(key) {
            Some(Value::Number(v)) => Some(*v),
            _ => None,
        }
    }

    /// The coefficient of thermal expansion [1/K]: the `thermal_expansion` given, else the
    /// kind's default ([`Schema::thermal_expansion`]); None for neither (or an unknown kind,
    /// refused by [`build`]).
    pub fn thermal_expansion(&self) -> Option<f64> {
        self.number(THERMAL_EXPANSION.name).or_else(|| {
            MaterialKind::from_name(&self.kind).and_then(|k| k.schema().thermal_expansion)
        })
    }
}

/// The key definition named `name` among `keys`, or among every kind's keys when `keys` is
/// None (the top level of a table, whose kind may come after its keys).
fn find_key(keys: Option<&'static [Key]>, name: &str) -> Option<&'static Key> {
    match keys {
        Some(list) => list.iter().find(|k| k.name == name),
        None => MaterialKind::ALL
            .iter()
            .flat_map(|k| k.schema().keys.iter())
            .find(|k| k.name == name),
    }
}

/// Every key name of `keys`, or of every kind (first appearance), in message order.
fn key_names(keys: Option<&'static [Key]>) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Vec::new();
    if keys.is_none() {
        names.extend(["name", "kind"]);
    }
    let all: Vec<&'static Key> = match keys {
        Some(list) => list.iter().collect(),
        None => MaterialKind::ALL
            .iter()
            .flat_map(|k| k.schema().keys.iter())
            .collect(),
    };
    for k in all {
        if !names.contains(&k.name) {
            names.push(k.name);
        }
    }
    names
}

/// A key of a table: known to the schema (top level: `name`, `kind` or a key of some kind),
/// else serde's "unknown field" error, raised while the key is read so that it carries the
/// key's line.
struct KeySeed(Option<&'static [Key]>);

impl<'de> DeserializeSeed<'de> for KeySeed {
    type Value = &'static str;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<&'static str, D::Error> {
        d.deserialize_str(self)
    }
}

impl Visitor<'_> for KeySeed {
    type Value = &'static str;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a key")
    }
    fn visit_str<E: de::Error>(self, s: &str) -> Result<&'static str, E> {
        if self.0.is_none() {
            if s == "name" {
                return Ok("name");
            }
            if s == "kind" {
                return Ok("kind");
            }
        }
        match find_key(self.0, s) {
            Some(k) => Ok(k.name),
            None => {
                let list: Vec<String> =
                    key_names(self.0).iter().map(|n| format!("`{n}`")).collect();
                Err(E::custom(format!(
                    "unknown field `{s}`, expected one of {}",
                    list.join(", ")
                )))
            }
        }
    }
}

/// A value of type `KeyType`.
struct ValueSeed(KeyType);

impl<'de> DeserializeSeed<'de> for ValueSeed {
    type Value = Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        Ok(match self.0 {
            KeyType::Number => Value::Number(f64::deserialize(d)?),
            KeyType::Count => Value::Count(usize::deserialize(d)?),
            KeyType::Text => Value::Text(String::deserialize(d)?),
            KeyType::Flag => Value::Flag(bool::deserialize(d)?),
            KeyType::Table(keys) => Value::Table(d.deserialize_map(TableVisitor(keys))?),
        })
    }
}

/// An inline table of a key (`viscoplastic = { ... }`).
struct TableVisitor(&'static [Key]);

impl<'de> Visitor<'de> for TableVisitor {
    type Value = BTreeMap<&'static str, Value>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a table")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut values = BTreeMap::new();
        while let Some(k) = map.next_key_seed(KeySeed(Some(self.0)))? {
            let ty = find_key(Some(self.0), k).expect("KeySeed found it").ty;
            values.insert(k, map.next_value_seed(ValueSeed(ty))?);
        }
        Ok(values)
    }
}

impl<'de> Deserialize<'de> for MaterialIn {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<MaterialIn, D::Error> {
        d.deserialize_map(MaterialVisitor)
    }
}

/// A `[[materials]]` table.
struct MaterialVisitor;

impl<'de> Visitor<'de> for MaterialVisitor {
    type Value = MaterialIn;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a [[materials]] table")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<MaterialIn, A::Error> {
        let (mut name, mut kind) = (None, None);
        let mut values = BTreeMap::new();
        while let Some(k) = map.next_key_seed(KeySeed(None))? {
            match k {
                "name" => name = Some(map.next_value::<String>()?),
                "kind" => kind = Some(map.next_value::<String>()?),
                _ => {
                    let ty = find_key(None, k).expect("KeySeed found it").ty;
                    values.insert(k, map.next_value_seed(ValueSeed(ty))?);
                }
            }
        }
        Ok(MaterialIn {
            kind: kind.ok_or_else(|| de::Error::missing_field("kind"))?,
            name: name.ok_or_else(|| de::Error::missing_field("name"))?,
            values,
        })
    }
}

/// The keys given in one table (or inline table) of a material, for its kind's builder:
/// typed accessors and errors at `materials[i].<key>`.
pub struct Table<'a> {
    ctx: &'a Ctx,
    /// Key path of the table: `materials[2]`, `materials[2].viscoplastic`.
    path: String,
    values: &'a BTreeMap<&'static str, Value>,
}

impl<'a> Table<'a> {
    /// The file's context (for the shared checks of `fields.rs`).
    pub fn ctx(&self) -> &'a Ctx {
        self.ctx
    }

    /// The path of `key`: `materials[2].fcm`.
    pub fn key(&self, key: &str) -> String {
        format!("{}.{key}", self.path)
    }

    /// An error at `key`.
    pub fn err(&self, key: &str, message: impl Into<String>) -> InputError {
        self.ctx.err(self.key(key), message)
    }

    /// An error on the whole table (`materials[2]`).
    pub fn table_err(&self, message: impl Into<String>) -> InputError {
        self.ctx.err(self.path.clone(), message)
    }

    /// Whether `key` is given.
    pub fn has(&self, key: &str) -> bool {
        self.values.contains_key(key)
    }

    /// A number at `key` (a key the schema types as a number).
    pub fn num(&self, key: &str) -> Option<f64> {
        match self.values.get(key) {
            Some(Value::Number(v)) => Some(*v),
            _ => None,
        }
    }

    /// A number at `key`, or the error `missing` there.
    pub fn need(&self, key: &str, missing: &str) -> R<f64> {
        self.num(key).ok_or_else(|| self.err(key, missing))
    }

    /// A steel's modulus and strength [Pa] at `key_e` and `key_f` (rebar: E and fy;
    /// prestressing steel: Ep and fptk): both required and > 0, the strength far below the
    /// modulus (a value in MPa or GPa is refused, with a warning on an unusual magnitude).
    pub fn steel_modulus_and_strength(
        &self,
        warnings: &mut Vec<String>,
        key_e: &str,
        key_f: &str,
    ) -> R<(f64, f64)> {
        use crate::input::build::fields::positive;
        use crate::input::units;
        let e = positive(self.ctx, &self.key(key_e), self.need(key_e, "missing")?)?;
        let f = positive(self.ctx, &self.key(key_f), self.need(key_f, "missing")?)?;
        units::modulus(warnings, self.ctx, &self.key(key_e), e);
        units::strength(warnings, self.ctx, &self.key(key_f), f);
        if f >= e {
            return Err(self.err(key_f, format!("must be far below {key_e} (units are Pa)")));
        }
        Ok((e, f))
    }

    /// A whole number at `key`.
    pub fn count(&self, key: &str) -> Option<usize> {
        match self.values.get(key) {
            Some(Value::Count(v)) => Some(*v),
            _ => None,
        }
    }

    /// A string at `key`.
    pub fn text(&self, key: &str) -> Option<&'a str> {
        match self.values.get(key) {
            Some(Value::Text(v)) => Some(v.as_str()),
            _ => None,
        }
    }

    /// A boolean at `key`.
    pub fn flag(&self, key: &str) -> Option<bool> {
        match self.values.get(key) {
            Some(Value::Flag(v)) => Some(*v),
            _ => None,
        }
    }

    /// The inline table at `key`, its errors at `materials[i].<key>.<subkey>`.
    pub fn sub(&self, key: &str) -> Option<Table<'a>> {
        match self.values.get(key) {
            Some(Value::Table(values)) => Some(Table {
                ctx: self.ctx,
                path: self.key(key),
                values,
            }),
            _ => None,
        }
    }
}

/// A key the table gives that its kind does not take is an error, not silently ignored:
/// first the keys the kind refuses with a message of their own, then any other.
fn check_keys(ctx: &Ctx, i: usize, m: &MaterialIn, schema: &Schema) -> R<()> {
    for (key, message) in schema.refused {
        if m.values.contains_key(key) {
            return Err(ctx.err(format!("materials[{i}].{key}"), *message));
        }
    }
    let allowed: Vec<&str> = schema.keys.iter().map(|k| k.name).collect();
    // In message order (every kind's keys), so the first wrong key is reported.
    for k in key_names(None) {
        if m.values.contains_key(k) && !allowed.contains(&k) {
            return Err(ctx.err(
                format!("materials[{i}].{k}"),
                format!(
                    "not a key of kind '{}' (its keys: {})",
                    m.kind,
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The `[[materials]]`: the continuum laws (for regions), and the steels (`rebar`,
/// `prestressing_steel`) by name for bars and bar layers.
#[allow(clippy::type_complexity)]
pub(super) fn build(
    ctx: &Ctx,
    list: &[MaterialIn],
    warnings: &mut Vec<String>,
) -> R<(Vec<NamedMaterial>, Vec<(String, SteelParams)>)> {
    super::fields::unique_names(ctx, "materials", list.iter().map(|m| m.name.as_str()))?;
    let mut materials = Vec::new();
    let mut steels: Vec<(String, SteelParams)> = Vec::new();
    for (i, m) in list.iter().enumerate() {
        let schema = MaterialKind::parse(ctx, i, &m.kind)?.schema();
        check_keys(ctx, i, m, schema)?;
        let table = Table {
            ctx,
            path: format!("materials[{i}]"),
            values: &m.values,
        };
        match (schema.build)(&table, warnings)? {
            Law::Region { law, strength } => materials.push(NamedMaterial {
                name: m.name.clone(),
                law,
                strength,
            }),
            Law::Bar(steel) => steels.push((m.name.clone(), steel)),
        }
    }
    Ok((materials, steels))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A key two kinds share has one type (a table is read before its kind is known), and
    /// no kind lists a key twice.
    #[test]
    fn shared_keys_have_one_type() {
        let ty = |k: &Key| format!("{:?}", k.ty);
        for a in MaterialKind::ALL {
            let keys = a.schema().keys;
            for (n, k) in keys.iter().enumerate() {
                assert!(
                    !keys[..n].iter().any(|x| x.name == k.name),
                    "{} lists {} twice",
                    a.name(),
                    k.name
                );
                let first = find_key(None, k.name).unwrap();
                assert_eq!(ty(first), ty(k), "{} of {}", k.name, a.name());
            }
            assert!(keys.iter().any(|k| k.name == THERMAL_EXPANSION.name));
            for (r, _) in a.schema().refused {
                assert!(
                    !keys.iter().any(|k| k.name == *r),
                    "{} refuses its own {r}",
                    a.name()
                );
                assert!(find_key(None, r).is_some(), "{r} is no kind's key");
            }
        }
    }

    /// Every key a kind's file reads through its `Table` (`t.num("E")`, `t.text(..)`, …,
    /// `t.err("E", ..)`) is declared in that kind's schema (inline tables' keys included), with
    /// the type the accessor reads: an accessor of the wrong type would read None, silently.
    #[test]
    fn builders_read_only_keys_their_schema_declares() {
        let mut reads = 0;
        for kind in MaterialKind::ALL {
            let mut declared: Vec<(&str, String)> = Vec::new();
            for k in kind.schema().keys {
                declared.push((k.name, format!("{:?}", k.ty)));
                if let KeyType::Table(sub) = k.ty {
                    declared.extend(sub.iter().map(|x| (x.name, format!("{:?}", x.ty))));
                }
            }
            let src = kind.source();
            for (call, ty) in [
                ("t.num(\"", Some("Number")),
                ("t.need(\"", Some("Number")),
                ("t.count(\"", Some("Count")),
                ("t.text(\"", Some("Text")),
                ("t.flag(\"", Some("Flag")),
                ("t.sub(\"", Some("Table")),
                ("t.has(\"", None),
                ("t.err(\"", None),
                ("t.key(\"", None),
            ] {
                for (at, _) in src.match_indices(call) {
                    let rest = &src[at + call.len()..];
                    let key = &rest[..rest.find('"').unwrap()];
                    reads += 1;
                    let found = declared.iter().find(|(n, _)| *n == key);
                    let Some((_, declared_ty)) = found else {
                        panic!("{}.rs reads {key}, not a key of its schema", kind.name());
                    };
                    if let Some(ty) = ty {
                        assert!(
                            declared_ty.starts_with(ty),
                            "{}.rs reads {key} with {call}…), declared {declared_ty}",
                            kind.name()
                        );
                    }
                }
            }
        }
        assert!(reads > 100, "{reads} key reads found");
    }
}
