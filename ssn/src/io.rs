//! Checked input and output of the `ssn` program.
//!
//! Contract (README "Exit codes"):
//! - Results go to standard output through [`write_stdout`], which reports every failure
//!   (a full device, a closed pipe, a closed descriptor) as an [`OutputError`] (exit code 3)
//!   instead of panicking like `println!`. [`guard_standard_streams`], called first thing
//!   by `main`, notices a closed standard output or error (a write to a closed descriptor
//!   would otherwise "succeed" silently) and parks `/dev/null` on the free descriptors so
//!   that no file the program opens later takes their number.
//! - `--quiet` ([`set_quiet`]) silences the text summaries ([`write_text`]); what a user
//!   asked for explicitly (`--json`, an output named `-`) and errors are still written.
//! - Output files are an [`OutputSet`]: every target is checked before the solve (a
//!   symbolic link, a device, a FIFO or a directory is never replaced; no target is an
//!   input; no two outputs share a path), written to exclusive temporary files (the
//!   `tempfile` crate) in its directory and renamed into place only when all of them were
//!   written, so a failed run leaves none of them (and no temporary file) behind.

use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
static QUIET: AtomicBool = AtomicBool::new(false);

/// The name that stands for standard output in an output option.
pub const STDOUT_NAME: &str = "-";

/// Checks standard output once, first thing in `main`: when it was closed, every later
/// [`write_stdout`] is an error.
///
/// The Rust runtime opens `/dev/null` read-write on a closed descriptor 0, 1 or 2 before
/// `main` (so that no file opened later takes its number); a standard output that is
/// `/dev/null` opened read-write is taken for such a closed one (a shell's `> /dev/null`
/// opens it write-only and stays a normal, silent output). Where `/proc` is not available
/// this check finds nothing.
pub fn guard_standard_streams() {
    let closed = std::io::stdout().as_fd().try_clone_to_owned().is_err()
        || runtime_replaced_stdout().unwrap_or(false);
    STDOUT_CLOSED.store(closed, Ordering::Relaxed);
}

/// Whether descriptor 1 is `/dev/null` opened read-write (Linux `/proc`).
fn runtime_replaced_stdout() -> Option<bool> {
    let target = std::fs::read_link("/proc/self/fd/1").ok()?;
    if target != Path::new("/dev/null") {
        return Some(false);
    }
    let info = std::fs::read_to_string("/proc/self/fdinfo/1").ok()?;
    let flags = info
        .lines()
        .find_map(|l| l.strip_prefix("flags:"))
        .and_then(|f| u32::from_str_radix(f.trim(), 8).ok())?;
    // O_ACCMODE = 3, O_RDWR = 2.
    Some(flags & 3 == 2)
}

/// Whether text summaries are silenced (`--quiet`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

fn stdout_error(source: std::io::Error) -> OutputError {
    OutputError::Io {
        path: PathBuf::from("standard output"),
        source,
    }
}

/// Writes `text` to standard output and flushes it; every failure is an error.
pub fn write_stdout(text: &str) -> Result<(), OutputError> {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return Err(stdout_error(std::io::Error::new(
            std::io::ErrorKind::BrokenPipe,
            "standard output is closed",
        )));
    }
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(stdout_error)
}

/// Writes a text summary to standard output unless `--quiet`.
pub fn write_text(text: &str) -> Result<(), OutputError> {
    if quiet() {
        Ok(())
    } else {
        write_stdout(text)
    }
}

/// Writes a message to standard error; a failure to do so is ignored (there is nowhere
/// left to report it), never a panic.
pub fn write_stderr(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes()).and_then(|()| err.flush());
}

/// `outln!(...)`: a line of text summary on standard output (nothing with `--quiet`),
/// returning `Result<(), OutputError>`.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::io::write_text("\n")
    };
    ($($arg:tt)*) => {
        $crate::io::write_text(&format!("{}\n", format_args!($($arg)*)))
    };
}

/// Largest scene file read, in bytes (the shipped scenes are under 2 kB).
pub const SCENE_SIZE_LIMIT: u64 = 1 << 20;

/// Reads a text input that must be a regular file of at most `limit` bytes: a FIFO, a
/// device or a directory is refused before it is opened (reading one could block forever
/// or never end), and a longer file is refused after `limit + 1` bytes.
pub fn read_regular_file(path: &Path, limit: u64) -> std::io::Result<String> {
    let invalid = |what: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, what);
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(invalid(format!(
            "not a regular file ({}): a scene is read from a regular file",
            file_kind(&meta.file_type())
        )));
    }
    let mut text = String::new();
    let read = File::open(path)?
        .take(limit + 1)
        .read_to_string(&mut text)?;
    if read as u64 > limit {
        return Err(invalid(format!(
            "larger than the limit of {limit} bytes for a scene file"
        )));
    }
    Ok(text)
}

fn file_kind(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Why an output target was refused before anything ran.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// The target exists and is not a regular file (exit code 3).
    #[error(
        "{path}: an output replaces only regular files, and this is {kind} (name a regular file, \
         or `-` for standard output)"
    )]
    NotRegular {
        /// The output path.
        path: PathBuf,
        /// What it is.
        kind: &'static str,
    },
    /// Two outputs, or an output and an input, name one file (exit code 2).
    #[error(
        "{path}: named as both {first} and {second}: an input is never replaced, and each \
         output needs a file of its own"
    )]
    Clash {
        /// The path.
        path: PathBuf,
        /// The first use (option or input).
        first: String,
        /// The second use.
        second: String,
    },
}

/// The identity of a file for clash detection: its device and inode when it exists, else
/// its absolute path with the parent resolved.
#[derive(PartialEq, Eq, Debug)]
enum Identity {
    Inode(u64, u64),
    Path(PathBuf),
    Stdout,
}

fn identity(path: &Path) -> Identity {
    use std::os::unix::fs::MetadataExt;
    if path.as_os_str() == STDOUT_NAME {
        return Identity::Stdout;
    }
    if let Ok(m) = std::fs::metadata(path) {
        return Identity::Inode(m.dev(), m.ino());
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let parent = std::fs::canonicalize(parent).unwrap_or_else(|_| parent.to_path_buf());
    Identity::Path(parent.join(path.file_name().unwrap_or_default()))
}

/// The outputs of one run: checked before the run, written all or nothing after it.
#[derive(Debug, Default)]
pub struct OutputSet {
    /// Files already claimed, with the name of their use and whether it is an output.
    claimed: Vec<(Identity, String, bool)>,
    /// Contents to write, in order.
    pending: Vec<(PathBuf, Vec<u8>)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Claims an input (the scene, a file it names, a start state): no output may replace
    /// it; `Err` when an output claimed before names it.
    pub fn input(&mut self, path: &Path, what: &str) -> Result<(), TargetError> {
        self.claim(path, what, false)
    }

    /// Claims standard output for `what` (e.g. `--json`).
    pub fn stdout(&mut self, what: &str) -> Result<(), TargetError> {
        self.target(Path::new(STDOUT_NAME), what)
    }

    /// Checks and claims the output `path` for `what` (an option name): it must not exist
    /// or be a regular file, and must not be claimed already. `-` is standard output.
    pub fn target(&mut self, path: &Path, what: &str) -> Result<(), TargetError> {
        if path.as_os_str() != STDOUT_NAME {
            if let Ok(meta) = std::fs::symlink_metadata(path) {
                if !meta.is_file() {
                    return Err(TargetError::NotRegular {
                        path: path.to_path_buf(),
                        kind: file_kind(&meta.file_type()),
                    });
                }
            }
        }
        self.claim(path, what, true)
    }

    /// Claims `path` for `what`, an output or an input: `Err` when a claim before names the
    /// same file and one of the two is an output (two inputs may share a file).
    fn claim(&mut self, path: &Path, what: &str, output: bool) -> Result<(), TargetError> {
        let id = identity(path);
        let clash = |(i, _, out): &&(Identity, String, bool)| *i == id && (output || *out);
        if let Some((_, first, _)) = self.claimed.iter().find(clash) {
            return Err(TargetError::Clash {
                path: path.to_path_buf(),
                first: first.clone(),
                second: what.to_string(),
            });
        }
        self.claimed.push((id, what.to_string(), output));
        Ok(())
    }

    /// Queues the contents of a claimed target (`-`: standard output, written first).
    pub fn add(&mut self, path: &Path, bytes: Vec<u8>) {
        self.pending.push((path.to_path_buf(), bytes));
    }

    /// Writes every queued file to a temporary file beside it, checks every target again,
    /// writes the standard-output contents, then renames the files into place; when a file
    /// or standard output cannot be written, none is renamed and the temporary files are
    /// removed. The directories written into are locked (`flock`) meanwhile, so two runs
    /// writing into one directory at once leave one run's complete set, never a mix.
    pub fn commit(self) -> Result<(), OutputError> {
        let mut to_stdout = Vec::new();
        let mut files = Vec::new();
        for (path, bytes) in self.pending {
            if path.as_os_str() == STDOUT_NAME {
                to_stdout.push(bytes);
            } else {
                files.push((path, bytes));
            }
        }
        let _locks = lock_directories(files.iter().map(|(p, _)| p.as_path()))?;
        let mut staged = Vec::new();
        for (path, bytes) in files {
            let tmp = stage(&path, &bytes)?;
            staged.push((path, Staged::new(tmp)));
        }
        // The targets were checked before the run; check them all again before replacing
        // any.
        for (path, _) in &staged {
            if let Ok(meta) = std::fs::symlink_metadata(path) {
                if !meta.is_file() {
                    return Err(OutputError::Io {
                        source: std::io::Error::other(format!(
                            "it became {} during the run: not replaced",
                            file_kind(&meta.file_type())
                        )),
                        path: path.clone(),
                    });
                }
            }
        }
        for bytes in to_stdout {
            write_stdout(&String::from_utf8_lossy(&bytes))?;
        }
        for (path, tmp) in staged {
            tmp.persist(&path)?;
        }
        Ok(())
    }
}

/// A staged temporary file, registered for removal on an interrupt until it is renamed
/// into place or dropped.
struct Staged(Option<tempfile::NamedTempFile>);

impl Staged {
    fn new(tmp: tempfile::NamedTempFile) -> Self {
        register_cleanup(tmp.path());
        Self(Some(tmp))
    }

    fn persist(mut self, path: &Path) -> Result<(), OutputError> {
        let tmp = self.0.take().expect("a staged file is persisted once");
        let temporary = tmp.path().to_path_buf();
        let result = tmp.persist(path).map_err(|e| OutputError::Io {
            path: path.to_path_buf(),
            source: e.error,
        });
        unregister_cleanup(&temporary);
        result.map(|_| ())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(tmp) = self.0.take() {
            unregister_cleanup(tmp.path());
        }
    }
}

/// Exclusive `flock`s on the distinct directories of `paths`, taken in a fixed order (no
/// two runs wait on each other), released when dropped.
fn lock_directories<'a>(
    paths: impl Iterator<Item = &'a Path>,
) -> Result<Vec<std::fs::File>, OutputError> {
    // Each directory once, with the first file written into it (the one an error names).
    let mut dirs: Vec<(PathBuf, &Path)> = paths
        .map(|p| {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            (
                std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()),
                p,
            )
        })
        .collect();
    dirs.sort_by(|a, b| a.0.cmp(&b.0));
    dirs.dedup_by(|a, b| a.0 == b.0);
    let mut locks = Vec::with_capacity(dirs.len());
    for (dir, file) in dirs {
        let io = |source: std::io::Error| OutputError::Io {
            path: file.to_path_buf(),
            source: std::io::Error::new(
                source.kind(),
                format!("its directory {}: {source}", dir.display()),
            ),
        };
        let handle = File::open(&dir).map_err(io)?;
        rustix::fs::flock(&handle, rustix::fs::FlockOperation::LockExclusive)
            .map_err(|e| io(e.into()))?;
        locks.push(handle);
    }
    Ok(locks)
}

/// Paths removed when the program is interrupted: staged temporary files and output
/// directories a run created.
static CLEANUP: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Registers `path` for removal on an interrupt ([`remove_on_interrupt`]).
pub fn register_cleanup(path: &Path) {
    if let Ok(mut list) = CLEANUP.lock() {
        list.push(path.to_path_buf());
    }
}

/// Forgets `path` (kept, or removed already).
pub fn unregister_cleanup(path: &Path) {
    if let Ok(mut list) = CLEANUP.lock() {
        if let Some(k) = list.iter().rposition(|p| p == path) {
            list.remove(k);
        }
    }
}

/// What an interrupted run keeps, in words (`None`: nothing, the run's outputs are
/// written at its end).
static KEPT_ON_INTERRUPT: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Says what an interrupted run keeps (a study keeps the records of the cases done), in
/// the message of [`remove_on_interrupt`].
pub fn keep_on_interrupt(kept: String) {
    if let Ok(mut k) = KEPT_ON_INTERRUPT.lock() {
        *k = Some(kept);
    }
}

/// Exit code of a run ended by a signal (128 + SIGINT, as a shell reports it).
pub const INTERRUPTED_EXIT_CODE: i32 = 130;

/// On SIGINT, SIGTERM or SIGHUP: removes the registered staged files and created
/// directories (so an interrupted run leaves nothing half-written behind), says so on
/// standard error and exits with [`INTERRUPTED_EXIT_CODE`]. Called first thing by `main`;
/// a failure to install the handler leaves the default behaviour.
pub fn remove_on_interrupt() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    let spawned = std::thread::Builder::new()
        .name("interrupt".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let paths = CLEANUP
                    .lock()
                    .map(|mut l| std::mem::take(&mut *l))
                    .unwrap_or_default();
                for path in paths.iter().rev() {
                    let _ = if path.is_dir() {
                        std::fs::remove_dir_all(path)
                    } else {
                        std::fs::remove_file(path)
                    };
                }
                let kept = KEPT_ON_INTERRUPT.lock().ok().and_then(|k| k.clone());
                write_stderr(&format!(
                    "interrupted (signal {signal}): {}\n",
                    kept.unwrap_or_else(|| "no output written".into())
                ));
                std::process::exit(INTERRUPTED_EXIT_CODE);
            }
        });
    drop(spawned);
}

/// The set [`write_atomically`] queues into while [`all_or_nothing`] runs.
static COLLECTING: std::sync::Mutex<Option<OutputSet>> = std::sync::Mutex::new(None);

/// Runs `run`, whose [`write_atomically`] calls are queued instead of written, and
/// commits them together when it succeeds ([`OutputSet::commit`]): a run that fails, or
/// whose last file cannot be written, leaves none of them.
pub fn all_or_nothing<T, E: From<OutputError>>(run: impl FnOnce() -> Result<T, E>) -> Result<T, E> {
    if let Ok(mut c) = COLLECTING.lock() {
        *c = Some(OutputSet::new());
    }
    let result = run();
    let set = COLLECTING.lock().ok().and_then(|mut c| c.take());
    let value = result?;
    if let Some(set) = set {
        set.commit()?;
    }
    Ok(value)
}

/// Writes `bytes` to a new exclusive temporary file in `path`'s directory (mode 0644
/// before the umask, like a file created by the shell).
fn stage(path: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile, OutputError> {
    use std::os::unix::fs::PermissionsExt;
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .permissions(std::fs::Permissions::from_mode(0o644))
        .tempfile_in(dir)
        .map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    Ok(tmp)
}

/// Escapes control characters (ANSI escape sequences, carriage returns, ...) of a text
/// read from a file before it is printed to a terminal: `\u{1b}` is printed as `\u{1b}`.
pub fn printable(text: &str) -> String {
    text.chars()
        .flat_map(|c| {
            if c.is_control() {
                c.escape_unicode().collect::<Vec<_>>()
            } else {
                vec![c]
            }
        })
        .collect()
}

/// `text` with its control characters escaped but its line breaks kept: an error message
/// prints a file name or a value from the input (a raw ESC would drive the terminal).
pub fn printable_message(text: &str) -> String {
    text.split('\n')
        .map(printable)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Why an output could not be produced.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// A file or directory could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The target path.
        path: PathBuf,
        /// The system error.
        source: std::io::Error,
    },
    /// The plot could not be drawn.
    #[error("cannot draw plot {title:?}: {reason}")]
    Plot {
        /// The plot's title.
        title: String,
        /// What went wrong.
        reason: String,
    },
}

/// Writes `bytes` to `path` through an exclusive temporary file in the same directory and a
/// rename: readers see either the old file or the whole new one. A target that exists and
/// is not a regular file (a symbolic link, a device, a FIFO, a directory) is not replaced
/// (see [`OutputSet`], which writes several files all or nothing). Within
/// [`all_or_nothing`] the file is queued and written with the run's other files.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let refused = |e: TargetError| OutputError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    };
    if let Ok(mut collecting) = COLLECTING.lock() {
        if let Some(set) = collecting.as_mut() {
            set.target(path, "output").map_err(refused)?;
            set.add(path, bytes.to_vec());
            return Ok(());
        }
    }
    let mut set = OutputSet::new();
    set.target(path, "output").map_err(refused)?;
    set.add(path, bytes.to_vec());
    set.commit()
}

/// Creates `dir` (and parents) and checks that a file can be created in it (an anonymous
/// temporary file, removed when closed).
pub fn prepare_directory(dir: &Path) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    tempfile::tempfile_in(dir).map_err(io)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_text_kept() {
        assert_eq!(printable("a\u{1b}[31mb\tc"), "a\\u{1b}[31mb\\u{9}c");
        assert_eq!(printable("rod, gap 0.5 µm"), "rod, gap 0.5 µm");
    }

    #[test]
    fn a_set_that_fails_leaves_nothing_and_one_that_succeeds_leaves_only_its_files() {
        let dir = tempfile::tempdir().unwrap();
        let ok = dir.path().join("a.csv");
        let missing = dir.path().join("no/such/dir/b.svg");
        let mut set = OutputSet::new();
        set.target(&ok, "--csv").unwrap();
        set.target(&missing, "--svg").unwrap();
        set.add(&ok, b"one".to_vec());
        set.add(&missing, b"two".to_vec());
        assert!(set.commit().is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

        let mut set = OutputSet::new();
        set.target(&ok, "--csv").unwrap();
        set.add(&ok, b"one".to_vec());
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&ok).unwrap(), "one");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn clashes_and_non_regular_targets_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("s.toml");
        std::fs::write(&scene, "x").unwrap();
        let mut set = OutputSet::new();
        set.input(&scene, "the scene").unwrap();
        let e = set.target(&scene, "--csv").unwrap_err().to_string();
        assert!(e.contains("the scene") && e.contains("--csv"), "{e}");
        let out = dir.path().join("o.csv");
        set.target(&out, "--csv").unwrap();
        // The same file through another spelling.
        let e = set
            .target(&dir.path().join(".").join("o.csv"), "--svg")
            .unwrap_err();
        assert!(matches!(e, TargetError::Clash { .. }), "{e}");
        let e = set.target(Path::new("/dev/null"), "--svg").unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&out, &link).unwrap();
        let e = set.target(&link, "--svg").unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
        set.stdout("--json").unwrap();
        assert!(set.target(Path::new("-"), "--csv").is_err());
    }

    #[test]
    fn a_fifo_or_an_oversized_file_is_not_read() {
        let dir = tempfile::tempdir().unwrap();
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; 100]).unwrap();
        let e = read_regular_file(&big, 99).unwrap_err().to_string();
        assert!(e.contains("99 bytes"), "{e}");
        assert_eq!(read_regular_file(&big, 100).unwrap().len(), 100);
        let e = read_regular_file(Path::new("/dev/zero"), 100)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a device"), "{e}");
        let e = read_regular_file(dir.path(), 100).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
    }
}
