//! Files written whole or not at all: each output goes to a temporary name in its own folder
//! and is renamed onto its final name only once it is complete (flushed and synced). A reader
//! never sees a half-written file under a final name, an interrupted or failed write leaves
//! no final file behind, and a symlink at the final name is replaced, never followed (rename
//! replaces the link itself). The temporary file is created with `O_EXCL` (`create_new`), so
//! it is never an existing file or a symlink either.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files start with this (`.host-sim-tmp.{pid}-{n}.{name}`: the final name last, so
/// that writers which pick the format by extension, like the PNG encoder, see it); a folder's
/// stale ones (from a process that was killed) are removed by
/// [`super::dir::OutputDir::prepare`].
pub const TMP_PREFIX: &str = ".host-sim-tmp.";

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A file being written under a temporary name; [`Pending::commit`] puts it in place, dropping
/// it uncommitted removes it.
#[derive(Debug)]
pub struct Pending {
    tmp: PathBuf,
    dest: PathBuf,
    committed: bool,
}

impl Pending {
    /// Creates the temporary file for `dest` next to it, and returns it open for writing.
    pub fn create(dest: &Path) -> io::Result<(Pending, File)> {
        let dir = match dest.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let name = dest
            .file_name()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "no file name"))?;
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(
            "{TMP_PREFIX}{}-{n}.{}",
            std::process::id(),
            name.to_string_lossy()
        ));
        let file = OpenOptions::new().write(true).create_new(true).open(&tmp)?;
        Ok((
            Pending {
                tmp,
                dest: dest.to_path_buf(),
                committed: false,
            },
            file,
        ))
    }

    /// Where the bytes go until [`commit`](Self::commit) (for writers that open a path
    /// themselves, such as the PNG encoder: the file exists, is ours, and is not a symlink).
    pub fn tmp_path(&self) -> &Path {
        &self.tmp
    }

    /// The final name.
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// Syncs the temporary file and renames it onto the final name.
    pub fn commit(mut self) -> io::Result<PathBuf> {
        File::open(&self.tmp)?.sync_all()?;
        fs::rename(&self.tmp, &self.dest)?;
        self.committed = true;
        Ok(self.dest.clone())
    }

    /// Renames the temporary file, as it is, to `partial` (not synced: what a run that ends
    /// early keeps of a streamed file, [`super::csv::CsvStream`]). If the rename fails, the
    /// temporary file is left as it is rather than removed.
    pub fn keep_as(mut self, partial: &Path) -> io::Result<PathBuf> {
        self.committed = true;
        fs::rename(&self.tmp, partial)?;
        Ok(partial.to_path_buf())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to `dest` whole or not at all.
pub fn write(dest: &Path, bytes: &[u8]) -> io::Result<PathBuf> {
    let (pending, mut file) = Pending::create(dest)?;
    file.write_all(bytes)?;
    file.flush()?;
    drop(file);
    pending.commit()
}
