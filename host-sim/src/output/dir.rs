//! The output folder of a command, checked before anything is computed, and holding only the
//! files of its last run.
//!
//! [`OutputDir::prepare`], before the computation:
//! - the folder must be a folder (not a file) and not a symlink (host-sim never follows a
//!   symlink it did not create, and it creates none; a symlink higher up the path is the
//!   user's choice of disk and is followed as usual); it is created if it does not exist;
//! - it must be writable: the new manifest is written there first;
//! - **one run at a time** (**Choice 122**): the run holds an exclusive advisory lock
//!   (`flock`) on the folder's [`LOCK`] file for its whole life (until the [`OutputDir`] is
//!   dropped, or the process ends, however it ends); the file names the process that holds
//!   it. A second run into the same folder is refused at once: "output folder … is in use by
//!   process N on HOST". The lock file stays (removing it would let two runs lock two
//!   different files); it is neither an output nor in the manifest;
//! - **reuse:** the folder keeps a manifest, [`MANIFEST`], of the files its last run wrote.
//!   The files it lists are removed (a symlink among them is unlinked, not followed), with the
//!   `.partial.csv` of each CSV listed (what a run that ended early kept of it,
//!   [`super::csv::partial_name`]), and so are the temporary files
//!   ([`super::atomic::TMP_PREFIX`]`{pid}-…`) of processes that no longer exist (**Choice
//!   123**: under the lock no live host-sim writes there, and the name's pid is asked of the
//!   system; a pid alive, whoever it is now, keeps its file). Files host-sim did not write
//!   are never touched. A folder that is not empty and has no manifest is refused
//!   with a message listing what is in it: host-sim cannot tell its old outputs from the user's
//!   files there, and will not mix them with new ones. So after a run the folder holds exactly
//!   that run's files (and the user's own, untouched).
//!
//! Then every file is claimed ([`OutputDir::claim`]: added to the manifest before it is
//! written, so that a run killed half-way still has its files listed) and written whole or not
//! at all ([`super::atomic`]).

use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};

use super::atomic::{self, TMP_PREFIX};
use super::csv::partial_name;

/// The manifest's file name.
pub const MANIFEST: &str = "host-sim-manifest.txt";
const MANIFEST_HEADER: &str = "# host-sim: the files the last run wrote into this folder; \
     the next run removes them first (do not edit)";

/// The lock file's name: locked by the run using the folder, and naming its process.
pub const LOCK: &str = "host-sim.lock";

/// A checked output folder (see the module doc), locked for as long as it lives.
#[derive(Debug)]
pub struct OutputDir {
    path: PathBuf,
    files: Mutex<Vec<String>>,
    _lock: File,
}

impl OutputDir {
    /// Checks `path`, creates it if needed, removes the files of its previous run, and writes
    /// an empty manifest (see the module doc). Every error names the folder and says what to
    /// do.
    pub fn prepare(path: &Path) -> Result<OutputDir> {
        Self::open(path, false)
    }

    /// [`OutputDir::prepare`] for a run that resumes the folder's previous run (a campaign
    /// shard, **Choice 135**): the same checks and lock, but the files of the previous run are
    /// kept (and stay in the manifest); only stale temporary files are removed.
    pub fn resume(path: &Path) -> Result<OutputDir> {
        Self::open(path, true)
    }

    fn open(path: &Path, keep: bool) -> Result<OutputDir> {
        let shown = path.display();
        match fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => bail!(
                "output folder {shown} is a symlink: host-sim does not write through a symlink \
                 it did not create; give the folder it points to, or another --out"
            ),
            Ok(m) if !m.is_dir() => {
                bail!("output folder {shown} exists and is not a folder; give another --out")
            }
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => fs::create_dir_all(path)
                .with_context(|| format!("cannot create the output folder {shown}"))?,
            Err(e) => bail!("cannot use the output folder {shown}: {e}"),
        }
        // A folder of someone else's files is refused before the lock file is made there.
        previous_files(path)?;
        let dir = OutputDir {
            path: path.to_path_buf(),
            files: Mutex::new(Vec::new()),
            _lock: lock(path)?,
        };
        let previous = previous_files(path)?;
        if keep {
            *dir.files.lock().unwrap_or_else(|e| e.into_inner()) = previous.clone();
        }
        for name in previous.iter().filter(|_| !keep) {
            dir.remove_entry(name)?;
            // What a run that ended before finishing this CSV kept of it (Choice 126).
            if name.ends_with(".csv") {
                dir.remove_entry(&partial_name(name))?;
            }
        }
        for entry in fs::read_dir(path).with_context(|| format!("cannot list {shown}"))? {
            let name = entry
                .with_context(|| format!("cannot list {shown}"))?
                .file_name();
            let name = name.to_string_lossy();
            if stale_tmp(&name) {
                dir.remove_entry(&name)?;
            }
        }
        dir.write_manifest(&dir.files())
            .with_context(|| format!("output folder {shown} is not writable"))?;
        Ok(dir)
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path of `name` in the folder, recorded in the manifest first. `name` is a plain
    /// file name (no folder part).
    pub fn claim(&self, name: &str) -> Result<PathBuf> {
        if !plain_name(name) {
            bail!("{name:?} is not a plain file name");
        }
        let mut files = self.files.lock().unwrap_or_else(|e| e.into_inner());
        if !files.iter().any(|f| f == name) {
            files.push(name.to_string());
            self.write_manifest(&files)
                .with_context(|| format!("cannot update {}", self.path.join(MANIFEST).display()))?;
        }
        Ok(self.path.join(name))
    }

    /// The files claimed so far, in order.
    pub fn files(&self) -> Vec<String> {
        self.files.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Removes `name` if it is a file or a symlink (the link, not what it points to).
    fn remove_entry(&self, name: &str) -> Result<()> {
        let p = self.path.join(name);
        match fs::symlink_metadata(&p) {
            Ok(m) if m.is_dir() => bail!(
                "{} was written by host-sim's last run but is now a folder; remove it",
                p.display()
            ),
            Ok(_) => fs::remove_file(&p)
                .with_context(|| format!("cannot remove the old output {}", p.display())),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
            Err(e) => Err(e).with_context(|| format!("cannot check {}", p.display())),
        }
    }

    /// Writes the manifest: the names sorted, so that it does not depend on which of the
    /// parallel runs claimed its files first.
    fn write_manifest(&self, files: &[String]) -> io::Result<PathBuf> {
        let mut text = String::from(MANIFEST_HEADER);
        text.push('\n');
        let mut sorted: Vec<&String> = files.iter().collect();
        sorted.sort();
        for f in sorted {
            text.push_str(f);
            text.push('\n');
        }
        atomic::write(&self.path.join(MANIFEST), text.as_bytes())
    }
}

/// A file name without a folder part, not `.` or `..`.
fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\'])
        && !name.chars().any(char::is_control)
}

/// The names in the previous run's manifest; refuses a non-empty folder without one.
fn previous_files(path: &Path) -> Result<Vec<String>> {
    let manifest = path.join(MANIFEST);
    let shown = path.display();
    match fs::symlink_metadata(&manifest) {
        Ok(m) if !m.is_file() => bail!(
            "{} is not a regular file (a symlink?): host-sim will not read or replace it; \
             remove it",
            manifest.display()
        ),
        Ok(_) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            let mut others: Vec<String> = fs::read_dir(path)
                .with_context(|| format!("cannot list {shown}"))?
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| !n.starts_with(TMP_PREFIX) && n != LOCK)
                .collect();
            if others.is_empty() {
                return Ok(Vec::new());
            }
            others.sort();
            let n = others.len();
            others.truncate(5);
            bail!(
                "output folder {shown} is not empty and has no {MANIFEST}, so host-sim did \
                 not write it and cannot tell old outputs from other files ({n} entries: \
                 {}{}); empty it, or give another --out",
                others.join(", "),
                if n > 5 { ", …" } else { "" }
            );
        }
        Err(e) => bail!("cannot read {}: {e}", manifest.display()),
    }
    let text = fs::read_to_string(&manifest)
        .with_context(|| format!("cannot read {}", manifest.display()))?;
    let mut names = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !plain_name(line) || line == MANIFEST || line == LOCK {
            bail!(
                "{} lists {line:?}, which host-sim never writes (the manifest was edited?); \
                 remove the manifest and empty the folder",
                manifest.display()
            );
        }
        names.push(line.to_string());
    }
    Ok(names)
}

/// Takes the folder's lock (see the module doc): the [`LOCK`] file, created if needed (never
/// through a symlink), locked exclusively, and its content replaced by this process's id and
/// host. Another holder: refused, naming it.
fn lock(path: &Path) -> Result<File> {
    let lock_path = path.join(LOCK);
    let shown = lock_path.display();
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&lock_path)
        .map_err(|e| match e.raw_os_error() {
            Some(libc::ELOOP) => anyhow::anyhow!(
                "{shown} is a symlink: host-sim does not follow a symlink it did not create; \
                 remove it"
            ),
            _ => anyhow::Error::new(e).context(format!(
                "output folder {} is not writable (its lock file {shown})",
                path.display()
            )),
        })?;
    match file.try_lock() {
        Ok(()) => {}
        Err(fs::TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            let holder = match holder.split_whitespace().collect::<Vec<_>>()[..] {
                [pid, host, ..] => format!("process {pid} on {host}"),
                [pid] => format!("process {pid}"),
                [] => "another process".to_string(),
            };
            bail!(
                "output folder {} is in use by {holder} (another host-sim run writes there); \
                 wait for it to end, or give another --out",
                path.display()
            );
        }
        Err(fs::TryLockError::Error(e)) => {
            return Err(e).with_context(|| format!("cannot lock {shown}"));
        }
    }
    let id = format!("{} {}\n", std::process::id(), host_name());
    file.set_len(0)
        .and_then(|()| file.write_all(id.as_bytes()))
        .with_context(|| format!("output folder {} is not writable", path.display()))?;
    Ok(file)
}

/// This machine's name (for the lock file), or `?`.
fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname writes at most that much.
    let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } == 0;
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    match std::str::from_utf8(&buf[..end]) {
        Ok(h) if ok && !h.is_empty() && !h.contains(char::is_whitespace) => h.to_string(),
        _ => "?".to_string(),
    }
}

/// A temporary file ([`TMP_PREFIX`]`{pid}-{n}.{name}`) whose writing process no longer exists.
fn stale_tmp(name: &str) -> bool {
    let Some(rest) = name.strip_prefix(TMP_PREFIX) else {
        return false;
    };
    let Some(pid) = rest
        .split('-')
        .next()
        .and_then(|p| p.parse::<libc::pid_t>().ok())
    else {
        return false;
    };
    if pid <= 0 {
        return false;
    }
    // SAFETY: signal 0 sends nothing; it only asks whether the process exists.
    let alive = unsafe { libc::kill(pid, 0) } == 0
        || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH);
    !alive
}
