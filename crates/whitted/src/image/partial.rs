//! Partial files: the temporary files (`.whitted-XXXXXX.partial`) an image
//! is encoded into before it is renamed over its destination, and the
//! registry of those still in flight, so that a process ending on a signal
//! can remove them ([`remove_partial_files`]).
//!
//! The registry is locked while a partial file is created, renamed or
//! removed, so at any moment every partial file on disk is either listed or
//! about to be gone with the lock held by its owner.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// A list of partial files that exist now.
#[derive(Debug)]
pub(crate) struct Registry(Mutex<Vec<Listed>>);

/// A listed partial file.
#[derive(Debug)]
struct Listed {
    path: PathBuf,
    /// The same path as the system takes it, made when it was listed, so
    /// that a process being aborted removes it without allocating.
    #[cfg(unix)]
    c_path: std::ffi::CString,
}

impl Listed {
    fn new(path: &Path) -> io::Result<Self> {
        Ok(Self {
            path: path.to_path_buf(),
            #[cfg(unix)]
            c_path: std::ffi::CString::new(std::os::unix::ffi::OsStrExt::as_bytes(
                path.as_os_str(),
            ))?,
        })
    }

    /// Removes the file, allocating nothing on Unix.
    fn remove(&self) {
        // Already gone is as good as removed; nothing else can be done
        // about a file that cannot be removed by a process that is ending.
        #[cfg(unix)]
        let _ = rustix::fs::unlink(self.c_path.as_c_str());
        #[cfg(not(unix))]
        let _ = std::fs::remove_file(&self.path);
    }
}

impl Registry {
    /// An empty list.
    pub(crate) const fn new() -> Self {
        Self(Mutex::new(Vec::new()))
    }

    fn lock(&self) -> MutexGuard<'_, Vec<Listed>> {
        // The list stays valid whatever panicked while holding it: every
        // change to it is one push or one removal.
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Removes every listed file and keeps the list locked.
    fn remove_all(&self) -> MutexGuard<'_, Vec<Listed>> {
        let mut list = self.lock();
        for listed in list.drain(..) {
            listed.remove();
        }
        list
    }

    /// Removes every listed file when the list is not locked, without
    /// waiting for it and, on Unix, without allocating. Returns whether
    /// the list could be read.
    fn remove_all_now(&self) -> bool {
        let Ok(list) = self.0.try_lock() else {
            return false;
        };
        for listed in list.iter() {
            listed.remove();
        }
        true
    }
}

/// The partial files of this process.
pub(crate) static IN_FLIGHT: Registry = Registry::new();

/// A new temporary file in a folder, listed in the registry until it is
/// renamed into place or dropped (which removes it).
#[derive(Debug)]
pub(crate) struct PartialFile {
    /// Always `Some` until `persist` or `drop` takes it.
    temp: Option<tempfile::NamedTempFile>,
    registry: &'static Registry,
}

impl PartialFile {
    /// Creates an empty partial file in `folder`, readable as the umask
    /// allows like any new file (not private to the owner, as temporary
    /// files are by default).
    pub(crate) fn create_in(folder: &Path, registry: &'static Registry) -> io::Result<Self> {
        let mut builder = tempfile::Builder::new();
        builder.prefix(".whitted-").suffix(".partial");
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let mut list = registry.lock();
        let temp = builder.tempfile_in(folder)?;
        list.push(Listed::new(temp.path())?);
        Ok(Self {
            temp: Some(temp),
            registry,
        })
    }

    /// The open file, to write into.
    pub(crate) fn file(&mut self) -> &mut File {
        self.temp
            .as_mut()
            .map(tempfile::NamedTempFile::as_file_mut)
            .expect("a partial file is present until persisted or dropped")
    }

    /// Renames the file to `target`, replacing what is there.
    pub(crate) fn persist(mut self, target: &Path) -> io::Result<()> {
        let mut list = self.registry.lock();
        let temp = self
            .temp
            .take()
            .expect("a partial file is present until persisted or dropped");
        let path = temp.path().to_path_buf();
        // On failure the file comes back with the error and is removed
        // here, with the registry still locked.
        let result = temp.persist(target).map(drop).map_err(|e| e.error);
        list.retain(|l| l.path != path);
        result
    }
}

impl Drop for PartialFile {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            let mut list = self.registry.lock();
            let path = temp.path().to_path_buf();
            drop(temp);
            list.retain(|l| l.path != path);
        }
    }
}

/// Proof that the partial files are gone: while it is held, no partial
/// file can be created, renamed or removed by another thread.
#[must_use = "hold it until the process exits, so that no new partial file appears"]
pub struct PartialFilesRemoved {
    _list: MutexGuard<'static, Vec<Listed>>,
}

/// Removes every partial file this process has on disk, for a process
/// about to end on a signal (an image half encoded must not be left
/// behind). Hold the result until the process exits: it keeps other
/// threads from starting a new one.
pub fn remove_partial_files() -> PartialFilesRemoved {
    PartialFilesRemoved {
        _list: IN_FLIGHT.remove_all(),
    }
}

/// Removes every partial file this process has on disk, for a process
/// being aborted (in a `SIGABRT` handler): it neither waits for the
/// registry's lock nor, on Unix, allocates. Returns false, removing
/// nothing, when a thread held the registry at that moment (one creating,
/// renaming or removing a partial file, possibly the one aborting): the
/// files are then left behind.
pub fn remove_partial_files_now() -> bool {
    IN_FLIGHT.remove_all_now()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each test's own registry: emptying one that another test uses
    /// (the process's, or a shared one) would remove that test's files
    /// while it runs beside it.
    static LISTED: Registry = Registry::new();
    static EMPTIED: Registry = Registry::new();
    static ABORTED: Registry = Registry::new();

    /// The files `registry` lists.
    fn listed(registry: &Registry) -> Vec<PathBuf> {
        registry.lock().iter().map(|l| l.path.clone()).collect()
    }

    #[test]
    fn a_partial_file_is_listed_while_it_exists() {
        let dir = tempfile::tempdir().unwrap();
        let partial = PartialFile::create_in(dir.path(), &LISTED).unwrap();
        let path = partial.temp.as_ref().unwrap().path().to_path_buf();
        assert!(listed(&LISTED).contains(&path));
        assert!(
            path.file_name()
                .unwrap()
                .to_string_lossy()
                .ends_with(".partial")
        );
        drop(partial);
        assert!(!path.exists());
        assert!(!listed(&LISTED).contains(&path));

        let mut partial = PartialFile::create_in(dir.path(), &LISTED).unwrap();
        let path = partial.temp.as_ref().unwrap().path().to_path_buf();
        std::io::Write::write_all(partial.file(), b"image").unwrap();
        let target = dir.path().join("done");
        partial.persist(&target).unwrap();
        assert!(!listed(&LISTED).contains(&path));
        assert_eq!(std::fs::read(&target).unwrap(), b"image");
    }

    #[test]
    fn removing_the_partial_files_empties_the_folder_of_them() {
        let dir = tempfile::tempdir().unwrap();
        let partial = PartialFile::create_in(dir.path(), &EMPTIED).unwrap();
        let path = partial.temp.as_ref().unwrap().path().to_path_buf();
        {
            let _removed = EMPTIED.remove_all();
        }
        assert!(!path.exists());
        // Dropping it afterwards finds nothing to remove and no entry.
        drop(partial);
        assert!(!listed(&EMPTIED).contains(&path));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn removing_at_an_abort_neither_waits_nor_needs_the_list_free() {
        let dir = tempfile::tempdir().unwrap();
        let partial = PartialFile::create_in(dir.path(), &ABORTED).unwrap();
        let path = partial.temp.as_ref().unwrap().path().to_path_buf();
        {
            let _held = ABORTED.lock();
            assert!(!ABORTED.remove_all_now());
        }
        assert!(path.exists());
        assert!(ABORTED.remove_all_now());
        assert!(!path.exists());
        drop(partial);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
