//! CDR, the serialization of ROS 2 messages (OMG XCDR1 "plain CDR", as rmw's Fast-DDS and
//! Cyclone write it): a 4-byte encapsulation header, then the fields in order, each primitive
//! aligned to its own size (at most 8) counted from the end of the header; strings as a `u32`
//! length that includes a terminating NUL, then the bytes and the NUL; sequences as a `u32` count,
//! then the elements; fixed arrays without a count.
//!
//! Written little-endian (`00 01 00 00`); read in either byte order (`00 00` big, `00 01` little).
//! Hand-written rather than a codec crate: the few message types placewords exchanges need only
//! these rules, and a reader of untrusted bytes that never allocates more than its input holds
//! is easier to see whole here than through a serde data model.

/// Why CDR bytes could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    #[error("the message ends at byte {len}, but {what} needs {need} bytes from byte {at}")]
    Truncated {
        what: &'static str,
        at: usize,
        need: usize,
        len: usize,
    },
    #[error("unsupported CDR encapsulation {0:02x} {1:02x} (only plain CDR, 00 00 or 00 01)")]
    Encapsulation(u8, u8),
    #[error("{what} at byte {at} is not valid UTF-8 text")]
    NotText { what: &'static str, at: usize },
    #[error("{what} at byte {at} claims {count} elements, more than the {left} bytes left hold")]
    TooLong {
        what: &'static str,
        at: usize,
        count: usize,
        left: usize,
    },
}

/// Writes one CDR message, little-endian, header first.
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl CdrWriter {
    /// A message holding only the encapsulation header (CDR little-endian).
    pub fn new() -> Self {
        CdrWriter {
            buf: vec![0x00, 0x01, 0x00, 0x00],
        }
    }

    /// The message's bytes.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    fn align(&mut self, n: usize) {
        while !(self.buf.len() - 4).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A string: length with the NUL, bytes, NUL.
    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A sequence's element count.
    pub fn count(&mut self, n: usize) {
        self.u32(n as u32);
    }
}

/// Reads one CDR message field by field; every read is bounds-checked.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    /// Position in `buf` (the header included).
    pos: usize,
    little: bool,
}

impl<'a> CdrReader<'a> {
    /// Reads the encapsulation header of `buf`.
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        if buf.len() < 4 {
            return Err(CdrError::Truncated {
                what: "the encapsulation header",
                at: 0,
                need: 4,
                len: buf.len(),
            });
        }
        let little = match (buf[0], buf[1]) {
            (0x00, 0x00) => false,
            (0x00, 0x01) => true,
            (a, b) => return Err(CdrError::Encapsulation(a, b)),
        };
        Ok(CdrReader {
            buf,
            pos: 4,
            little,
        })
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.pos
    }

    fn take(&mut self, n: usize, align: usize, what: &'static str) -> Result<&'a [u8], CdrError> {
        let pad = (align - (self.pos - 4) % align) % align;
        let at = self.pos + pad;
        if at.checked_add(n).is_none_or(|end| end > self.buf.len()) {
            return Err(CdrError::Truncated {
                what,
                at,
                need: n,
                len: self.buf.len(),
            });
        }
        self.pos = at + n;
        Ok(&self.buf[at..at + n])
    }

    fn array<const N: usize>(&mut self, what: &'static str) -> Result<[u8; N], CdrError> {
        let mut b: [u8; N] = self.take(N, N, what)?.try_into().expect("N bytes");
        if !self.little {
            b.reverse();
        }
        Ok(b)
    }

    pub fn u8(&mut self, what: &'static str) -> Result<u8, CdrError> {
        Ok(self.take(1, 1, what)?[0])
    }

    pub fn i32(&mut self, what: &'static str) -> Result<i32, CdrError> {
        self.array(what).map(i32::from_le_bytes)
    }

    pub fn u32(&mut self, what: &'static str) -> Result<u32, CdrError> {
        self.array(what).map(u32::from_le_bytes)
    }

    pub fn f32(&mut self, what: &'static str) -> Result<f32, CdrError> {
        self.array(what).map(f32::from_le_bytes)
    }

    pub fn f64(&mut self, what: &'static str) -> Result<f64, CdrError> {
        self.array(what).map(f64::from_le_bytes)
    }

    /// A string (its NUL dropped; a string without one is read whole).
    pub fn string(&mut self, what: &'static str) -> Result<String, CdrError> {
        let n = self.u32(what)? as usize;
        let at = self.pos;
        let bytes = self.take(n, 1, what)?;
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        std::str::from_utf8(bytes)
            .map(str::to_string)
            .map_err(|_| CdrError::NotText { what, at })
    }

    /// A sequence's element count, checked against the bytes left (`min_size` bytes at least
    /// per element), so a corrupt count never makes a huge allocation.
    pub fn count(&mut self, what: &'static str, min_size: usize) -> Result<usize, CdrError> {
        let n = self.u32(what)? as usize;
        let left = self.remaining();
        if n.saturating_mul(min_size.max(1)) > left {
            return Err(CdrError::TooLong {
                what,
                at: self.pos,
                count: n,
                left,
            });
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_aligned_from_the_end_of_the_header() {
        let mut w = CdrWriter::new();
        w.u8(7);
        w.f64(1.5);
        w.string("ab");
        w.u32(3);
        let b = w.into_bytes();
        // header 4, u8 at 4, pad to 12, f64 12..20, len 20..24, "ab\0" 24..27, pad, u32 28..32
        assert_eq!(b.len(), 32);
        let mut r = CdrReader::new(&b).unwrap();
        assert_eq!(r.u8("a").unwrap(), 7);
        assert_eq!(r.f64("b").unwrap(), 1.5);
        assert_eq!(r.string("c").unwrap(), "ab");
        assert_eq!(r.u32("d").unwrap(), 3);
        assert_eq!(r.remaining(), 0);
    }

    #[test]
    fn big_endian_is_read_too() {
        let b = [0, 0, 0, 0, 0, 0, 0, 5];
        assert_eq!(CdrReader::new(&b).unwrap().u32("n").unwrap(), 5);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            CdrReader::new(&[0, 1]),
            Err(CdrError::Truncated { .. })
        ));
        assert!(matches!(
            CdrReader::new(&[0, 2, 0, 0]),
            Err(CdrError::Encapsulation(0, 2))
        ));
        let huge = [0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff];
        let e = CdrReader::new(&huge)
            .unwrap()
            .count("ranges", 4)
            .unwrap_err();
        assert!(e.to_string().contains("ranges"), "{e}");
        let e = CdrReader::new(&huge)
            .unwrap()
            .string("frame_id")
            .unwrap_err();
        assert!(matches!(e, CdrError::Truncated { .. }), "{e}");
    }
}
