//! The output folder of a command, checked before anything is computed, and holding only the
//! files of its last run.
//!
//! [`OutputDir::prepare`], before the computation:
//! - the folder must be a folder (not a file) and not a symlink (host-sim never follows a
//!   symlink it did not create, and it creates none; a symlink higher up the path is the
//!   user's choice of disk and is followed as usual); it is created if it does not exist;
//! - it must be writable: the new manifest is written there first;
//! - **reuse:** the folder keeps a manifest, [`MANIFEST`], of the files its last run wrote.
//!   The files it lists are removed (a symlink among them is unlinked, not followed), and so are
//!   temporary files that a killed run left ([`super::atomic::TMP_PREFIX`]). Files host-sim did
//!   not write are never touched. A folder that is not empty and has no manifest is refused
//!   with a message listing what is in it: host-sim cannot tell its old outputs from the user's
//!   files there, and will not mix them with new ones. So after a run the folder holds exactly
//!   that run's files (and the user's own, untouched).
//!
//! Then every file is claimed ([`OutputDir::claim`]: added to the manifest before it is
//! written, so that a run killed half-way still has its files listed) and written whole or not
//! at all ([`super::atomic`]).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};

use super::atomic::{self, TMP_PREFIX};

/// The manifest's file name.
pub const MANIFEST: &str = "host-sim-manifest.txt";
const MANIFEST_HEADER: &str = "# host-sim: the files the last run wrote into this folder; \
     the next run removes them first (do not edit)";

/// A checked output folder (see the module doc).
#[derive(Debug)]
pub struct OutputDir {
    path: PathBuf,
    files: Mutex<Vec<String>>,
}

impl OutputDir {
    /// Checks `path`, creates it if needed, removes the files of its previous run, and writes
    /// an empty manifest (see the module doc). Every error names the folder and says what to
    /// do.
    pub fn prepare(path: &Path) -> Result<OutputDir> {
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
        let dir = OutputDir {
            path: path.to_path_buf(),
            files: Mutex::new(Vec::new()),
        };
        let previous = dir.previous_files()?;
        for name in &previous {
            dir.remove_entry(name)?;
        }
        for entry in fs::read_dir(path).with_context(|| format!("cannot list {shown}"))? {
            let name = entry
                .with_context(|| format!("cannot list {shown}"))?
                .file_name();
            let name = name.to_string_lossy();
            if name.starts_with(TMP_PREFIX) {
                dir.remove_entry(&name)?;
            }
        }
        dir.write_manifest(&[])
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

    /// The names in the previous run's manifest; refuses a non-empty folder without one.
    fn previous_files(&self) -> Result<Vec<String>> {
        let manifest = self.path.join(MANIFEST);
        let shown = self.path.display();
        match fs::symlink_metadata(&manifest) {
            Ok(m) if !m.is_file() => bail!(
                "{} is not a regular file (a symlink?): host-sim will not read or replace it; \
                 remove it",
                manifest.display()
            ),
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                let mut others: Vec<String> = fs::read_dir(&self.path)
                    .with_context(|| format!("cannot list {shown}"))?
                    .filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| !n.starts_with(TMP_PREFIX))
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
            if !plain_name(line) || line == MANIFEST {
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
