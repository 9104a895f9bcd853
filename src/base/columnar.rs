//! Plain-old-data types that can be stored as columns of one scalar type (snapshots write
//! them as raw little-endian bytes). A leaf: the algebra types declare their scalar here
//! without knowing about any file format.

use bytemuck::Pod;
use glam::{DMat2, DMat3, DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// Scalar type of a column's elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scalar {
    /// 64-bit float.
    F64,
    /// 64-bit unsigned integer.
    U64,
    /// 16-bit unsigned integer.
    U16,
    /// Byte (UTF-8 text).
    U8,
}

impl Scalar {
    /// Bytes per element.
    pub fn size(self) -> u64 {
        match self {
            Scalar::F64 | Scalar::U64 => 8,
            Scalar::U16 => 2,
            Scalar::U8 => 1,
        }
    }
}

/// Plain-old-data types stored as columns, with their scalar type.
pub trait Columnar: Pod {
    /// The scalar every component has.
    const SCALAR: Scalar;
}

macro_rules! columnar {
    ($($t:ty => $e:ident),*) => { $(impl Columnar for $t { const SCALAR: Scalar = Scalar::$e; })* };
}
columnar!(f64 => F64, u64 => U64, u16 => U16, u8 => U8, DVec2 => F64, DVec3 => F64,
    DMat2 => F64, DMat3 => F64);
