//! The integer element types of label files (in their own module: the error
//! type names them and the readers parse them).

use std::fmt;

/// Integer element type of a label file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dtype {
    /// Unsigned 8-bit.
    U8,
    /// Unsigned 16-bit.
    U16,
    /// Unsigned 32-bit.
    U32,
    /// Signed 32-bit (labels must be ≥ 0).
    I32,
    /// Signed 64-bit (labels must be in 0 ..= u32::MAX).
    I64,
}

impl Dtype {
    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            Self::U8 => 1,
            Self::U16 => 2,
            Self::U32 | Self::I32 => 4,
            Self::I64 => 8,
        }
    }

    /// Largest label this type can hold.
    pub fn max_label(self) -> u32 {
        match self {
            Self::U8 => u8::MAX.into(),
            Self::U16 => u16::MAX.into(),
            Self::I32 => i32::MAX as u32,
            Self::U32 | Self::I64 => u32::MAX,
        }
    }

    /// The smallest unsigned type holding `max_label` (U8, U16 or U32).
    pub fn smallest_for(max_label: u32) -> Self {
        if max_label <= u8::MAX.into() {
            Self::U8
        } else if max_label <= u16::MAX.into() {
            Self::U16
        } else {
            Self::U32
        }
    }
}

impl fmt::Display for Dtype {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::U8 => "u8",
            Self::U16 => "u16",
            Self::U32 => "u32",
            Self::I32 => "i32",
            Self::I64 => "i64",
        })
    }
}
