//! Atomic output: write to a temporary file beside the target, then rename, so an interrupted
//! run never leaves a half-written file under a final name; output folders are staged the same
//! way ([`StagedDir`]), so a folder holds one complete run or is left as it was.
//!
//! Temporary names are `.NAME.tmpPID` (hidden, beside `NAME`; PID the writing process). Every
//! error path removes them. A process killed outright (`kill -9`, a file-size limit) cannot, so
//! the next write of `NAME` in that folder removes the `.NAME.tmpPID` of any process that no
//! longer runs (on systems with `/proc`; elsewhere they stay, hidden, and nothing reads them).
//!
//! A staged folder replaces an existing one by exchanging the two in one `renameat2`
//! (`RENAME_EXCHANGE`, Linux), so a kill at any instant leaves the old folder or the new one
//! whole; where the exchange is not available it falls back to two renames (old aside, new in).
//! While a process writes a folder, `.DIR.lock` beside it holds its pid; another process asked
//! to write the same folder refuses, naming that pid.
//!
//! Every rename goes through one function, so a test can kill the process at the n-th one:
//! `PLACEWORDS_TEST_KILL_AT=n` (test-only; nothing sets it in normal use) aborts the process
//! just before its n-th rename.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The test-only hook's environment variable: abort just before the n-th rename (1-based).
pub const TEST_KILL_AT_ENV: &str = "PLACEWORDS_TEST_KILL_AT";

/// Renames done by this process so far (for [`TEST_KILL_AT_ENV`]).
static RENAMES: AtomicUsize = AtomicUsize::new(0);

/// Aborts the process when this is the rename [`TEST_KILL_AT_ENV`] names.
fn kill_point() {
    let n = RENAMES.fetch_add(1, Ordering::SeqCst) + 1;
    let at = std::env::var(TEST_KILL_AT_ENV).ok();
    if at.and_then(|v| v.parse::<usize>().ok()) == Some(n) {
        std::process::abort();
    }
}

/// `std::fs::rename`, the one place every output is renamed.
fn rename(from: &Path, to: &Path) -> std::io::Result<()> {
    kill_point();
    std::fs::rename(from, to)
}

/// Swaps two existing paths in one atomic step; `Ok(false)` where the system or file system
/// cannot (then nothing was changed).
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    kill_point();
    #[cfg(target_os = "linux")]
    {
        use rustix::fs::{CWD, RenameFlags, renameat_with};
        match renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE) {
            Ok(()) => Ok(true),
            Err(e)
                if e == rustix::io::Errno::INVAL
                    || e == rustix::io::Errno::NOSYS
                    || e == rustix::io::Errno::OPNOTSUPP =>
            {
                Ok(false)
            }
            Err(e) => Err(e.into()),
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = (a, b);
        Ok(false)
    }
}

/// `.NAME.tmpPID` beside `path`, for this process.
fn temp_path(path: &Path) -> PathBuf {
    path.with_file_name(format!(".{}.tmp{}", file_name(path), std::process::id()))
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into())
}

/// Whether process `pid` may still be running: `false` only when `/proc` says it is gone.
fn may_be_running(pid: u32) -> bool {
    pid == std::process::id()
        || !Path::new("/proc/self").exists()
        || Path::new(&format!("/proc/{pid}")).exists()
}

/// Removes the `.NAME.tmpPID` files and folders a killed process left beside `path`.
pub fn remove_stale_temps(path: &Path) {
    let prefix = format!(".{}.tmp", file_name(path));
    let dir = match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let digits = |p: &str| {
            p.split(|c: char| !c.is_ascii_digit())
                .next()
                .map(str::to_owned)
        };
        let pid = name.strip_prefix(&prefix).and_then(digits);
        let pid = pid.and_then(|p| p.parse::<u32>().ok());
        if pid.is_some_and(|pid| !may_be_running(pid)) {
            let p = e.path();
            let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
        }
    }
}

fn create_parent(path: &Path) -> std::io::Result<()> {
    match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(parent) => std::fs::create_dir_all(parent),
        None => Ok(()),
    }
}

/// Refuses a file whose folder does not exist: a misspelt folder is a mistake to report, not a
/// tree to create (output *folders*, `--svg DIR` and `-o DIR`, are created).
pub fn check_parent(path: &Path) -> std::io::Result<()> {
    match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(parent) if !parent.is_dir() => Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!(
                "folder {} does not exist; create it first (output files are written into \
                 existing folders)",
                parent.display()
            ),
        )),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` atomically, creating parent folders.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    create_parent(path)?;
    remove_stale_temps(path);
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A file written piece by piece under its temporary name and renamed onto `path` by
/// [`AtomicFile::commit`] (as [`write_atomic`] does for bytes held whole); dropped without a
/// commit, the temporary file is removed. Buffered: many small writes cost one system call per
/// 64 KiB.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Creates the temporary file beside `path` (and `path`'s parent folders).
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        create_parent(path)?;
        remove_stale_temps(path);
        let tmp = temp_path(path);
        let file = std::fs::File::create(&tmp)?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            out: Some(std::io::BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// [`AtomicFile::create`] with a temporary name no other writer of this process uses
    /// (`.NAME.tmpPID-N`), for files several threads may write at once under one name (a lap
    /// cache entry): each writes its own, and the last rename wins.
    pub fn create_unique(path: &Path) -> std::io::Result<AtomicFile> {
        static WRITERS: AtomicUsize = AtomicUsize::new(0);
        create_parent(path)?;
        remove_stale_temps(path);
        let n = WRITERS.fetch_add(1, Ordering::SeqCst);
        let tmp = path.with_file_name(format!(
            ".{}.tmp{}-{n}",
            file_name(path),
            std::process::id()
        ));
        let file = std::fs::File::create(&tmp)?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            out: Some(std::io::BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file onto its final path.
    pub fn commit(mut self) -> std::io::Result<()> {
        let out = self.out.take().expect("an uncommitted file has its writer");
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        rename(&self.tmp, &self.path)
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out.as_mut().expect("not committed").write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.as_mut().expect("not committed").flush()
    }
}

/// Seeking flushes the buffer first (writers such as MCAP's go back to patch a header).
impl std::io::Seek for AtomicFile {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.out.as_mut().expect("not committed").seek(pos)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // A committed file was renamed; a failed commit or an abandoned one leaves the temporary.
        drop(self.out.take());
        if self.tmp.exists() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// A scratch file beside `path` (`.NAME.tmpPID`, so stale ones are cleaned like the temporaries
/// above): written in one pass, read back from the start in another, removed when dropped. It
/// holds what an output needs at its end but should not keep in memory meanwhile.
#[derive(Debug)]
pub struct ScratchFile {
    tmp: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
}

impl ScratchFile {
    /// Creates the scratch file for `path` (and `path`'s parent folders).
    pub fn create(path: &Path) -> std::io::Result<ScratchFile> {
        create_parent(path)?;
        remove_stale_temps(path);
        let tmp = temp_path(path);
        let file = std::fs::File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(&tmp)?;
        Ok(ScratchFile {
            tmp,
            out: std::io::BufWriter::with_capacity(1 << 16, file),
        })
    }

    /// Everything written so far, from the start (writing again after this is not supported).
    pub fn read_back(&mut self) -> std::io::Result<std::io::BufReader<std::fs::File>> {
        use std::io::Seek;
        self.out.flush()?;
        let mut file = self.out.get_ref().try_clone()?;
        file.rewind()?;
        Ok(std::io::BufReader::new(file))
    }
}

impl Write for ScratchFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.out.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

impl Drop for ScratchFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.tmp);
    }
}

/// Checks, before any work, that a file can be written at `path`: its folder exists
/// ([`check_parent`]) and takes a temporary file (removed again). An existing folder at `path`
/// is an error.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other("it is a folder; give a file name"));
    }
    check_parent(path)?;
    let tmp = temp_path(path);
    std::fs::File::create(&tmp)?;
    std::fs::remove_file(&tmp)
}

/// Checks, before any work, that files can be written into folder `dir` (created if missing).
pub fn check_writable_dir(dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    check_writable(&dir.join(".placewords-probe"))
}

/// An output folder written in full beside its final place (`.DIR.tmpPID`), then put in its
/// place by [`StagedDir::commit`] in one atomic exchange; dropped without a commit, the staging
/// folder is removed. While it lives, `.DIR.lock` beside the folder holds this process's pid.
#[derive(Debug)]
pub struct StagedDir {
    target: PathBuf,
    staging: PathBuf,
    lock: PathBuf,
    committed: bool,
}

/// Why an output folder cannot be staged.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    #[error(
        "{0}: the folder holds other files than an earlier output of this command; \
         choose an empty or new folder"
    )]
    Foreign(String),
    #[error(
        "{path}: another placewords (pid {pid}) is writing this output; wait for it to finish \
         or choose another path (if no such process runs, remove {lock})"
    )]
    Busy {
        path: String,
        pid: u32,
        lock: String,
    },
    #[error("{path}: cannot write: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

/// `.DIR.lock` beside `dir`.
fn lock_path(dir: &Path) -> PathBuf {
    dir.with_file_name(format!(".{}.lock", file_name(dir)))
}

/// Takes `.DIR.lock` for this process: `Ok(Some(pid))` when a live process holds it. A lock
/// whose process is gone is taken over.
fn take_lock(lock: &Path) -> std::io::Result<Option<u32>> {
    for _ in 0..2 {
        match std::fs::File::options()
            .write(true)
            .create_new(true)
            .open(lock)
        {
            Ok(mut f) => {
                write!(f, "{}", std::process::id())?;
                return Ok(None);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let text = std::fs::read_to_string(lock).unwrap_or_default();
                match text.trim().parse::<u32>() {
                    Ok(pid) if may_be_running(pid) && pid != std::process::id() => {
                        return Ok(Some(pid));
                    }
                    // Stale (its process is gone) or half-written: take it over.
                    _ => {
                        let _ = std::fs::remove_file(lock);
                    }
                }
            }
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::other("the lock file could not be taken"))
}

/// Takes the lock of output `path` and returns the lock file's path; [`StageError::Busy`] when
/// another live process holds it.
fn lock_for(path: &Path) -> Result<PathBuf, StageError> {
    let lock = lock_path(path);
    let taken = take_lock(&lock).map_err(|source| StageError::Io {
        path: lock.display().to_string(),
        source,
    })?;
    if let Some(pid) = taken {
        return Err(StageError::Busy {
            path: path.display().to_string(),
            pid,
            lock: lock.display().to_string(),
        });
    }
    Ok(lock)
}

/// Refuses a `dir` that is a file, or a folder that is neither empty nor, by `replaceable`,
/// an earlier output of the same kind.
fn check_replaceable(dir: &Path, replaceable: &dyn Fn(&Path) -> bool) -> Result<(), StageError> {
    if !dir.exists() {
        return Ok(());
    }
    let io = |source| StageError::Io {
        path: dir.display().to_string(),
        source,
    };
    if !dir.is_dir() {
        let e = std::io::Error::other("it is a file; give a folder name");
        return Err(io(e));
    }
    let empty = std::fs::read_dir(dir).map_err(io)?.next().is_none();
    if !empty && !replaceable(dir) {
        return Err(StageError::Foreign(dir.display().to_string()));
    }
    Ok(())
}

impl StagedDir {
    /// Stages output for `dir`. An existing `dir` must be empty or, by `replaceable`, an earlier
    /// output of the same kind (it is then replaced whole on commit); otherwise an error, before
    /// anything is written. A folder another live process is staging is refused
    /// ([`StageError::Busy`]).
    pub fn begin(dir: &Path, replaceable: &dyn Fn(&Path) -> bool) -> Result<StagedDir, StageError> {
        let io = |path: &Path, source| StageError::Io {
            path: path.display().to_string(),
            source,
        };
        check_replaceable(dir, replaceable)?;
        create_parent(dir).map_err(|e| io(dir, e))?;
        let lock = lock_for(dir)?;
        // From here the lock is ours: the value below releases it on every path.
        let mut staged = StagedDir {
            target: dir.to_path_buf(),
            staging: temp_path(dir),
            lock,
            committed: false,
        };
        remove_stale_temps(dir);
        let _ = std::fs::remove_dir_all(&staged.staging);
        if let Err(e) = std::fs::create_dir(&staged.staging) {
            staged.committed = true; // nothing staged to remove
            return Err(io(dir, e));
        }
        Ok(staged)
    }

    /// The folder to write into now.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The final folder.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Puts the staged folder in the target's place. An old target is exchanged with it in one
    /// atomic step and then removed; where the exchange is not available, the old target is
    /// first moved aside (to `.DIR.tmpPID-old`) and removed after, so the target is never a mix
    /// of two runs (though a kill between those two renames leaves it missing).
    pub fn commit(mut self) -> std::io::Result<()> {
        let result = self.put_in_place();
        self.committed = result.is_ok();
        result
    }

    fn put_in_place(&self) -> std::io::Result<()> {
        if !self.target.exists() {
            return rename(&self.staging, &self.target);
        }
        if exchange(&self.staging, &self.target)? {
            // The staging path now holds the old output.
            let _ = std::fs::remove_dir_all(&self.staging);
            return Ok(());
        }
        let old = self
            .staging
            .with_file_name(format!("{}-old", file_name(&self.staging)));
        rename(&self.target, &old)?;
        if let Err(e) = rename(&self.staging, &self.target) {
            let _ = std::fs::rename(&old, &self.target);
            return Err(e);
        }
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
        let _ = std::fs::remove_file(&self.lock);
    }
}

/// Whether `dir` holds at least one file `named` accepts and nothing else but hidden files: an
/// earlier output of a command that writes those names, which a new output may replace whole.
pub fn holds_only(dir: &Path, named: &dyn Fn(&str) -> bool) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    let mut any = false;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        if !named(&name) || !e.file_type().is_ok_and(|t| t.is_file()) {
            return false;
        }
        any = true;
    }
    any
}

/// A folder an output set replaces whole, with the test of what may be in the old one.
pub type Replaced<'a> = (&'a Path, &'a dyn Fn(&Path) -> bool);

/// Several outputs at paths of the user's choosing (`run --report R.json --export-matches M.csv
/// --svg DIR`, `check --report … --junit … -o DIR`) written as one: a kill at any instant leaves
/// the old set or the new set, as every placewords reader and writer of those paths sees them.
///
/// No single rename can swap files in different folders, so the set commits by a journal
/// ("write-ahead"): every file is first written in full beside its place (`.NAME.tmpPID`; a
/// picture folder's files in `.DIR.tmpPID/`, a replaced folder as [`StagedDir`] stages it);
/// then a journal naming every move is left beside each output (`.NAME.pendingPID`); then the
/// commit marker (`.FIRST.commitPID`) is made by renaming the first output's journal — the
/// instant the new set is the result, with no temporary file of its own for a kill to leave; then the moves are made and the journals removed, the
/// marker last. A process killed before the marker leaves the old set (its temporaries are
/// removed later as any killed writer's); killed after it, the new set is complete on disk and
/// [`settle`], which every reader of these outputs (`score --matches`, `compare`, `merge`,
/// `check --baseline`) and every writer of them calls first, finishes the moves. While the set
/// is written, `.NAME.lock` beside each output holds the pid, as for a staged folder, and
/// another writer is refused ([`StageError::Busy`]).
///
/// A set of one output (`check -o DIR` alone, `run --report R` alone) needs no journal: it
/// commits by the one rename of its file, or the one exchange of its folder ([`StagedDir`]), so
/// even a reader that does not settle finds the old output or the new one whole.
#[derive(Debug)]
pub struct OutputSet {
    /// Output files, each with where it is staged.
    files: Vec<(PathBuf, PathBuf)>,
    /// Picture folders (files added to the folder, others left), with their staging folder.
    dirs: Vec<(PathBuf, PathBuf)>,
    /// Folders replaced whole.
    replaced: Vec<StagedDir>,
    locks: Vec<PathBuf>,
    finished: bool,
}

/// What a set's journal and marker hold.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct Journal {
    /// The writing process.
    pid: u32,
    /// The commit marker: the set is committed once it exists.
    marker: PathBuf,
    /// File moves, staged → final.
    moves: Vec<(PathBuf, PathBuf)>,
    /// Folders replaced whole, staged → final (the staged one holds [`SET_TAG`] naming the
    /// marker until it is in place, so a repeated move is never made twice).
    folders: Vec<(PathBuf, PathBuf)>,
    /// The journals beside each output, and the staging folders to remove after the moves.
    pendings: Vec<PathBuf>,
    staging: Vec<PathBuf>,
}

impl Journal {
    /// The journal with every path absolute, so a reader in another folder finds them.
    fn absolute(self) -> std::io::Result<Journal> {
        let abs = |p: &PathBuf| std::path::absolute(p);
        let pair = |(a, b): &(PathBuf, PathBuf)| Ok::<_, std::io::Error>((abs(a)?, abs(b)?));
        Ok(Journal {
            pid: self.pid,
            marker: abs(&self.marker)?,
            moves: self.moves.iter().map(pair).collect::<Result<_, _>>()?,
            folders: self.folders.iter().map(pair).collect::<Result<_, _>>()?,
            pendings: self.pendings.iter().map(abs).collect::<Result<_, _>>()?,
            staging: self.staging.iter().map(abs).collect::<Result<_, _>>()?,
        })
    }
}

/// The file inside a staged replacement folder naming its set's marker (removed once in place).
const SET_TAG: &str = ".placewords-set";

/// Creates picture folder `dir` when missing and an empty staging folder for it, returned.
fn fresh_staging(dir: &Path) -> Result<PathBuf, StageError> {
    let io = |source| StageError::Io {
        path: dir.display().to_string(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    remove_stale_temps(dir);
    let staging = temp_path(dir);
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir(&staging).map_err(io)?;
    Ok(staging)
}

impl OutputSet {
    /// Begins a set of output `files`, picture folders `dirs` (created if missing; the set's files
    /// are added to them) and folders `replaced`, each replaced whole when it is empty, new or,
    /// by its test, an earlier output of the same kind. Finishes first any set a killed process
    /// committed at these paths ([`settle`]); refuses paths another live process writes.
    pub fn begin(
        files: &[&Path],
        dirs: &[&Path],
        replaced: &[Replaced<'_>],
    ) -> Result<OutputSet, StageError> {
        let mut set = OutputSet {
            files: Vec::new(),
            dirs: Vec::new(),
            replaced: Vec::new(),
            locks: Vec::new(),
            finished: false,
        };
        set.lock_outputs(files)?;
        set.lock_outputs(dirs)?;
        for &file in files {
            remove_stale_temps(file);
            set.files.push((file.to_path_buf(), temp_path(file)));
        }
        for &dir in dirs {
            let staging = fresh_staging(dir)?;
            set.dirs.push((dir.to_path_buf(), staging));
        }
        for &(dir, replaceable) in replaced {
            settle(dir);
            set.replaced.push(StagedDir::begin(dir, replaceable)?);
        }
        Ok(set)
    }

    /// Takes the lock of each of `paths`, after settling what a process left there.
    fn lock_outputs(&mut self, paths: &[&Path]) -> Result<(), StageError> {
        for &path in paths {
            settle(path);
            self.locks.push(lock_for(path)?);
        }
        Ok(())
    }

    /// Writes output file `path` (one of the set's files) in full, staged until the commit.
    pub fn write(&self, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        let (_, staged) = self
            .files
            .iter()
            .find(|(f, _)| f == path)
            .ok_or_else(|| std::io::Error::other("not an output of this set"))?;
        let mut f = std::fs::File::create(staged)?;
        f.write_all(bytes)?;
        f.sync_all()
    }

    /// Where to write the files of folder `dir` (one of the set's picture or replaced folders)
    /// until the commit.
    pub fn dir(&self, dir: &Path) -> Option<&Path> {
        self.dirs
            .iter()
            .find(|(d, _)| d == dir)
            .map(|(_, s)| s.as_path())
            .or_else(|| {
                self.replaced
                    .iter()
                    .find(|s| s.target() == dir)
                    .map(StagedDir::path)
            })
    }

    /// Puts every output written in its place, as one (see the type's doc). Outputs of the set
    /// never written are left as they were.
    pub fn commit(mut self) -> std::io::Result<()> {
        if self.dirs.is_empty() && self.files.len() + self.replaced.len() == 1 {
            return self.commit_single();
        }
        let pid = std::process::id();
        let mut moves: Vec<(PathBuf, PathBuf)> = self
            .files
            .iter()
            .filter(|(_, staged)| staged.exists())
            .map(|(target, staged)| (staged.clone(), target.clone()))
            .collect();
        for (dir, staging) in &self.dirs {
            for e in std::fs::read_dir(staging)? {
                let e = e?;
                moves.push((e.path(), dir.join(e.file_name())));
            }
        }
        let folders: Vec<(PathBuf, PathBuf)> = self
            .replaced
            .iter()
            .map(|s| (s.path().to_path_buf(), s.target().to_path_buf()))
            .collect();
        let outputs: Vec<&Path> = self
            .files
            .iter()
            .map(|(f, _)| f.as_path())
            .chain(self.dirs.iter().map(|(d, _)| d.as_path()))
            .chain(folders.iter().map(|(_, d)| d.as_path()))
            .collect();
        let Some(first) = outputs.first() else {
            self.finished = true;
            return Ok(());
        };
        let marker = first.with_file_name(format!(".{}.commit{pid}", file_name(first)));
        let pendings = outputs
            .iter()
            .map(|p| p.with_file_name(format!(".{}.pending{pid}", file_name(p))))
            .collect();
        let journal = Journal {
            pid,
            marker,
            moves,
            folders,
            pendings,
            staging: self.dirs.iter().map(|(_, s)| s.clone()).collect(),
        };
        let journal = journal.absolute()?;
        for (staged, _) in &journal.folders {
            std::fs::write(staged.join(SET_TAG), journal.marker.display().to_string())?;
        }
        let text = serde_json::to_vec(&journal).map_err(std::io::Error::other)?;
        for p in &journal.pendings {
            let mut f = std::fs::File::create(p)?;
            f.write_all(&text)?;
            f.sync_all()?;
        }
        // The commit: from here the new set is the result, whatever happens to this process. The
        // first output's journal becomes the marker by one rename, so no temporary file of the
        // marker exists for a kill to leave behind.
        rename(&journal.pendings[0], &journal.marker)?;
        self.finished = true;
        for s in &mut self.replaced {
            s.committed = true; // its move is the journal's now
        }
        apply(&journal)
    }
}

impl OutputSet {
    /// Commits a set of one output (a file, or a folder replaced whole) by one rename or
    /// exchange: no journal, so nothing is left for [`settle`] and a reader never sees a
    /// committed-but-unmoved output.
    fn commit_single(mut self) -> std::io::Result<()> {
        if let Some(stage) = self.replaced.pop() {
            self.finished = true;
            return stage.commit();
        }
        let (target, staged) = &self.files[0];
        if staged.exists() {
            rename(staged, target)?;
        }
        self.finished = true;
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.finished {
            for (_, staged) in &self.files {
                let _ = std::fs::remove_file(staged);
            }
            for (_, staging) in &self.dirs {
                let _ = std::fs::remove_dir_all(staging);
            }
        }
        for lock in &self.locks {
            let _ = std::fs::remove_file(lock);
        }
    }
}

/// Makes a committed journal's moves (those not made yet), then removes the journals, the
/// staging folders and the marker, in that order, so a kill anywhere here leaves a journal to
/// finish from.
fn apply(journal: &Journal) -> std::io::Result<()> {
    for (from, to) in &journal.moves {
        if from.exists() {
            rename(from, to)?;
        }
    }
    let tag = journal.marker.display().to_string();
    for (from, to) in &journal.folders {
        let ours = std::fs::read_to_string(from.join(SET_TAG)).is_ok_and(|t| t == tag);
        if ours && to.exists() {
            replace_folder(from, to)?;
        } else if ours {
            rename(from, to)?;
        }
        // What is left at `from` is the old folder (or nothing).
        let _ = std::fs::remove_dir_all(from);
        let _ = std::fs::remove_file(to.join(SET_TAG));
    }
    for p in &journal.pendings {
        let _ = std::fs::remove_file(p);
    }
    for s in &journal.staging {
        let _ = std::fs::remove_dir_all(s);
    }
    let _ = std::fs::remove_file(&journal.marker);
    Ok(())
}

/// Puts folder `from` in the place of the existing `to`, atomically where the system can
/// exchange them; the old `to` ends up at `from` or removed.
fn replace_folder(from: &Path, to: &Path) -> std::io::Result<()> {
    if !exchange(from, to)? {
        let old = from.with_file_name(format!("{}-old", file_name(from)));
        rename(to, &old)?;
        rename(from, to)?;
        let _ = std::fs::remove_dir_all(&old);
    }
    Ok(())
}

/// Finishes or drops an output set a process left at `path` ([`OutputSet`]): a journal whose
/// marker exists is committed, and its moves are made; one without a marker whose process is
/// gone was never committed, and is removed (the old output stays). A set whose process still
/// runs is waited for, a few seconds at most, as its moves take milliseconds. Every reader of
/// an output a set may write calls this before reading.
pub fn settle(path: &Path) {
    let dir = match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    let name = file_name(path);
    let (pending, commit) = (format!(".{name}.pending"), format!(".{name}.commit"));
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let entries: Vec<std::fs::DirEntry> = entries.flatten().collect();
    // The temporary file of a marker (`..NAME.commitPID.tmpPID`, as versions that wrote the
    // marker through one could leave) of a process that is gone: never a commit, removed.
    let marker_temp = format!(".{commit}");
    for e in &entries {
        let n = e.file_name().to_string_lossy().into_owned();
        let Some((_, pid)) = n
            .strip_prefix(&marker_temp)
            .and_then(|t| t.rsplit_once(".tmp"))
        else {
            continue;
        };
        if pid.parse::<u32>().is_ok_and(|pid| !may_be_running(pid)) {
            let _ = std::fs::remove_file(e.path());
        }
    }
    let journals: Vec<PathBuf> = entries
        .iter()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            [&pending, &commit].iter().any(|p| {
                n.strip_prefix(p.as_str())
                    .is_some_and(|pid| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
            })
        })
        .map(|e| e.path())
        .collect();
    for j in journals {
        for _ in 0..100 {
            let Ok(bytes) = std::fs::read(&j) else {
                break; // finished meanwhile
            };
            let journal: Option<Journal> = serde_json::from_slice(&bytes).ok();
            let pid = j
                .to_string_lossy()
                .rsplit(|c: char| !c.is_ascii_digit())
                .next()
                .and_then(|p| p.parse::<u32>().ok());
            let live = pid.is_some_and(|p| p != std::process::id() && may_be_running(p));
            if live {
                std::thread::sleep(std::time::Duration::from_millis(50));
                continue;
            }
            match journal {
                Some(journal) if journal.marker.exists() => {
                    let _ = apply(&journal);
                }
                // Never committed (or half-written before the marker): the old output stands.
                _ => {
                    let _ = std::fs::remove_file(&j);
                }
            }
            break;
        }
    }
}
