//! Reading big-endian bit fields, as shading streams and sampled functions pack them.

/// Reads big-endian bit fields.
pub(crate) struct BitReader<'a> {
    data: &'a [u8],
    bit: u64,
}

impl<'a> BitReader<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        BitReader { data, bit: 0 }
    }

    /// The byte the next field starts in.
    pub fn byte_position(&self) -> u64 {
        self.bit / 8
    }

    pub fn remaining(&self) -> u64 {
        (self.data.len() as u64 * 8).saturating_sub(self.bit)
    }

    /// The next `bits` (at most 32) as an unsigned number; `None` past the end.
    pub fn read(&mut self, bits: u32) -> Option<u64> {
        if self.remaining() < u64::from(bits) {
            return None;
        }
        let mut value = 0u64;
        for _ in 0..bits {
            let byte = self.data[(self.bit / 8) as usize];
            let b = (byte >> (7 - (self.bit % 8))) & 1;
            value = (value << 1) | u64::from(b);
            self.bit += 1;
        }
        Some(value)
    }

    /// Skips to the next byte boundary.
    pub fn align(&mut self) {
        self.bit = self.bit.div_ceil(8) * 8;
    }
}
