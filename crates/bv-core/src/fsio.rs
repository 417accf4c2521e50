//! Reading and writing user-named files without surprises: the one place
//! where bv opens a file it did not create, and where it replaces one.
//!
//! # Reading ([`open_regular`], [`read_capped`])
//! A path a user types may name anything: a FIFO (opening it blocks until a
//! writer appears, possibly forever), a device (`/dev/zero` never ends), a
//! directory, or a regular file far larger than anything bv reads. So every
//! read checks the file's kind with `stat` before opening; opens with
//! `O_NONBLOCK` on unix, so that a FIFO swapped in after the check still
//! cannot block; checks the opened file again with `fstat` (same kind, same
//! inode); refuses a size above the caller's cap; and reads through
//! `Read::take(cap + 1)`, so a file that grows while it is read cannot make
//! bv hold more than the cap.
//!
//! # Writing ([`write_atomic`])
//! The new contents go to a temporary file beside the target (created with
//! `O_EXCL`, never over an existing file), are synced, and the temporary is
//! renamed over the target: readers see the old file or the whole new one,
//! and a failed write (full disk, killed process) leaves the old file intact.
//! The temporary's name is short (`.bv-PID-XXXXXXXX.tmp`), so it fits beside
//! a target name of any legal length, and names its process: a process
//! killed while writing (`kill -9`) leaves its temporary behind, and the next
//! save into that folder removes it once its process is gone and it has not
//! changed for a minute (never the file of a writer that is still alive).
//! Before anything is written the target is checked:
//! - a symlink is written **through**: its final target is replaced and the
//!   link stays a link (a dangling link is refused, nothing is created at
//!   its target);
//! - a directory, FIFO, socket or device is refused (renaming over it would
//!   silently replace it by a regular file);
//! - a read-only file (no write permission bit, or not writable by this
//!   user) is refused, also when running as root, who could write it anyway;
//! - an existing file's permission bits (and, where allowed, owner) are
//!   copied to the new file.
//!
//! # Files handed in as bytes ([`provide`])
//! A process without a file system (a browser page) is handed the files the
//! user drops or picks as bytes; it puts them here under their names, and
//! bv's readers ([`read_capped`], the MERL reader, `.brdf` files) find them
//! here before they look on a disk. Nothing is here unless a caller put it
//! there, so on the desktop the readers behave as above.
//!
//! Errors are [`BvError::File`]: the path as given once, then one reason that
//! includes the system's message once.

use crate::{BvError, Result};
use std::fs::{File, Metadata};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

/// Largest scene file read (1 MiB; bv writes them in a few KiB).
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// Largest environment map file read (1 GiB: a 16k × 8k float EXR).
pub const MAX_ENV_MAP_BYTES: u64 = 1 << 30;

/// Most symlinks followed when resolving a write target (as Linux's `ELOOP`).
const MAX_LINK_HOPS: usize = 40;

fn file_err(path: &Path, reason: impl Into<String>) -> BvError {
    BvError::File {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

/// What kind of thing `t` is, for messages: "a directory", "a FIFO (named
/// pipe)", "a character device", ….
pub fn kind_name(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// A byte count for messages: `104857600 bytes (100.0 MiB)`.
pub fn human_bytes(n: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if n >= size {
            let x = n as f64 / size as f64;
            let shown = if n.is_multiple_of(size) {
                format!("{}", n / size)
            } else {
                format!("{x:.1}")
            };
            return format!("{n} bytes ({shown} {unit})");
        }
    }
    format!("{n} bytes")
}

/// The cap as it is stated in messages: `1 MiB`.
fn cap_text(cap: u64) -> String {
    match human_bytes(cap).split_once('(') {
        Some((_, rest)) => rest.trim_end_matches(')').to_string(),
        None => human_bytes(cap),
    }
}

/// Why `stat` of `path` failed, saying so when `path` is a dangling symlink.
fn stat_reason(path: &Path, e: &io::Error) -> String {
    if e.kind() == io::ErrorKind::NotFound
        && let Ok(m) = std::fs::symlink_metadata(path)
        && m.file_type().is_symlink()
    {
        let to = std::fs::read_link(path)
            .map(|t| t.display().to_string())
            .unwrap_or_else(|_| "?".into());
        return format!("a symbolic link to {to}, which does not exist");
    }
    e.to_string()
}

/// Opens `path` for reading, which must be (or link to) a regular file of at
/// most `cap` bytes; `what` names the expected content in messages ("a scene
/// file"). Returns the file and its length. Never blocks on a FIFO.
pub fn open_regular(path: &Path, cap: u64, what: &str) -> Result<(File, u64)> {
    if path.as_os_str().is_empty() {
        return Err(BvError::Invalid(format!(
            "an empty path where {what} was expected"
        )));
    }
    let before = std::fs::metadata(path).map_err(|e| file_err(path, stat_reason(path, &e)))?;
    check_regular(path, &before, cap, what)?;
    let file = open_nonblocking(path).map_err(|e| file_err(path, e.to_string()))?;
    let after = file.metadata().map_err(|e| file_err(path, e.to_string()))?;
    check_regular(path, &after, cap, what)?;
    if !same_file(&before, &after) {
        return Err(file_err(
            path,
            "the file was replaced while bv opened it; try again",
        ));
    }
    Ok((file, after.len()))
}

/// Reads all of `path` (see [`open_regular`]) into memory, holding at most
/// `cap` bytes even if the file grows meanwhile.
pub fn read_capped(path: &Path, cap: u64, what: &str) -> Result<Vec<u8>> {
    if let Some(p) = provided(path) {
        if p.bytes.len() as u64 > cap {
            return Err(too_big(path, Some(p.bytes.len() as u64), cap, what));
        }
        return Ok(p.bytes.to_vec());
    }
    let (file, len) = open_regular(path, cap, what)?;
    let mut bytes = Vec::new();
    // `len` is at most `cap`; reserve what the file says, not more.
    bytes
        .try_reserve_exact(len as usize)
        .map_err(|e| file_err(path, format!("cannot allocate {}: {e}", human_bytes(len))))?;
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| file_err(path, e.to_string()))?;
    if bytes.len() as u64 > cap {
        return Err(too_big(path, None, cap, what));
    }
    Ok(bytes)
}

fn too_big(path: &Path, len: Option<u64>, cap: u64, what: &str) -> BvError {
    let size = match len {
        Some(n) => format!("{} is", human_bytes(n)),
        None => "grew while being read and is".to_string(),
    };
    file_err(
        path,
        format!("{size} over the {} limit for {what}", cap_text(cap)),
    )
}

fn check_regular(path: &Path, m: &Metadata, cap: u64, what: &str) -> Result<()> {
    let t = m.file_type();
    if !t.is_file() {
        let hint = if t.is_dir() {
            format!("; give the path of {what} inside it")
        } else {
            String::new()
        };
        return Err(file_err(
            path,
            format!("{}, not a regular file{hint}", kind_name(&t)),
        ));
    }
    if m.len() > cap {
        return Err(too_big(path, Some(m.len()), cap, what));
    }
    Ok(())
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    // O_NONBLOCK: opening a FIFO for reading returns at once instead of
    // waiting for a writer (regular files ignore the flag for reads).
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

#[cfg(unix)]
fn same_file(a: &Metadata, b: &Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(_: &Metadata, _: &Metadata) -> bool {
    true
}

/// Creates the missing folders above `path` (for figures written into a new
/// folder).
pub fn create_parent_dirs(path: &Path) -> Result<()> {
    if let Some(dir) = path.parent()
        && !dir.as_os_str().is_empty()
    {
        std::fs::create_dir_all(dir).map_err(|e| {
            file_err(
                dir,
                if e.kind() == io::ErrorKind::AlreadyExists {
                    "exists and is not a directory".to_string()
                } else {
                    format!("cannot create the folder: {e}")
                },
            )
        })?;
    }
    Ok(())
}

/// The file a write to `path` replaces: `path` itself, or the final target
/// of the symlink chain starting at `path` (see the module docs).
fn resolve_target(path: &Path) -> Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINK_HOPS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p).map_err(|e| file_err(path, e.to_string()))?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            Ok(_) => return Ok(p),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                if p != path {
                    return Err(file_err(
                        path,
                        format!(
                            "a symbolic link to {}, which does not exist; bv writes through \
                             symbolic links but does not create their targets",
                            p.display()
                        ),
                    ));
                }
                return Ok(p);
            }
            Err(e) if e.kind() == io::ErrorKind::NotADirectory => {
                let parent = p.parent().map(|d| d.display().to_string());
                return Err(file_err(
                    path,
                    format!(
                        "a part of the folder {} is a file, not a directory",
                        parent.unwrap_or_default()
                    ),
                ));
            }
            Err(e) => return Err(file_err(path, e.to_string())),
        }
    }
    Err(file_err(
        path,
        format!("more than {MAX_LINK_HOPS} levels of symbolic links"),
    ))
}

/// Whether this process may write `path` (the permission bits alone say
/// nothing for root; `access(2)` says nothing for root either, so both the
/// bits and `access` are asked).
fn is_read_only(path: &Path, m: &Metadata) -> bool {
    if m.permissions().readonly() {
        return true;
    }
    // Only `access(2)` reads the path; elsewhere the bits are all there is.
    #[cfg(not(unix))]
    let _ = path;
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        if let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) {
            // SAFETY: `c` is a valid NUL-terminated string for the call.
            return unsafe { libc::access(c.as_ptr(), libc::W_OK) } != 0;
        }
    }
    false
}

#[cfg(unix)]
fn mode_text(m: &Metadata) -> String {
    use std::os::unix::fs::PermissionsExt;
    format!(" (mode {:04o})", m.permissions().mode() & 0o7777)
}

#[cfg(not(unix))]
fn mode_text(_: &Metadata) -> String {
    String::new()
}

/// Writes `path` atomically with what `write` produces (see the module docs
/// for what is refused and how symlinks and permissions are treated). The
/// parent folder must exist ([`create_parent_dirs`] makes it).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<()> {
    if path.as_os_str().is_empty() {
        return Err(BvError::Invalid("an empty output path".to_string()));
    }
    if path.as_os_str().to_string_lossy().ends_with(['/', '\\']) {
        return Err(file_err(
            path,
            "ends with a path separator, so it names a folder; give a file name",
        ));
    }
    let target = resolve_target(path)?;
    let existing = match std::fs::metadata(&target) {
        Ok(m) => Some(m),
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(file_err(path, e.to_string())),
    };
    if let Some(m) = &existing {
        let t = m.file_type();
        if t.is_dir() {
            return Err(file_err(
                path,
                "a directory, not a file; give a file name inside it",
            ));
        }
        if !t.is_file() {
            return Err(file_err(
                path,
                format!(
                    "{}, not a regular file; bv replaces only regular files",
                    kind_name(&t)
                ),
            ));
        }
        if is_read_only(&target, m) {
            let what = if m.permissions().readonly() {
                "read-only"
            } else {
                "not writable by this user"
            };
            return Err(file_err(
                path,
                format!(
                    "the file is {what}{}; bv does not overwrite it (make it writable \
                     or choose another name)",
                    mode_text(m)
                ),
            ));
        }
    }
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(m) => {
            return Err(file_err(
                path,
                format!(
                    "its folder {} is {}, not a directory",
                    dir.display(),
                    kind_name(&m.file_type())
                ),
            ));
        }
        Err(e) => {
            return Err(file_err(
                path,
                format!("its folder {} cannot be used: {e}", dir.display()),
            ));
        }
    }
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| file_err(path, "not a file name"))?;
    let (tmp, file) = create_temp(&dir, &name, existing.as_ref()).map_err(|e| {
        file_err(
            path,
            format!("cannot create a file in {}: {e}", dir.display()),
        )
    })?;
    let result = (|| {
        let mut w = io::BufWriter::with_capacity(1 << 16, file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        if let Some(m) = &existing {
            copy_metadata(&file, m);
        }
        file.sync_all()?;
        // Closed before the rename (a `File` on wasm32 has nothing to close).
        #[cfg_attr(target_arch = "wasm32", allow(clippy::drop_non_drop))]
        drop(file);
        std::fs::rename(&tmp, &target)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(file_err(path, format!("cannot write: {e}")));
    }
    // Make the rename itself durable where the platform allows.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The start and end of bv's temporary names (`.bv-PID-XXXXXXXX.tmp`).
const TEMP_PREFIX: &str = ".bv-";
const TEMP_SUFFIX: &str = ".tmp";

/// How long a temporary must have been left untouched, besides its process
/// being gone, before another save removes it. bv's writers hand over bytes
/// they have already computed, so a live writer's temporary is always
/// fresher than this, even one of a process this one cannot see (another
/// container sharing the folder, whose process ids mean nothing here).
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(60);

/// A temporary this old is removed even when a process with its number is
/// alive (the number was reused by a process that has nothing to do with it).
const ABANDONED_AFTER: std::time::Duration = std::time::Duration::from_secs(24 * 60 * 60);

/// The name of a temporary of this process: short, so that it fits beside
/// any legal target name (a name of 255 bytes, the longest most file systems
/// allow, cannot have anything added to it), and carrying the process id,
/// so that a later save can tell a killed writer's leftover from a live
/// writer's file.
fn temp_name(pid: u32, nonce: u32) -> String {
    format!("{TEMP_PREFIX}{pid}-{nonce:08x}{TEMP_SUFFIX}")
}

/// The process id in `name`, if it is a temporary of bv's: the present
/// pattern, or the one older versions used (`.TARGET.PID.N.tmp`) for the
/// target `target`.
fn temp_owner(name: &str, target: &str) -> Option<u32> {
    let core = name.strip_suffix(TEMP_SUFFIX)?;
    if let Some(rest) = core.strip_prefix(TEMP_PREFIX)
        && let Some((pid, nonce)) = rest.split_once('-')
        && nonce.len() == 8
        && nonce.bytes().all(|b| b.is_ascii_hexdigit())
        && !pid.is_empty()
        && pid.bytes().all(|b| b.is_ascii_digit())
    {
        return pid.parse().ok();
    }
    // Older versions: `.{target}.{pid}.{n}.tmp`, only for the file being
    // saved (another name of that shape may be someone else's).
    let rest = core
        .strip_prefix('.')?
        .strip_prefix(target)?
        .strip_prefix('.')?;
    let (pid, n) = rest.split_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !(digits(pid) && digits(n)) {
        return None;
    }
    pid.parse().ok()
}

/// Whether a process `pid` may be running (true when that cannot be told).
fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return false;
        };
        if pid <= 0 {
            return false;
        }
        // SAFETY: signal 0 sends nothing; it only asks whether `pid` exists.
        if unsafe { libc::kill(pid, 0) } == 0 {
            return true;
        }
        // EPERM: it exists but belongs to another user.
        io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        true
    }
}

/// Removes the temporaries of bv's pattern in `dir` that a killed writer
/// left (its process is gone and the file has not been touched for
/// [`STALE_AFTER`], or it is older than [`ABANDONED_AFTER`]); `target` is
/// the name being saved (for the older pattern). Never a live writer's file:
/// best effort, errors are ignored. Returns how many were removed.
fn remove_stale_temps(dir: &Path, target: &str) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let now = std::time::SystemTime::now();
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(|n| temp_owner(n, target)) else {
            continue;
        };
        // `DirEntry::metadata` does not follow symlinks: only regular files.
        let Ok(m) = entry.metadata() else { continue };
        if !m.file_type().is_file() {
            continue;
        }
        let Some(age) = m.modified().ok().and_then(|t| now.duration_since(t).ok()) else {
            continue;
        };
        let stale = (age >= STALE_AFTER && !process_alive(pid)) || age >= ABANDONED_AFTER;
        if stale && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// A new temporary file beside the target, never over an existing file
/// (named by [`temp_name`]); stale temporaries of bv's in the folder are
/// removed first ([`remove_stale_temps`]), which also frees their space
/// for this write.
fn create_temp(dir: &Path, name: &str, existing: Option<&Metadata>) -> io::Result<(PathBuf, File)> {
    use std::sync::atomic::{AtomicU32, Ordering};
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    remove_stale_temps(dir, name);
    let pid = std::process::id();
    // Different in every call and every process start; `create_new` makes
    // a clash harmless (the next nonce is tried).
    let seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let mut last = io::Error::other("no temporary name was free");
    for _ in 0..100 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let nonce = seed ^ n.wrapping_mul(0x9e37_79b9);
        let tmp = dir.join(temp_name(pid, nonce));
        let mut opts = std::fs::OpenOptions::new();
        opts.write(true).create_new(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            // A new file gets the usual 0666 less the umask; a replacement
            // starts private and gets the old file's mode once written.
            opts.mode(if existing.is_some() { 0o600 } else { 0o666 });
        }
        #[cfg(not(unix))]
        let _ = existing;
        match opts.open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = e,
            Err(e) => return Err(e),
        }
    }
    Err(last)
}

/// Gives the new file the old one's permission bits and, where allowed, its
/// owner (best effort: a failure leaves the new file with the defaults).
fn copy_metadata(file: &File, old: &Metadata) {
    let _ = file.set_permissions(old.permissions());
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let Ok(now) = file.metadata()
            && (now.uid() != old.uid() || now.gid() != old.gid())
        {
            let _ = std::os::unix::fs::fchown(file, Some(old.uid()), Some(old.gid()));
            // A change of owner clears set-id bits; set the mode again.
            let _ = file.set_permissions(old.permissions());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("bv-fsio-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
        write_atomic(path, |w| w.write_all(bytes))
    }

    #[test]
    fn provided_files_are_read_by_name_before_the_disk() {
        // A name that no disk has, and one that shadows a real file.
        let d = temp_dir("provided");
        let real = d.join("real.txt");
        std::fs::write(&real, b"on disk").unwrap();
        let virtual_name = Path::new("bv-test-provided/only-in-memory.txt");
        assert!(provided(virtual_name).is_none());
        assert!(read_capped(virtual_name, 100, "a test file").is_err());
        provide(virtual_name, b"first".to_vec());
        let g1 = provided(virtual_name).unwrap().generation;
        assert_eq!(
            read_capped(virtual_name, 100, "a test file").unwrap(),
            b"first"
        );
        provide(virtual_name, b"second".to_vec());
        let p = provided(virtual_name).unwrap();
        assert!(
            p.generation > g1
                && p.stamp()
                    != Provided {
                        generation: g1,
                        ..p.clone()
                    }
                    .stamp()
        );
        assert_eq!(
            read_capped(virtual_name, 100, "a test file").unwrap(),
            b"second"
        );
        let e = read_capped(virtual_name, 3, "a test file")
            .unwrap_err()
            .to_string();
        assert!(e.contains("over the 3 bytes limit"), "{e}");
        provide(&real, b"in memory".to_vec());
        assert_eq!(
            read_capped(&real, 100, "a test file").unwrap(),
            b"in memory"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn reads_regular_files_and_refuses_the_rest() {
        let d = temp_dir("read");
        let f = d.join("a.txt");
        std::fs::write(&f, b"hello").unwrap();
        assert_eq!(read_capped(&f, 5, "a test file").unwrap(), b"hello");
        let e = read_capped(&f, 4, "a test file").unwrap_err().to_string();
        assert!(
            e.contains("5 bytes is over the 4 bytes limit for a test file"),
            "{e}"
        );
        let e = read_capped(&d, 100, "a test file").unwrap_err().to_string();
        assert!(e.contains("a directory, not a regular file"), "{e}");
        let e = read_capped(Path::new("/dev/zero"), 100, "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a character device, not a regular file"), "{e}");
        let e = read_capped(&d.join("missing"), 100, "x")
            .unwrap_err()
            .to_string();
        assert_eq!(e.matches("No such file").count(), 1, "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn writes_through_symlinks_and_keeps_modes() {
        use std::os::unix::fs::PermissionsExt;
        let d = temp_dir("write");
        let real = d.join("real.txt");
        std::fs::write(&real, b"old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        write_bytes(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        let mode = std::fs::metadata(&real).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o640);

        let ro = d.join("ro.txt");
        std::fs::write(&ro, b"keep").unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o444)).unwrap();
        let e = write_bytes(&ro, b"lost").unwrap_err().to_string();
        assert!(e.contains("read-only (mode 0444)"), "{e}");
        assert_eq!(std::fs::read(&ro).unwrap(), b"keep");

        let dangling = d.join("dangling.txt");
        std::os::unix::fs::symlink("nowhere/x.txt", &dangling).unwrap();
        let e = write_bytes(&dangling, b"x").unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");

        let e = write_bytes(&d, b"x").unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = write_bytes(Path::new("/dev/null"), b"x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a character device, not a regular file"), "{e}");
        // Only the files made above: no temporary is left behind.
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 4);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failed_write_keeps_the_old_file() {
        let d = temp_dir("fail");
        let f = d.join("f.txt");
        std::fs::write(&f, b"old").unwrap();
        let e = write_atomic(&f, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk on fire"))
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("disk on fire"), "{e}");
        assert_eq!(std::fs::read(&f).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_target_name_of_the_longest_legal_length_is_written() {
        // 255 bytes is NAME_MAX on Linux and macOS: the temporary's name
        // must not grow with the target's.
        let d = temp_dir("long-name");
        let f = d.join("n".repeat(251) + ".png");
        assert_eq!(f.file_name().unwrap().len(), 255);
        write_bytes(&f, b"first").unwrap();
        write_bytes(&f, b"second").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"second");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn temporary_names_are_recognised() {
        let name = temp_name(1234, 0xdead_beef);
        assert_eq!(name, ".bv-1234-deadbeef.tmp");
        assert_eq!(temp_owner(&name, "x.png"), Some(1234));
        assert_eq!(temp_owner(".x.png.77.3.tmp", "x.png"), Some(77));
        // The older pattern only for the file being saved; nothing else.
        for other in [
            ".y.png.77.3.tmp",
            ".bv-1234-deadbee.tmp",
            ".bv-notes.tmp",
            ".bv--deadbeef.tmp",
            ".bv-12a-deadbeef.tmp",
            "bv-1234-deadbeef.tmp",
            ".bv-1234-deadbeef.tmp.png",
            ".x.png.77.tmp",
        ] {
            assert_eq!(temp_owner(other, "x.png"), None, "{other}");
        }
    }

    /// Makes `path` (a file) look `secs` seconds old.
    fn age(path: &Path, secs: u64) {
        let t = std::time::SystemTime::now() - std::time::Duration::from_secs(secs);
        File::options()
            .write(true)
            .open(path)
            .unwrap()
            .set_modified(t)
            .unwrap();
    }

    #[test]
    fn a_save_removes_stale_temporaries_and_keeps_live_ones() {
        let d = temp_dir("stale");
        // No process has this number (above every kernel's pid_max).
        let gone = i32::MAX as u32;
        let me = std::process::id();
        let stale = d.join(temp_name(gone, 1));
        let stale_old_pattern = d.join(format!(".x.png.{gone}.0.tmp"));
        let fresh_of_gone = d.join(temp_name(gone, 2));
        let old_but_alive = d.join(temp_name(me, 3));
        let abandoned = d.join(temp_name(me, 4));
        let old_pattern_other = d.join(format!(".y.png.{gone}.0.tmp"));
        let users_file = d.join(".bv-notes.tmp");
        for p in [
            &stale,
            &stale_old_pattern,
            &fresh_of_gone,
            &old_but_alive,
            &abandoned,
            &old_pattern_other,
            &users_file,
        ] {
            std::fs::write(p, b"left over").unwrap();
        }
        for p in [
            &stale,
            &stale_old_pattern,
            &old_but_alive,
            &old_pattern_other,
            &users_file,
        ] {
            age(p, 120);
        }
        age(&abandoned, 2 * 24 * 60 * 60);
        // A folder with the pattern's name is not a temporary.
        let folder = d.join(temp_name(gone, 5));
        std::fs::create_dir(&folder).unwrap();

        write_bytes(&d.join("x.png"), b"new").unwrap();
        for (p, kept) in [
            (&stale, false),
            (&stale_old_pattern, false),
            (&abandoned, false),
            // Still being written, as far as anyone can tell.
            (&fresh_of_gone, true),
            // Its writer (this process) is alive.
            (&old_but_alive, true),
            (&old_pattern_other, true),
            (&users_file, true),
            (&folder, true),
        ] {
            assert_eq!(p.exists(), kept, "{}", p.display());
        }
        assert_eq!(std::fs::read(d.join("x.png")).unwrap(), b"new");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn sizes_read_well() {
        assert_eq!(human_bytes(12), "12 bytes");
        assert_eq!(human_bytes(1 << 20), "1048576 bytes (1 MiB)");
        assert_eq!(cap_text(1 << 20), "1 MiB");
        assert_eq!(human_bytes(100_000_000), "100000000 bytes (95.4 MiB)");
    }
}

/// Most files kept by [`provide`] (the oldest goes first); a full MERL table
/// is 34 MB.
pub const MAX_PROVIDED: usize = 8;

/// A file handed in with [`provide`].
#[derive(Debug, Clone)]
pub struct Provided {
    /// Its contents.
    pub bytes: std::sync::Arc<[u8]>,
    /// Counts the calls of [`provide`] in the process: a file handed in again
    /// under the same name has a larger one (caches keyed by it read it
    /// again).
    pub generation: u64,
}

impl Provided {
    /// A stand-in for the modification time, for caches keyed by one
    /// (different for every generation; no clock is read).
    pub fn stamp(&self) -> std::time::SystemTime {
        std::time::UNIX_EPOCH + std::time::Duration::from_nanos(self.generation)
    }
}

type ProvidedFiles = (u64, Vec<(PathBuf, Provided)>);

fn provided_files() -> std::sync::MutexGuard<'static, ProvidedFiles> {
    static FILES: std::sync::Mutex<ProvidedFiles> = std::sync::Mutex::new((0, Vec::new()));
    // The list is whole between statements: a panic elsewhere leaves it usable.
    FILES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Hands bv the contents of the file `path` (see the module's notes): from
/// now on bv's readers find it here, before any disk. Handing in the same
/// path again replaces its contents. At most [`MAX_PROVIDED`] files are kept.
pub fn provide(path: impl Into<PathBuf>, bytes: impl Into<std::sync::Arc<[u8]>>) {
    let path = path.into();
    let mut g = provided_files();
    g.0 += 1;
    let generation = g.0;
    g.1.retain(|(p, _)| *p != path);
    if g.1.len() >= MAX_PROVIDED {
        g.1.remove(0);
    }
    g.1.push((
        path,
        Provided {
            bytes: bytes.into(),
            generation,
        },
    ));
}

/// The file handed in under `path` with [`provide`], if any.
pub fn provided(path: &Path) -> Option<Provided> {
    provided_files()
        .1
        .iter()
        .find(|(p, _)| p == path)
        .map(|(_, f)| f.clone())
}
