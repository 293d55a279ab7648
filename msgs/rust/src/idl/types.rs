//! The parsed form of an interface definition.

use crate::InterfaceKind;

/// A primitive ROS 2 type other than the string types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// `bool`
    Bool,
    /// `byte` (an octet)
    Byte,
    /// `char` (an 8-bit character, same range as `uint8`)
    Char,
    /// `float32`
    Float32,
    /// `float64`
    Float64,
    /// `int8`
    Int8,
    /// `uint8`
    Uint8,
    /// `int16`
    Int16,
    /// `uint16`
    Uint16,
    /// `int32`
    Int32,
    /// `uint32`
    Uint32,
    /// `int64`
    Int64,
    /// `uint64`
    Uint64,
}

impl Primitive {
    /// Every primitive, in the order of `rosidl_adapter.parser.PRIMITIVE_TYPES`.
    pub const ALL: [Primitive; 13] = [
        Primitive::Bool,
        Primitive::Byte,
        Primitive::Char,
        Primitive::Float32,
        Primitive::Float64,
        Primitive::Int8,
        Primitive::Uint8,
        Primitive::Int16,
        Primitive::Uint16,
        Primitive::Int32,
        Primitive::Uint32,
        Primitive::Int64,
        Primitive::Uint64,
    ];

    /// The IDL spelling, e.g. `"float64"`.
    pub const fn name(self) -> &'static str {
        match self {
            Primitive::Bool => "bool",
            Primitive::Byte => "byte",
            Primitive::Char => "char",
            Primitive::Float32 => "float32",
            Primitive::Float64 => "float64",
            Primitive::Int8 => "int8",
            Primitive::Uint8 => "uint8",
            Primitive::Int16 => "int16",
            Primitive::Uint16 => "uint16",
            Primitive::Int32 => "int32",
            Primitive::Uint32 => "uint32",
            Primitive::Int64 => "int64",
            Primitive::Uint64 => "uint64",
        }
    }

    /// The primitive spelled `name`, if any.
    pub fn from_name(name: &str) -> Option<Primitive> {
        Primitive::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The inclusive value range of an integer primitive (`byte` and `char`
    /// are 0..=255), `None` for `bool` and the floats.
    pub fn integer_range(self) -> Option<(i128, i128)> {
        let signed = |bits: u32| (-(1_i128 << (bits - 1)), (1_i128 << (bits - 1)) - 1);
        let unsigned = |bits: u32| (0, (1_i128 << bits) - 1);
        match self {
            Primitive::Bool | Primitive::Float32 | Primitive::Float64 => None,
            Primitive::Byte | Primitive::Char | Primitive::Uint8 => Some(unsigned(8)),
            Primitive::Int8 => Some(signed(8)),
            Primitive::Int16 => Some(signed(16)),
            Primitive::Uint16 => Some(unsigned(16)),
            Primitive::Int32 => Some(signed(32)),
            Primitive::Uint32 => Some(unsigned(32)),
            Primitive::Int64 => Some(signed(64)),
            Primitive::Uint64 => Some(unsigned(64)),
        }
    }
}

/// The element type of a field, without array-ness.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum BaseType {
    /// A non-string primitive.
    Primitive(Primitive),
    /// `string`, `wstring` (`wide`), or their bounded forms `string<=N`.
    String {
        /// True for `wstring`.
        wide: bool,
        /// Maximum length in characters for `string<=N`.
        upper_bound: Option<usize>,
    },
    /// A nested message `package/Name`; a bare `Name` takes the package of
    /// the file it appears in.
    Message {
        /// Package of the nested message.
        package: String,
        /// Message name.
        name: String,
    },
}

/// Array-ness of a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Array {
    /// A single value, `T`.
    No,
    /// `T[]`, any length.
    Unbounded,
    /// `T[<=N]`, at most N elements.
    Bounded(usize),
    /// `T[N]`, exactly N elements.
    Fixed(usize),
}

/// The full type of a field.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct FieldType {
    /// Element type.
    pub base: BaseType,
    /// Array-ness.
    pub array: Array,
}

/// A literal value: a constant's value or a field's default.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `bool` value.
    Bool(bool),
    /// Integer value (every integer primitive, `byte` and `char`).
    Int(i128),
    /// Floating-point value.
    Float(f64),
    /// String value, quotes removed and escaped quotes unescaped.
    String(String),
    /// Default of an array field.
    Array(Vec<Value>),
}

/// A field line `TYPE NAME [DEFAULT]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Field name.
    pub name: String,
    /// Field type.
    pub field_type: FieldType,
    /// Default value, when the line gives one.
    pub default: Option<Value>,
}

/// A constant line `TYPE NAME=VALUE`.
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    /// Constant name.
    pub name: String,
    /// Constant type: a primitive or an unbounded `string`/`wstring`.
    pub constant_type: BaseType,
    /// Constant value.
    pub value: Value,
}

/// One message: a `.msg` file or one part of a service or action.
#[derive(Debug, Clone, PartialEq)]
pub struct MessageSpec {
    /// Package name.
    pub package: String,
    /// Message name; `<Service>_Request`, `<Action>_Goal` etc. for parts.
    pub name: String,
    /// Fields in declaration (= wire) order.
    pub fields: Vec<Field>,
    /// Constants in declaration order.
    pub constants: Vec<Constant>,
}

/// A whole interface file.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceSpec {
    /// Kind of the file.
    pub kind: InterfaceKind,
    /// Package name.
    pub package: String,
    /// Interface name (file stem).
    pub name: String,
    /// One part for a message; request and response for a service; goal,
    /// result and feedback for an action.
    pub parts: Vec<MessageSpec>,
}
