// Structured reading of fuzz bytes, shared by the target bodies.
//
// Included (with `include!`) as a module named `input` next to each target
// body, both by the cargo-fuzz binaries in `fuzz/fuzz_targets/` and by the
// stable corpus tests `crates/*/tests/fuzz_corpus.rs`. Plain `//` comments
// only: an included file cannot carry inner doc comments.

/// Reads fixed-size values off the front of a byte string; once the bytes
/// run out every read returns zero, so every input decodes to something.
pub struct Bytes<'a> {
    data: &'a [u8],
}

#[allow(dead_code)]
impl<'a> Bytes<'a> {
    /// Reader over `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Bytes { data }
    }

    /// Next byte (0 when exhausted).
    pub fn u8(&mut self) -> u8 {
        match self.data.split_first() {
            Some((&b, rest)) => {
                self.data = rest;
                b
            }
            None => 0,
        }
    }

    /// Next little-endian u32 (missing bytes read as 0).
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    /// Next little-endian u64 (missing bytes read as 0).
    pub fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | (u64::from(self.u32()) << 32)
    }

    /// Next f32 from raw bits: NaN, infinities, subnormals and -0 included.
    pub fn f32_bits(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }

    /// A value in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u32) -> u32 {
        self.u32() % n
    }

    /// One element of `table`, chosen by the next byte.
    pub fn pick<T: Copy>(&mut self, table: &[T]) -> T {
        table[self.u8() as usize % table.len()]
    }

    /// The unread bytes.
    pub fn rest(&self) -> &'a [u8] {
        self.data
    }

    /// True when every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}
