//! The walk over a message's numeric leaves: a serde [`Serializer`] that sees every field of a
//! message (serde mirrors serialize every field in declaration order, nested messages and
//! arrays included) with its path.

use serde::ser::{
    Serialize, SerializeMap, SerializeSeq, SerializeStruct, SerializeStructVariant, SerializeTuple,
    SerializeTupleStruct, SerializeTupleVariant, Serializer,
};

use super::rule::{find_rule, Rule, Section};
use super::{Number, NumberError};

/// One numeric leaf of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Leaf {
    /// Its path, e.g. `points[3].x`.
    pub path: String,
    /// Its normalized key (indices as `[]`), e.g. `points[].x`: what rules match.
    pub key: String,
    /// Its value.
    pub value: Number,
}

/// Every numeric leaf of `msg`, in declaration order.
pub fn leaves<T: Serialize + ?Sized>(msg: &T) -> Vec<Leaf> {
    let mut out = Vec::new();
    let mut visit = |w: &Position, event: Event| {
        if let Event::Number(value) = event {
            out.push(Leaf {
                path: w.path(),
                key: w.key.clone(),
                value,
            });
        }
        Ok(())
    };
    let mut walker = Walker::new(&mut visit);
    // The walker never fails unless the visitor does, and this one does not.
    let _ = msg.serialize(&mut walker);
    out
}

/// Checks every numeric leaf of `msg` against the rules of `sections`; a leaf without a rule
/// is checked finite.
///
/// # Errors
/// The first leaf outside its rule.
pub fn check<T: Serialize + ?Sized>(msg: &T, sections: &[Section]) -> Result<(), NumberError> {
    let mut flags: Vec<(String, bool)> = Vec::new();
    // The rules of the keys seen so far (a message has a few dozen keys; an array's elements
    // share theirs): one lookup per key, not per leaf.
    let mut seen: Vec<(String, Option<(&'static str, &'static Rule)>)> = Vec::new();
    let mut last = 0usize;
    let mut visit = |w: &Position, event: Event| match event {
        Event::Flag(v) => {
            flags.push((w.key.clone(), v));
            Ok(())
        }
        Event::Number(value) => {
            if seen.get(last).is_none_or(|(k, _)| *k != w.key) {
                last = match seen.iter().position(|(k, _)| *k == w.key) {
                    Some(i) => i,
                    None => {
                        seen.push((w.key.clone(), find_rule(sections, &w.key)));
                        seen.len() - 1
                    }
                };
            }
            let cached = seen.get(last).and_then(|(_, r)| *r);
            let result = match cached {
                None => match value.as_f64().is_finite() {
                    true => Ok(()),
                    false => Err("must be finite".to_string()),
                },
                Some((prefix, rule)) => {
                    let applies = rule.when.is_none_or(|flag| {
                        flags
                            .iter()
                            .find(|(k, _)| k.strip_prefix(prefix).is_some_and(|rest| rest == flag))
                            .is_none_or(|(_, v)| *v)
                    });
                    rule.check(value, applies)
                }
            };
            result.map_err(|rule| NumberError {
                field: w.path(),
                value: value.to_string(),
                rule,
            })
        }
    };
    let mut walker = Walker::new(&mut visit);
    msg.serialize(&mut walker).map_err(|e| match e {
        WalkError::Number(n) => n,
        WalkError::Other(text) => NumberError {
            field: String::new(),
            value: String::new(),
            rule: text,
        },
    })
}

/// Checks one value of a text request by its message field `path` (with indices, e.g.
/// `points[2].y`) against the rules of `sections`, the field applying (a text form gives a
/// value only where it is used).
///
/// # Errors
/// The value outside its rule (a field without a rule: not finite).
pub fn check_value(sections: &[Section], path: &str, value: Number) -> Result<(), NumberError> {
    let key = normalize(path);
    let result = match find_rule(sections, &key) {
        Some((_, rule)) => rule.check(value, true),
        None if value.as_f64().is_finite() => Ok(()),
        None => Err("must be finite".to_string()),
    };
    result.map_err(|rule| NumberError {
        field: path.to_string(),
        value: value.to_string(),
        rule,
    })
}

/// `path` with every `[digits]` replaced by `[]`.
fn normalize(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push_str("[]");
            }
            ']' => in_index = false,
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

/// What the walker reports.
pub(crate) enum Event {
    /// A numeric leaf.
    Number(Number),
    /// A `bool` leaf (a `has_*` flag).
    Flag(bool),
}

/// Why a walk stopped.
#[derive(Debug)]
pub(crate) enum WalkError {
    /// A leaf outside its rule.
    Number(NumberError),
    /// A serde error (a mirror never raises one).
    Other(String),
}

impl std::fmt::Display for WalkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WalkError::Number(n) => n.fmt(f),
            WalkError::Other(t) => f.write_str(t),
        }
    }
}

impl std::error::Error for WalkError {}

impl serde::ser::Error for WalkError {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        WalkError::Other(msg.to_string())
    }
}

/// One step of a path.
#[derive(Debug, Clone, Copy)]
enum Seg {
    Field(&'static str),
    Index(usize),
}

/// Where the walk is: the path's steps, and its normalized key kept incrementally.
pub(crate) struct Position {
    segs: Vec<Seg>,
    key: String,
    key_lens: Vec<usize>,
}

impl Position {
    /// The current path, e.g. `points[3].x`.
    fn path(&self) -> String {
        let mut out = String::new();
        for seg in &self.segs {
            match seg {
                Seg::Field(name) => {
                    if !out.is_empty() {
                        out.push('.');
                    }
                    out.push_str(name);
                }
                Seg::Index(i) => out.push_str(&format!("[{i}]")),
            }
        }
        out
    }

    fn push(&mut self, seg: Seg) {
        self.key_lens.push(self.key.len());
        match seg {
            Seg::Field(name) => {
                if !self.key.is_empty() {
                    self.key.push('.');
                }
                self.key.push_str(name);
            }
            Seg::Index(_) => self.key.push_str("[]"),
        }
        self.segs.push(seg);
    }

    fn pop(&mut self) {
        self.segs.pop();
        if let Some(len) = self.key_lens.pop() {
            self.key.truncate(len);
        }
    }
}

type Visit<'v> = dyn FnMut(&Position, Event) -> Result<(), NumberError> + 'v;

/// The serializer: the position and what to do at each leaf.
pub(crate) struct Walker<'v> {
    at: Position,
    visit: &'v mut Visit<'v>,
}

impl<'v> Walker<'v> {
    fn new(visit: &'v mut Visit<'v>) -> Self {
        Walker {
            at: Position {
                segs: Vec::new(),
                key: String::new(),
                key_lens: Vec::new(),
            },
            visit,
        }
    }

    fn emit(&mut self, event: Event) -> Result<(), WalkError> {
        (self.visit)(&self.at, event).map_err(WalkError::Number)
    }

    fn int(&mut self, value: i128, min: i128, max: i128) -> Result<(), WalkError> {
        self.emit(Event::Number(Number::Int { value, min, max }))
    }

    fn nested<T: Serialize + ?Sized>(&mut self, seg: Seg, value: &T) -> Result<(), WalkError> {
        self.at.push(seg);
        let r = value.serialize(&mut *self);
        self.at.pop();
        r
    }
}

/// A sequence, tuple or map being walked: the next index.
pub(crate) struct Items<'a, 'v> {
    walker: &'a mut Walker<'v>,
    next: usize,
}

impl<'a, 'v> Items<'a, 'v> {
    /// Starts a sequence: its index step is pushed once and updated per element (the key,
    /// `[]`, is the same for every element).
    fn start(walker: &'a mut Walker<'v>) -> Self {
        walker.at.push(Seg::Index(0));
        Items { walker, next: 0 }
    }

    fn item<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        if let Some(last) = self.walker.at.segs.last_mut() {
            *last = Seg::Index(self.next);
        }
        self.next += 1;
        value.serialize(&mut *self.walker)
    }

    fn finish(self) -> Result<(), WalkError> {
        self.walker.at.pop();
        Ok(())
    }
}

macro_rules! ints {
    ($($method:ident: $ty:ty),*) => {$(
        fn $method(self, v: $ty) -> Result<(), WalkError> {
            self.int(i128::from(v), i128::from(<$ty>::MIN), i128::from(<$ty>::MAX))
        }
    )*};
}

impl<'a, 'v> Serializer for &'a mut Walker<'v> {
    type Ok = ();
    type Error = WalkError;
    type SerializeSeq = Items<'a, 'v>;
    type SerializeTuple = Items<'a, 'v>;
    type SerializeTupleStruct = Items<'a, 'v>;
    type SerializeTupleVariant = Items<'a, 'v>;
    type SerializeMap = Items<'a, 'v>;
    type SerializeStruct = &'a mut Walker<'v>;
    type SerializeStructVariant = &'a mut Walker<'v>;

    ints!(serialize_i8: i8, serialize_i16: i16, serialize_i32: i32, serialize_i64: i64,
          serialize_u8: u8, serialize_u16: u16, serialize_u32: u32, serialize_u64: u64);

    fn serialize_bool(self, v: bool) -> Result<(), WalkError> {
        self.emit(Event::Flag(v))
    }
    fn serialize_f32(self, v: f32) -> Result<(), WalkError> {
        self.emit(Event::Number(Number::Float(f64::from(v))))
    }
    fn serialize_f64(self, v: f64) -> Result<(), WalkError> {
        self.emit(Event::Number(Number::Float(v)))
    }
    fn serialize_char(self, _: char) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_str(self, _: &str) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_none(self) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), WalkError> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
    ) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), WalkError> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), WalkError> {
        self.nested(Seg::Field(variant), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Items<'a, 'v>, WalkError> {
        Ok(Items::start(self))
    }
    fn serialize_tuple(self, _: usize) -> Result<Items<'a, 'v>, WalkError> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Items<'a, 'v>, WalkError> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Items<'a, 'v>, WalkError> {
        self.serialize_seq(None)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Items<'a, 'v>, WalkError> {
        self.serialize_seq(None)
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<&'a mut Walker<'v>, WalkError> {
        Ok(self)
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<&'a mut Walker<'v>, WalkError> {
        Ok(self)
    }
}

impl SerializeSeq for Items<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        self.item(value)
    }
    fn end(self) -> Result<(), WalkError> {
        self.finish()
    }
}

impl SerializeTuple for Items<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        self.item(value)
    }
    fn end(self) -> Result<(), WalkError> {
        self.finish()
    }
}

impl SerializeTupleStruct for Items<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        self.item(value)
    }
    fn end(self) -> Result<(), WalkError> {
        self.finish()
    }
}

impl SerializeTupleVariant for Items<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        self.item(value)
    }
    fn end(self) -> Result<(), WalkError> {
        self.finish()
    }
}

impl SerializeMap for Items<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, _: &T) -> Result<(), WalkError> {
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), WalkError> {
        self.item(value)
    }
    fn end(self) -> Result<(), WalkError> {
        self.finish()
    }
}

impl SerializeStruct for &mut Walker<'_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), WalkError> {
        self.nested(Seg::Field(key), value)
    }
    fn end(self) -> Result<(), WalkError> {
        Ok(())
    }
}

impl SerializeStructVariant for &mut Walker<'_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), WalkError> {
        self.nested(Seg::Field(key), value)
    }
    fn end(self) -> Result<(), WalkError> {
        Ok(())
    }
}
