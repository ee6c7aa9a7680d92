//! The lap cache (`--cache DIR`, or `PLACEWORDS_CACHE`): simulated laps stored under their
//! key and read back instead of simulated again, so a change of the recognizer, the evaluation
//! or the gate re-runs only recognition and scoring.
//!
//! - **Key.** An entry's key is the BLAKE3 of the seed's simulation key
//!   (`eval::provenance::simulation_key`: the world model, route, runs with their lap counts
//!   after `--laps`, doors, people, robot, laser, odometry, the seed and `SIMULATOR_VERSION`)
//!   and of the build's simulator sources (`PLACEWORDS_SIM_SOURCES`, see `build.rs`), so a
//!   binary with another simulator never reads these laps. The entry is `DIR/KEY.laps`
//!   ([`crate::io::lap_file`]).
//! - **Written atomically.** Each writer fills its own temporary file beside the entry
//!   (`.KEY.laps.tmpPID-N`) and renames it onto the entry when every lap is in: two processes
//!   filling one cache each rename a whole entry with the same content, and the later wins.
//! - **Verified on read.** The header must carry the key and the lap counts, and every record
//!   its CRC-32, to the trailer: a corrupt or truncated entry is never used, its laps are
//!   simulated again and it is replaced; the run reports it (`provenance.lap_cache.corrupt`).
//! - **Reported.** Each seed's source ([`LapSource`]: hit, miss, corrupt) goes in its result
//!   and the counts in the report's `provenance.lap_cache`; the command prints them on stderr.
//! - **Bounded.** With a bound (`--cache-max-gb`), storing an entry removes the oldest entries
//!   (by modification time; a hit touches its entry) until the folder's entries fit. Clearing
//!   the cache is removing the folder.
//! - **Memory.** A whole read ([`LapCache::runs`]) holds the seed's laps as a simulation would;
//!   a streamed one ([`LapCache::open`] + [`Entry::next_lap`]) one lap at a time.

use crate::eval::provenance::{self, LapCacheUse, LapSource};
use crate::io::atomic::AtomicFile;
use crate::io::lap_file::{LapFileError, LapFileReader, LapFileWriter};
use crate::log::{LapLog, RunLog};
use crate::sim::SimPlan;
use std::io::{BufReader, Seek};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The fingerprint of the simulator's sources this binary was built from (`build.rs`).
pub const SIM_SOURCES: &str = env!("PLACEWORDS_SIM_SOURCES");

/// The file name extension of an entry.
const EXTENSION: &str = "laps";

/// A lap cache folder and what it did so far.
#[derive(Debug)]
pub struct LapCache {
    dir: PathBuf,
    /// The bound on the entries' bytes, `None`: unbounded.
    max_bytes: Option<u64>,
    used: Mutex<LapCacheUse>,
}

/// Two caches are alike when they are one folder with one bound (what they did aside).
impl PartialEq for LapCache {
    fn eq(&self, other: &Self) -> bool {
        (&self.dir, self.max_bytes) == (&other.dir, other.max_bytes)
    }
}

/// Why a cache folder cannot be used.
#[derive(Debug, thiserror::Error)]
#[error("--cache {dir}: {source}; give a folder this user can write (it is created if missing)")]
pub struct CacheError {
    pub dir: String,
    pub source: std::io::Error,
}

/// An intact entry open for reading lap by lap.
pub struct Entry {
    reader: LapFileReader<BufReader<std::fs::File>>,
    path: PathBuf,
}

impl Entry {
    /// The next lap and its run, `None` at the end.
    pub fn next_lap(&mut self) -> Result<Option<(usize, LapLog)>, String> {
        self.reader.next_lap().map_err(|e| {
            format!(
                "{}: {e} (after it was verified: was it changed in place?)",
                self.path.display()
            )
        })
    }
}

/// An entry being written lap by lap; [`LapCache::store`] puts it in place.
pub struct Pending {
    writer: Option<LapFileWriter<AtomicFile>>,
    path: PathBuf,
    why_not: Option<String>,
}

impl Pending {
    /// Adds lap `lap` of run `run` (a write error is kept for [`LapCache::store`] and the rest
    /// is not written).
    pub fn push(&mut self, run: usize, lap: &LapLog) {
        if let Some(w) = self.writer.as_mut()
            && let Err(e) = w.push(run, lap)
        {
            self.why_not = Some(format!("{}: {e}", self.path.display()));
            self.writer = None;
        }
    }
}

impl LapCache {
    /// The cache in `dir` (created if missing, checked writable), its entries bounded to
    /// `max_gb` gigabytes (10⁹ bytes) when given.
    pub fn open(dir: &Path, max_gb: Option<f64>) -> Result<LapCache, CacheError> {
        let err = |source| CacheError {
            dir: dir.display().to_string(),
            source,
        };
        crate::io::atomic::check_writable_dir(dir).map_err(err)?;
        let max_bytes = match max_gb {
            Some(g) if g.is_finite() && g >= 0.0 => Some((g * 1e9) as u64),
            Some(g) => {
                return Err(err(std::io::Error::other(format!(
                    "--cache-max-gb {g} is not a size in GB (a number ≥ 0)"
                ))));
            }
            None => None,
        };
        Ok(LapCache {
            dir: dir.to_path_buf(),
            max_bytes,
            used: Mutex::new(LapCacheUse {
                dir: dir.display().to_string(),
                ..LapCacheUse::default()
            }),
        })
    }

    /// What the cache did so far (for the report's provenance and the stderr lines).
    pub fn used(&self) -> LapCacheUse {
        self.used.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    fn note(&self, f: impl FnOnce(&mut LapCacheUse)) {
        f(&mut self.used.lock().unwrap_or_else(|e| e.into_inner()));
    }

    /// The key of `plan`'s laps at its seed with `laps_per_run[r]` laps in run `r`: the
    /// simulation key and the simulator's sources (see the module doc).
    pub fn key(plan: &SimPlan, laps_per_run: &[usize]) -> String {
        let mut p = plan.clone();
        for (r, &n) in p.runs.iter_mut().zip(laps_per_run) {
            r.laps = n;
        }
        let sim = provenance::simulation_key(&p, None);
        provenance::hash_bytes(format!("placewords-lap-cache/1\n{sim}\n{SIM_SOURCES}").as_bytes())
    }

    fn path_of(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.{EXTENSION}"))
    }

    /// The intact entry under `key` holding `laps_per_run`, verified to its trailer and
    /// touched (for the bound's order), or why there is none: `Ok(None)` no entry, `Err` a
    /// corrupt one (noted).
    pub fn open_entry(&self, key: &str, laps_per_run: &[usize]) -> Result<Option<Entry>, String> {
        let path = self.path_of(key);
        let Ok(mut file) = std::fs::File::open(&path) else {
            return Ok(None);
        };
        let checked = (|| -> Result<(), LapFileError> {
            let len = file.metadata().map_err(LapFileError::Io)?.len();
            let reader = LapFileReader::open(BufReader::new(&file), len)?;
            let h = reader.header();
            if h.key != key || h.laps_per_run != laps_per_run {
                return Err(LapFileError::Corrupt(format!(
                    "its header names key {} with laps {:?}, not the entry's",
                    h.key, h.laps_per_run
                )));
            }
            reader.verify()
        })();
        let checked = checked.and_then(|()| {
            file.rewind().map_err(LapFileError::Io)?;
            let len = file.metadata().map_err(LapFileError::Io)?.len();
            let _ = file.set_modified(std::time::SystemTime::now());
            LapFileReader::open(BufReader::with_capacity(1 << 20, file), len)
        });
        match checked {
            Ok(reader) => Ok(Some(Entry { reader, path })),
            Err(e) => {
                let why = format!("{}: {e}", path.display());
                self.note(|u| u.corrupt.push(why.clone()));
                Err(why)
            }
        }
    }

    /// Starts writing the entry under `key` (a failure is noted and nothing is stored).
    pub fn begin(&self, key: &str, laps_per_run: &[usize]) -> Pending {
        let path = self.path_of(key);
        let writer =
            AtomicFile::create_unique(&path).and_then(|f| LapFileWriter::new(f, key, laps_per_run));
        match writer {
            Ok(w) => Pending {
                writer: Some(w),
                path,
                why_not: None,
            },
            Err(e) => Pending {
                writer: None,
                why_not: Some(format!("{}: {e}", path.display())),
                path,
            },
        }
    }

    /// Puts a whole entry in place (or notes why not) and keeps the folder within its bound.
    pub fn store(&self, pending: Pending) {
        let Pending {
            writer,
            path,
            why_not,
        } = pending;
        let stored = match (writer, why_not) {
            (Some(w), None) => w
                .finish()
                .and_then(AtomicFile::commit)
                .map_err(|e| format!("{}: {e}", path.display())),
            (_, why) => Err(why.unwrap_or_else(|| format!("{}: not written", path.display()))),
        };
        match stored {
            Ok(()) => self.evict(&path),
            Err(why) => self.note(|u| u.not_stored.push(why)),
        }
    }

    /// Counts a seed's source.
    pub fn count(&self, source: LapSource) {
        self.note(|u| match source {
            LapSource::Hit => u.hits += 1,
            LapSource::Miss | LapSource::Corrupt => u.misses += 1,
        });
    }

    /// The runs of `plan` (`laps` replacing each run's lap count) from the cache, or from
    /// `simulate` (then stored), with the CPU seconds spent (reading, or simulating and
    /// storing) and where they came from.
    pub fn runs<E>(
        &self,
        plan: &SimPlan,
        laps: Option<usize>,
        simulate: impl FnOnce() -> Result<(Vec<RunLog>, f64), E>,
    ) -> Result<(Vec<RunLog>, f64, LapSource), E> {
        let counts: Vec<usize> = plan.runs.iter().map(|r| laps.unwrap_or(r.laps)).collect();
        let key = Self::key(plan, &counts);
        let w = crate::clock::Stopwatch::start();
        let source = match self.open_entry(&key, &counts) {
            Ok(Some(mut entry)) => {
                let mut runs: Vec<RunLog> = (0..counts.len())
                    .map(|run| RunLog {
                        run,
                        laps: Vec::new(),
                    })
                    .collect();
                let read = (|| {
                    while let Some((run, lap)) = entry.next_lap()? {
                        runs[run].laps.push(lap);
                    }
                    Ok::<(), String>(())
                })();
                match read {
                    Ok(()) => {
                        self.count(LapSource::Hit);
                        return Ok((runs, w.cpu_s(), LapSource::Hit));
                    }
                    Err(why) => {
                        self.note(|u| u.corrupt.push(why));
                        LapSource::Corrupt
                    }
                }
            }
            Ok(None) => LapSource::Miss,
            Err(_) => LapSource::Corrupt,
        };
        let (runs, sim_s) = simulate()?;
        let w = crate::clock::Stopwatch::start();
        let mut pending = self.begin(&key, &counts);
        for r in &runs {
            for lap in &r.laps {
                pending.push(r.run, lap);
            }
        }
        self.store(pending);
        self.count(source);
        Ok((runs, sim_s + w.cpu_s(), source))
    }

    /// Removes the oldest entries (by modification time) until the entries fit the bound,
    /// never `keep` (the entry just stored).
    fn evict(&self, keep: &Path) {
        let Some(max) = self.max_bytes else { return };
        let Ok(dir) = std::fs::read_dir(&self.dir) else {
            return;
        };
        let mut entries: Vec<(std::time::SystemTime, u64, PathBuf)> = dir
            .flatten()
            .filter(|e| {
                let p = e.path();
                p.extension().is_some_and(|x| x == EXTENSION)
                    && !e.file_name().to_string_lossy().starts_with('.')
            })
            .filter_map(|e| {
                let m = e.metadata().ok()?;
                Some((m.modified().ok()?, m.len(), e.path()))
            })
            .collect();
        let mut total: u64 = entries.iter().map(|e| e.1).sum();
        entries.sort();
        for (_, len, path) in entries {
            if total <= max {
                break;
            }
            if path == keep {
                continue;
            }
            if std::fs::remove_file(&path).is_ok() {
                total = total.saturating_sub(len);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, SystemTime};

    /// With a bound, storing an entry removes the oldest others (by modification time) until
    /// the entries fit, never the one just stored; files that are not entries stay.
    #[test]
    fn the_bound_removes_the_oldest_entries_first() {
        let dir = tempfile::tempdir().unwrap();
        let old = SystemTime::now() - Duration::from_secs(3600);
        let put = |name: &str, age_s: u64| {
            let p = dir.path().join(name);
            std::fs::write(&p, vec![0u8; 1000]).unwrap();
            let f = std::fs::File::options().write(true).open(&p).unwrap();
            f.set_modified(old + Duration::from_secs(age_s)).unwrap();
            p
        };
        let (a, b, c) = (put("a.laps", 0), put("b.laps", 10), put("c.laps", 20));
        let other = put("notes.txt", 0);
        let cache = LapCache::open(dir.path(), Some(2500e-9)).unwrap();
        cache.evict(&a);
        assert!(a.exists(), "the entry just stored stays, old as it is");
        assert!(!b.exists(), "the oldest other goes first");
        assert!(c.exists() && other.exists());
        let unbounded = LapCache::open(dir.path(), None).unwrap();
        unbounded.evict(&c);
        assert!(a.exists() && c.exists());
        assert!(LapCache::open(dir.path(), Some(-1.0)).is_err());
    }

    /// The key follows the seed and the lap counts, and names this build's simulator.
    #[test]
    fn the_key_follows_seed_and_laps() {
        let scn = crate::experiment::load_scenario(Path::new("scenarios/smoke.toml")).unwrap();
        let k = LapCache::key(&scn.sim, &[3, 2]);
        assert_eq!(k, LapCache::key(&scn.sim.clone(), &[3, 2]));
        assert_ne!(k, LapCache::key(&scn.sim, &[3, 1]));
        let mut other = scn.sim.clone();
        other.seed += 1;
        assert_ne!(k, LapCache::key(&other, &[3, 2]));
        assert_eq!(SIM_SOURCES.len(), 32);
    }
}
