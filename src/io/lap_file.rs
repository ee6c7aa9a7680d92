//! The lap file: simulated laps stored whole and exactly (every `f64` bit for bit), for the
//! lap cache (`experiment::cache`). Written lap by lap as the simulator makes them and read
//! back lap by lap, so neither side holds more than one lap of scans.
//!
//! Layout (integers little-endian):
//!
//! ```text
//! header   "PWLAPS\0" 0x01 | key: 64 ASCII bytes | runs: u32 | laps per run: u64 × runs | crc32: u32
//! record   run: u32 | compressed length: u64 | raw length: u64 | crc32: u32 | zstd(lap)
//!          … one per lap, runs in order, laps in order within a run
//! trailer  0xFFFF_FFFF: u32 | laps: u64 | crc32: u32
//! ```
//!
//! Each CRC-32 (`crc32fast`) covers everything of its part before it (the header's, the
//! record's fields and its compressed bytes, the trailer's), so a flipped byte anywhere, a
//! truncated file or a file cut at a record boundary is found ([`LapFileError::Corrupt`])
//! before a lap is used. A lap's raw bytes are its scalars (lap number, door configuration,
//! open doors; per frame the time, odometry, truth, scan time, the beam layout when it differs
//! from the frame before, the range count) followed by every range of the lap split into byte
//! planes (byte 0 of every range, then byte 1, …): the high bytes of nearby ranges repeat, so
//! zstd shrinks them, while the noisy low bytes stay as they are.

use crate::geom::{OdomPose, Pose2, TruePose};
use crate::log::{Frame, LapLog, RunLog};
use crate::scan::{BeamLayout, Scan};
use std::io::{Read, Write};

/// The file's first bytes: the name and the format's version (1).
pub const MAGIC: [u8; 8] = *b"PWLAPS\x00\x01";

/// Length of a key in the header: 64 hex digits (a BLAKE3 hash).
pub const KEY_LEN: usize = 64;

/// The zstd level laps are compressed at (1: fast; the noisy low bytes do not compress anyway).
const ZSTD_LEVEL: i32 = 1;

/// The run field of the trailer.
const END: u32 = u32::MAX;

/// Most raw bytes one lap may claim (a lap of the longest route is a few tens of MB).
const MAX_RAW_LAP: u64 = 1 << 30;

/// Why a lap file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LapFileError {
    /// The bytes are not a whole, intact lap file: what is wrong and where.
    #[error("{0}")]
    Corrupt(String),
    #[error(transparent)]
    Io(std::io::Error),
}

fn corrupt(what: impl Into<String>) -> LapFileError {
    LapFileError::Corrupt(what.into())
}

/// What a lap file's header says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Header {
    /// The key the laps were stored under (64 hex digits).
    pub key: String,
    /// Laps per run, runs in order.
    pub laps_per_run: Vec<usize>,
}

/// Writes a lap file lap by lap to `W`; [`LapFileWriter::finish`] writes the trailer.
pub struct LapFileWriter<W: Write> {
    out: W,
    laps_per_run: Vec<usize>,
    /// Run and laps written in it so far.
    at: (usize, usize),
    written: u64,
}

impl<W: Write> LapFileWriter<W> {
    /// Writes the header for laps stored under `key` (64 hex digits), `laps_per_run[r]` laps
    /// in run `r`.
    pub fn new(mut out: W, key: &str, laps_per_run: &[usize]) -> std::io::Result<Self> {
        let mut head = Vec::with_capacity(MAGIC.len() + KEY_LEN + 4 + 8 * laps_per_run.len());
        head.extend_from_slice(&MAGIC);
        let mut k = key.as_bytes().to_vec();
        k.resize(KEY_LEN, b'0');
        head.extend_from_slice(&k);
        head.extend_from_slice(&(laps_per_run.len() as u32).to_le_bytes());
        for &n in laps_per_run {
            head.extend_from_slice(&(n as u64).to_le_bytes());
        }
        let crc = crc32fast::hash(&head);
        head.extend_from_slice(&crc.to_le_bytes());
        out.write_all(&head)?;
        let mut w = LapFileWriter {
            out,
            laps_per_run: laps_per_run.to_vec(),
            at: (0, 0),
            written: 0,
        };
        w.skip_empty_runs();
        Ok(w)
    }

    fn skip_empty_runs(&mut self) {
        while self.at.0 < self.laps_per_run.len() && self.at.1 >= self.laps_per_run[self.at.0] {
            self.at = (self.at.0 + 1, 0);
        }
    }

    /// Appends `lap` of run `run`. Laps must come in the header's order.
    pub fn push(&mut self, run: usize, lap: &LapLog) -> std::io::Result<()> {
        if run != self.at.0 || self.at.0 >= self.laps_per_run.len() {
            return Err(std::io::Error::other(format!(
                "lap file: lap of run {run} out of order (expected run {})",
                self.at.0
            )));
        }
        let raw = encode_lap(lap);
        let packed = zstd::bulk::compress(&raw, ZSTD_LEVEL)?;
        let mut head = Vec::with_capacity(24);
        head.extend_from_slice(&(run as u32).to_le_bytes());
        head.extend_from_slice(&(packed.len() as u64).to_le_bytes());
        head.extend_from_slice(&(raw.len() as u64).to_le_bytes());
        let mut crc = crc32fast::Hasher::new();
        crc.update(&head);
        crc.update(&packed);
        head.extend_from_slice(&crc.finalize().to_le_bytes());
        self.out.write_all(&head)?;
        self.out.write_all(&packed)?;
        self.at.1 += 1;
        self.written += 1;
        self.skip_empty_runs();
        Ok(())
    }

    /// Writes the trailer (every lap of the header must have been pushed) and hands back `W`.
    pub fn finish(mut self) -> std::io::Result<W> {
        if self.at.0 < self.laps_per_run.len() {
            return Err(std::io::Error::other(format!(
                "lap file: run {} has {} of its {} laps",
                self.at.0, self.at.1, self.laps_per_run[self.at.0]
            )));
        }
        let mut tail = Vec::with_capacity(16);
        tail.extend_from_slice(&END.to_le_bytes());
        tail.extend_from_slice(&self.written.to_le_bytes());
        let crc = crc32fast::hash(&tail);
        tail.extend_from_slice(&crc.to_le_bytes());
        self.out.write_all(&tail)?;
        Ok(self.out)
    }
}

/// Reads a lap file lap by lap from `R`, checking every part's CRC before its content is used.
pub struct LapFileReader<R: Read> {
    inp: R,
    /// Bytes left in the file (a length field may not claim more).
    left: u64,
    header: Header,
    at: (usize, usize),
    read: u64,
    done: bool,
}

impl<R: Read> LapFileReader<R> {
    /// Reads and checks the header of a file of `len` bytes.
    pub fn open(mut inp: R, len: u64) -> Result<Self, LapFileError> {
        let mut left = len;
        let mut fixed = [0u8; MAGIC.len() + KEY_LEN + 4];
        read_exact(&mut inp, &mut fixed, &mut left, "the header")?;
        if fixed[..MAGIC.len()] != MAGIC {
            return Err(corrupt(
                "not a lap file of this version (its first bytes differ)",
            ));
        }
        let key = &fixed[MAGIC.len()..MAGIC.len() + KEY_LEN];
        let runs = u32::from_le_bytes(fixed[MAGIC.len() + KEY_LEN..].try_into().expect("4"));
        if u64::from(runs) * 8 > left {
            return Err(corrupt(format!(
                "the header claims {runs} runs, more than the file holds"
            )));
        }
        let mut counts = vec![0u8; runs as usize * 8];
        read_exact(&mut inp, &mut counts, &mut left, "the header")?;
        let mut crc = [0u8; 4];
        read_exact(&mut inp, &mut crc, &mut left, "the header")?;
        let mut h = crc32fast::Hasher::new();
        h.update(&fixed);
        h.update(&counts);
        if h.finalize() != u32::from_le_bytes(crc) {
            return Err(corrupt("the header's checksum differs"));
        }
        let key = String::from_utf8(key.to_vec()).map_err(|_| corrupt("the key is not text"))?;
        let laps_per_run = counts
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8")) as usize)
            .collect();
        let mut r = LapFileReader {
            inp,
            left,
            header: Header { key, laps_per_run },
            at: (0, 0),
            read: 0,
            done: false,
        };
        r.skip_empty_runs();
        Ok(r)
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    fn skip_empty_runs(&mut self) {
        let per = &self.header.laps_per_run;
        while self.at.0 < per.len() && self.at.1 >= per[self.at.0] {
            self.at = (self.at.0 + 1, 0);
        }
    }

    /// The next record's run and checked compressed bytes (with its raw length), or `None`
    /// after a checked trailer.
    fn next_record(&mut self) -> Result<Option<(usize, Vec<u8>, u64)>, LapFileError> {
        if self.done {
            return Ok(None);
        }
        let place = format!("record {}", self.read);
        let mut run = [0u8; 4];
        read_exact(&mut self.inp, &mut run, &mut self.left, &place)?;
        let run_n = u32::from_le_bytes(run);
        if run_n == END {
            let mut rest = [0u8; 12];
            read_exact(&mut self.inp, &mut rest, &mut self.left, "the trailer")?;
            let mut h = crc32fast::Hasher::new();
            h.update(&run);
            h.update(&rest[..8]);
            if h.finalize() != u32::from_le_bytes(rest[8..].try_into().expect("4")) {
                return Err(corrupt("the trailer's checksum differs"));
            }
            let laps = u64::from_le_bytes(rest[..8].try_into().expect("8"));
            let expected: u64 = self.header.laps_per_run.iter().map(|&n| n as u64).sum();
            if laps != self.read
                || self.read != expected
                || self.at.0 < self.header.laps_per_run.len()
            {
                return Err(corrupt(format!(
                    "the file ends after {} laps; its header lists {expected}",
                    self.read
                )));
            }
            if self.left != 0 {
                return Err(corrupt(format!("{} bytes after the trailer", self.left)));
            }
            self.done = true;
            return Ok(None);
        }
        let mut lens = [0u8; 20];
        read_exact(&mut self.inp, &mut lens, &mut self.left, &place)?;
        let packed_len = u64::from_le_bytes(lens[..8].try_into().expect("8"));
        let raw_len = u64::from_le_bytes(lens[8..16].try_into().expect("8"));
        if packed_len > self.left {
            return Err(corrupt(format!(
                "truncated in {place}: it claims {packed_len} bytes, the file holds {} more",
                self.left
            )));
        }
        if raw_len > MAX_RAW_LAP {
            return Err(corrupt(format!(
                "{place} claims {raw_len} bytes unpacked, more than a lap may hold"
            )));
        }
        let mut packed = vec![0u8; packed_len as usize];
        read_exact(&mut self.inp, &mut packed, &mut self.left, &place)?;
        let mut h = crc32fast::Hasher::new();
        h.update(&run);
        h.update(&lens[..16]);
        h.update(&packed);
        if h.finalize() != u32::from_le_bytes(lens[16..].try_into().expect("4")) {
            return Err(corrupt(format!("{place}: its checksum differs")));
        }
        let per = &self.header.laps_per_run;
        if run_n as usize != self.at.0 || self.at.0 >= per.len() {
            return Err(corrupt(format!(
                "{place} is of run {run_n}, not of run {} as the header's order says",
                self.at.0
            )));
        }
        self.at.1 += 1;
        self.read += 1;
        self.skip_empty_runs();
        Ok(Some((run_n as usize, packed, raw_len)))
    }

    /// The next lap and its run, or `None` after the checked trailer.
    pub fn next_lap(&mut self) -> Result<Option<(usize, LapLog)>, LapFileError> {
        let Some((run, packed, raw_len)) = self.next_record()? else {
            return Ok(None);
        };
        let place = format!("record {}", self.read - 1);
        let raw = zstd::bulk::decompress(&packed, raw_len as usize)
            .map_err(|e| corrupt(format!("{place}: cannot unpack: {e}")))?;
        if raw.len() as u64 != raw_len {
            return Err(corrupt(format!("{place}: unpacks to another length")));
        }
        let lap = decode_lap(&raw).map_err(|e| corrupt(format!("{place}: {e}")))?;
        Ok(Some((run, lap)))
    }

    /// Checks every record's and the trailer's CRC without unpacking the laps.
    pub fn verify(mut self) -> Result<(), LapFileError> {
        while self.next_record()?.is_some() {}
        Ok(())
    }

    /// Every lap, as runs (checked to the trailer).
    pub fn read_runs(mut self) -> Result<Vec<RunLog>, LapFileError> {
        let mut runs: Vec<RunLog> = (0..self.header.laps_per_run.len())
            .map(|run| RunLog {
                run,
                laps: Vec::new(),
            })
            .collect();
        while let Some((run, lap)) = self.next_lap()? {
            runs[run].laps.push(lap);
        }
        Ok(runs)
    }
}

fn read_exact<R: Read>(
    inp: &mut R,
    buf: &mut [u8],
    left: &mut u64,
    place: &str,
) -> Result<(), LapFileError> {
    if (buf.len() as u64) > *left {
        return Err(corrupt(format!("truncated in {place}")));
    }
    inp.read_exact(buf).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => corrupt(format!("truncated in {place}")),
        _ => LapFileError::Io(e),
    })?;
    *left -= buf.len() as u64;
    Ok(())
}

/// The raw bytes of one lap (see the module doc).
fn encode_lap(lap: &LapLog) -> Vec<u8> {
    let ranges: usize = lap.frames.iter().map(|f| f.scan.ranges_m.len()).sum();
    let mut s = Vec::with_capacity(64 + lap.frames.len() * 90 + ranges * 8);
    s.extend_from_slice(&(lap.lap as u64).to_le_bytes());
    put_str(&mut s, &lap.door_config);
    s.extend_from_slice(&(lap.open_doors.len() as u32).to_le_bytes());
    for d in &lap.open_doors {
        put_str(&mut s, d);
    }
    s.extend_from_slice(&(lap.frames.len() as u64).to_le_bytes());
    let mut layout: Option<&BeamLayout> = None;
    for f in &lap.frames {
        for v in [f.time_s, f.odom.0.x, f.odom.0.y, f.odom.0.theta] {
            s.extend_from_slice(&v.to_le_bytes());
        }
        for v in [f.truth.0.x, f.truth.0.y, f.truth.0.theta, f.scan.time_s] {
            s.extend_from_slice(&v.to_le_bytes());
        }
        if layout == Some(&f.scan.layout) {
            s.push(0);
        } else {
            let l = &f.scan.layout;
            s.push(1);
            s.extend_from_slice(&l.start_angle_rad.to_le_bytes());
            s.extend_from_slice(&l.step_rad.to_le_bytes());
            s.extend_from_slice(&(l.count as u64).to_le_bytes());
            for v in [l.max_range_m, l.mount.x, l.mount.y, l.mount.theta] {
                s.extend_from_slice(&v.to_le_bytes());
            }
            layout = Some(l);
        }
        s.extend_from_slice(&(f.scan.ranges_m.len() as u32).to_le_bytes());
    }
    let start = s.len();
    s.resize(start + ranges * 8, 0);
    let planes = &mut s[start..];
    let mut i = 0;
    for f in &lap.frames {
        for r in &f.scan.ranges_m {
            for (k, b) in r.to_bits().to_le_bytes().into_iter().enumerate() {
                planes[k * ranges + i] = b;
            }
            i += 1;
        }
    }
    s
}

fn put_str(s: &mut Vec<u8>, v: &str) {
    s.extend_from_slice(&(v.len() as u32).to_le_bytes());
    s.extend_from_slice(v.as_bytes());
}

/// A cursor over a lap's raw bytes that reports running out instead of panicking.
struct Cursor<'a> {
    b: &'a [u8],
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if n > self.b.len() {
            return Err("the lap's bytes end early".into());
        }
        let (h, t) = self.b.split_at(n);
        self.b = t;
        Ok(h)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4")))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8")))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn str(&mut self) -> Result<String, String> {
        let n = self.u32()? as usize;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| "a name is not UTF-8".into())
    }
    fn pose(&mut self) -> Result<Pose2, String> {
        Ok(Pose2 {
            x: self.f64()?,
            y: self.f64()?,
            theta: self.f64()?,
        })
    }
    /// A count of items of at least `each` bytes, refused when the bytes left cannot hold it.
    fn count(&mut self, n: u64, each: usize) -> Result<usize, String> {
        if n.saturating_mul(each as u64) > self.b.len() as u64 {
            return Err(format!("a count of {n} is more than the lap's bytes hold"));
        }
        Ok(n as usize)
    }
}

/// A lap from its raw bytes.
fn decode_lap(raw: &[u8]) -> Result<LapLog, String> {
    let mut c = Cursor { b: raw };
    let lap = c.u64()? as usize;
    let door_config = c.str()?;
    let n = c.u32()?;
    let n = c.count(n.into(), 4)?;
    let open_doors = (0..n).map(|_| c.str()).collect::<Result<Vec<_>, _>>()?;
    let n = c.u64()?;
    let n = c.count(n, 8 * 8 + 1 + 4)?;
    let mut heads = Vec::with_capacity(n);
    let mut layout: Option<BeamLayout> = None;
    for _ in 0..n {
        let time_s = c.f64()?;
        let odom = c.pose()?;
        let truth = c.pose()?;
        let scan_time_s = c.f64()?;
        match c.u8()? {
            0 if layout.is_some() => {}
            1 => {
                layout = Some(BeamLayout {
                    start_angle_rad: c.f64()?,
                    step_rad: c.f64()?,
                    count: c.u64()? as usize,
                    max_range_m: c.f64()?,
                    mount: c.pose()?,
                })
            }
            flag => return Err(format!("a frame's layout flag is {flag}")),
        }
        let ranges = c.u32()? as usize;
        heads.push((time_s, odom, truth, scan_time_s, layout.clone(), ranges));
    }
    let total = heads
        .iter()
        .try_fold(0usize, |acc, h| acc.checked_add(h.5))
        .filter(|t| t.checked_mul(8) == Some(c.b.len()))
        .ok_or("the ranges do not fill the lap's bytes")?;
    let planes = c.b;
    let mut frames = Vec::with_capacity(n);
    let mut i = 0;
    for (time_s, odom, truth, scan_time_s, layout, count) in heads {
        let mut ranges_m = Vec::with_capacity(count);
        for _ in 0..count {
            let mut b = [0u8; 8];
            for (k, byte) in b.iter_mut().enumerate() {
                *byte = planes[k * total + i];
            }
            ranges_m.push(f64::from_bits(u64::from_le_bytes(b)));
            i += 1;
        }
        frames.push(Frame {
            time_s,
            odom: OdomPose(odom),
            truth: TruePose(truth),
            scan: Scan {
                layout: layout.expect("the first frame carries its layout"),
                ranges_m,
                time_s: scan_time_s,
            },
        });
    }
    Ok(LapLog {
        lap,
        door_config,
        open_doors,
        frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lap(lap: usize, frames: usize) -> LapLog {
        let layout = BeamLayout::centered(5, 1.0, 8.0, Pose2::IDENTITY);
        LapLog {
            lap,
            door_config: "one-per-corridor-a".into(),
            open_doors: vec!["s-12".into(), "e-05".into()],
            frames: (0..frames)
                .map(|i| Frame {
                    time_s: i as f64 * 0.1 + 1e-17,
                    odom: OdomPose(Pose2 {
                        x: 1.0 / 3.0,
                        y: -0.0,
                        theta: f64::MIN_POSITIVE,
                    }),
                    truth: TruePose(Pose2 {
                        x: std::f64::consts::PI,
                        y: 2.5,
                        theta: -1.0,
                    }),
                    scan: Scan {
                        layout: if i == 2 {
                            BeamLayout::centered(3, 2.0, 30.0, Pose2::IDENTITY)
                        } else {
                            layout.clone()
                        },
                        ranges_m: (0..5 - (i % 2))
                            .map(|k| k as f64 * 0.123 + i as f64)
                            .collect(),
                        time_s: i as f64 * 0.1,
                    },
                })
                .collect(),
        }
    }

    fn file(runs: &[Vec<LapLog>]) -> Vec<u8> {
        let counts: Vec<usize> = runs.iter().map(Vec::len).collect();
        let mut w = LapFileWriter::new(Vec::new(), &"ab".repeat(32), &counts).unwrap();
        for (r, laps) in runs.iter().enumerate() {
            for l in laps {
                w.push(r, l).unwrap();
            }
        }
        w.finish().unwrap()
    }

    /// Laps read back bit for bit: layouts that change between frames, ranges of different
    /// counts, a run with no laps, negative zero and subnormal-adjacent values.
    #[test]
    fn laps_read_back_exactly() {
        let runs = vec![vec![lap(0, 4), lap(1, 0)], vec![], vec![lap(0, 3)]];
        let bytes = file(&runs);
        let r = LapFileReader::open(&bytes[..], bytes.len() as u64).unwrap();
        assert_eq!(r.header().laps_per_run, [2, 0, 1]);
        assert_eq!(r.header().key, "ab".repeat(32));
        let got = r.read_runs().unwrap();
        assert_eq!(got.len(), 3);
        for (g, want) in got.iter().zip(&runs) {
            assert_eq!(&g.laps, want);
        }
        assert!(got[0].laps[0].frames[0].odom.0.y.is_sign_negative());
        LapFileReader::open(&bytes[..], bytes.len() as u64)
            .unwrap()
            .verify()
            .unwrap();
    }

    /// Every truncation and every single flipped byte is refused, by `verify` and by reading.
    #[test]
    fn every_truncation_and_flipped_byte_is_refused() {
        let bytes = file(&[vec![lap(0, 3)], vec![lap(0, 2)]]);
        let refused = |b: &[u8]| {
            let read = LapFileReader::open(b, b.len() as u64).and_then(|r| r.read_runs());
            let verify = LapFileReader::open(b, b.len() as u64).and_then(|r| r.verify());
            matches!(read, Err(LapFileError::Corrupt(_)))
                && matches!(verify, Err(LapFileError::Corrupt(_)))
        };
        for n in 0..bytes.len() {
            assert!(refused(&bytes[..n]), "cut at {n}");
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(refused(&b), "byte {i} flipped");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(refused(&longer));
    }

    #[test]
    fn laps_out_of_order_or_missing_are_refused_by_the_writer() {
        let mut w = LapFileWriter::new(Vec::new(), &"0".repeat(64), &[1, 1]).unwrap();
        assert!(w.push(1, &lap(0, 1)).is_err());
        w.push(0, &lap(0, 1)).unwrap();
        assert!(w.finish().is_err());
    }
}
