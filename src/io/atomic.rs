//! Atomic output: write to a temporary file beside the target, then rename, so an interrupted
//! run never leaves a half-written file under a final name; output folders are staged the same
//! way ([`StagedDir`]), so a folder holds one complete run or is left as it was.
//!
//! Temporary names are `.NAME.tmpPID` (hidden, beside `NAME`; PID the writing process). Every
//! error path removes them. A process killed outright (`kill -9`, a file-size limit) cannot, so
//! the next write of `NAME` in that folder removes the `.NAME.tmpPID` of any process that no
//! longer runs (on systems with `/proc`; elsewhere they stay, hidden, and nothing reads them).

use std::io::Write;
use std::path::{Path, PathBuf};

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
        std::fs::rename(&tmp, path)
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

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file onto its final path.
    pub fn commit(mut self) -> std::io::Result<()> {
        let out = self.out.take().expect("an uncommitted file has its writer");
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&self.tmp, &self.path)
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

/// An output folder written in full beside its final place (`.DIR.tmpPID`), then renamed onto
/// it by [`StagedDir::commit`]; dropped without a commit, the staging folder is removed.
#[derive(Debug)]
pub struct StagedDir {
    target: PathBuf,
    staging: PathBuf,
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
    #[error("{path}: cannot write: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

impl StagedDir {
    /// Stages output for `dir`. An existing `dir` must be empty or, by `replaceable`, an earlier
    /// output of the same kind (it is then replaced whole on commit); otherwise an error, before
    /// anything is written.
    pub fn begin(dir: &Path, replaceable: &dyn Fn(&Path) -> bool) -> Result<StagedDir, StageError> {
        let io = |path: &Path, source| StageError::Io {
            path: path.display().to_string(),
            source,
        };
        if dir.exists() {
            let empty = std::fs::read_dir(dir)
                .map_err(|e| io(dir, e))?
                .next()
                .is_none();
            if !empty && !replaceable(dir) {
                return Err(StageError::Foreign(dir.display().to_string()));
            }
        }
        create_parent(dir).map_err(|e| io(dir, e))?;
        remove_stale_temps(dir);
        let staging = temp_path(dir);
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging).map_err(|e| io(dir, e))?;
        Ok(StagedDir {
            target: dir.to_path_buf(),
            staging,
            committed: false,
        })
    }

    /// The folder to write into now.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The final folder.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Moves the staged folder onto the target: an old target is first moved aside (to
    /// `.DIR.tmpPID-old`) and removed after, so the target is never a mix of two runs.
    pub fn commit(mut self) -> std::io::Result<()> {
        let old = self
            .staging
            .with_file_name(format!("{}-old", file_name(&self.staging)));
        let moved_aside = self.target.exists();
        if moved_aside {
            std::fs::rename(&self.target, &old)?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if moved_aside {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(e);
        }
        self.committed = true;
        if moved_aside {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}
