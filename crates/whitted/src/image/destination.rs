//! Where an image goes: the rules for replacing a file, checked before any
//! work ([`check_destination`]) and again when the image is written.
//!
//! - A symbolic link is written through: its target gets the image, the
//!   link stays (a dangling link's target is created).
//! - An existing file is replaced only if it is a regular file that the
//!   user may write (`access(W_OK)` with the effective ids; as root that is
//!   any file on a writable file system, as for `cp`).
//! - The new file keeps the old one's permission bits, and its owner and
//!   group where the user may set them (root may; a note says when another
//!   user's file will become the user's).
//! - A file with several names (hard links) gets a new file under this name
//!   only: a note says the other names keep the old image.
//! - The folder must exist and take a new file: a partial file is created
//!   and removed there to be sure. In a sticky folder (like `/tmp`) only
//!   the file's owner (or the folder's, or root) may replace it.
//! - Two destinations are the same file when their canonical paths are
//!   equal or they are one existing file (same device and inode).

use std::fs::{File, Metadata};
use std::io;
use std::path::{Path, PathBuf};

use super::partial::{IN_FLIGHT, PartialFile};
use super::{ImageError, ImageFormat};

/// Symbolic links followed at most, as Linux does.
const MAX_LINKS: usize = 40;

/// A checked destination: where the image will really be written and what
/// is there now.
#[derive(Clone, Debug)]
pub struct Destination {
    path: PathBuf,
    target: PathBuf,
    canonical: PathBuf,
    /// The image format, `None` for a text file ([`check_text_destination`]).
    format: Option<ImageFormat>,
    existing: Option<ExistingFile>,
}

/// What the replaced file was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ExistingFile {
    mode: u32,
    owner: u32,
    group: u32,
    links: u64,
    device: u64,
    inode: u64,
}

/// Checks that `path` names a file whitted may write: a known image format,
/// a name that is a file's, in an existing folder that takes new files, and
/// if a file is there, a regular file the user may write. Lets a caller
/// refuse bad destinations before doing the work.
pub fn check_destination(path: &Path) -> Result<Destination, ImageError> {
    let format = ImageFormat::from_path(path)?;
    check_writable(path, Some(format))
}

/// [`check_destination`] for a text file of the kind `extension` names
/// (such as `svg`, compared without regard to case): the name must end
/// in it, so that no drawing is written under an image's name.
pub fn check_text_destination(path: &Path, extension: &str) -> Result<Destination, ImageError> {
    let given = path.extension().and_then(|e| e.to_str());
    if !given.is_some_and(|e| e.eq_ignore_ascii_case(extension)) {
        return Err(refused(
            path,
            format!("this output is an .{extension} file; give a name ending in .{extension}"),
        ));
    }
    check_writable(path, None)
}

/// The rest of [`check_destination`] for a file of `format`.
fn check_writable(path: &Path, format: Option<ImageFormat>) -> Result<Destination, ImageError> {
    let (target, existing) = resolve(path)?;
    let folder = folder_of(&target);
    // The truest test that the folder takes a new file is to make one.
    drop(PartialFile::create_in(folder, &IN_FLIGHT).map_err(|e| {
        refused(
            path,
            format!(
                "cannot create a file in {}: {}",
                describe_folder(folder),
                os_message(&e)
            ),
        )
    })?);
    let canonical = match existing {
        Some(_) => target.canonicalize(),
        None => folder
            .canonicalize()
            .map(|f| f.join(target.file_name().unwrap_or_default())),
    }
    .map_err(|source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(Destination {
        path: path.to_path_buf(),
        target,
        canonical,
        format,
        existing,
    })
}

impl Destination {
    /// The path as given.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file that will be written: the path with its symbolic links
    /// followed.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The image format the name asks for (`None` for a text file).
    pub fn format(&self) -> Option<ImageFormat> {
        self.format
    }

    /// Whether both name one file: the same canonical path, or the same
    /// existing file under two names (hard links).
    pub fn is_same_file_as(&self, other: &Destination) -> bool {
        let same_inode = match (self.existing, other.existing) {
            (Some(a), Some(b)) => (a.device, a.inode) == (b.device, b.inode),
            _ => false,
        };
        same_inode || self.canonical == other.canonical
    }

    /// Whether the file that will be replaced is `input`, a file read
    /// ([`crate::limits::inputs_read`]): the same device and inode, by
    /// whatever name or link.
    pub fn is_input(&self, input: &crate::limits::InputFile) -> bool {
        self.existing
            .is_some_and(|e| (e.device, e.inode) == (input.device, input.inode))
    }

    /// What the user should know before the file is replaced, one sentence
    /// each: other names of the file that keep the old image, an owner
    /// that cannot be kept.
    pub fn notes(&self) -> Vec<String> {
        let Some(existing) = self.existing else {
            return Vec::new();
        };
        let mut notes = Vec::new();
        if existing.links > 1 {
            notes.push(format!(
                "{}: the file has {} names (hard links); the new image replaces this name only, \
                 the other {} keep the old file",
                self.path.display(),
                existing.links,
                existing.links - 1
            ));
        }
        if let Some(user) = user_id()
            && user != 0
            && user != existing.owner
        {
            notes.push(format!(
                "{}: the file belongs to user {}; the new file will belong to you (user {user})",
                self.path.display(),
                existing.owner
            ));
        }
        notes
    }
}

/// `path` with its symbolic links followed, and the file there if any
/// (checked to be a regular file the user may write). The folder is checked
/// to exist when no file is there.
pub(crate) fn resolve(path: &Path) -> Result<(PathBuf, Option<ExistingFile>), ImageError> {
    let mut target = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&target).map_err(|source| ImageError::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
                target = folder_of(&target).join(link);
            }
            Ok(m) => {
                let existing = writable_file(path, &target, &m)?;
                return Ok((target, Some(existing)));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                check_folder(path, folder_of(&target))?;
                return Ok((target, None));
            }
            Err(e) if e.kind() == io::ErrorKind::NotADirectory => {
                check_folder(path, folder_of(&target))?;
                return Err(ImageError::Io {
                    path: path.to_path_buf(),
                    source: e,
                });
            }
            Err(source) => {
                return Err(ImageError::Io {
                    path: path.to_path_buf(),
                    source,
                });
            }
        }
    }
    Err(refused(
        path,
        format!("more than {MAX_LINKS} symbolic links in a row (a loop?)"),
    ))
}

/// The file at `target` (the destination `path` with its links followed),
/// if it is there: it must be a regular file the user may write.
pub(crate) fn existing_file(
    path: &Path,
    target: &Path,
) -> Result<Option<ExistingFile>, ImageError> {
    match std::fs::symlink_metadata(target) {
        Ok(m) => writable_file(path, target, &m).map(Some),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(source) => Err(ImageError::Io {
            path: path.to_path_buf(),
            source,
        }),
    }
}

fn writable_file(path: &Path, target: &Path, m: &Metadata) -> Result<ExistingFile, ImageError> {
    let kind = m.file_type();
    if kind.is_dir() {
        return Err(refused(
            path,
            "this is a folder, not a file name".to_string(),
        ));
    }
    if !kind.is_file() {
        return Err(refused(
            path,
            format!(
                "this is {}, not a regular file; whitted writes images to regular files only",
                describe_kind(m)
            ),
        ));
    }
    may_write(target).map_err(|e| match e.kind() {
        io::ErrorKind::PermissionDenied => refused(
            path,
            "you may not write this file (permission denied), so whitted does not replace it"
                .to_string(),
        ),
        _ => refused(path, format!("cannot write this file: {}", os_message(&e))),
    })?;
    let existing = facts(m);
    if let Some(owner) = sticky_folder_owner(folder_of(target))
        && let Some(user) = user_id()
        && ![0, owner, existing.owner].contains(&user)
    {
        return Err(refused(
            path,
            format!(
                "the file belongs to user {} in {}, where only a file's owner may replace it \
                 (a sticky folder, like /tmp)",
                existing.owner,
                describe_folder(folder_of(target))
            ),
        ));
    }
    Ok(existing)
}

/// The owner of `folder` if it is sticky (its files may be renamed over
/// only by their owner, the folder's owner or root).
#[cfg(unix)]
fn sticky_folder_owner(folder: &Path) -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(folder).ok()?;
    (m.mode() & 0o1000 != 0).then(|| m.uid())
}

#[cfg(not(unix))]
fn sticky_folder_owner(_: &Path) -> Option<u32> {
    None
}

/// Checks that `folder` exists and is a folder, naming the true cause when
/// not: a missing folder, or a file where a folder should be.
fn check_folder(path: &Path, folder: &Path) -> Result<(), ImageError> {
    match std::fs::metadata(folder) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(m) => Err(not_a_folder(path, folder, &m)),
        Err(e)
            if matches!(
                e.kind(),
                io::ErrorKind::NotFound | io::ErrorKind::NotADirectory
            ) =>
        {
            // The nearest existing ancestor says why: a file on the way,
            // or a folder that simply is not there.
            for ancestor in folder.ancestors().skip(1) {
                if ancestor.as_os_str().is_empty() {
                    break;
                }
                if let Ok(m) = std::fs::metadata(ancestor) {
                    if !m.is_dir() {
                        return Err(not_a_folder(path, ancestor, &m));
                    }
                    break;
                }
            }
            Err(refused(
                path,
                format!("the folder {} does not exist", folder.display()),
            ))
        }
        Err(e) => Err(refused(
            path,
            format!(
                "cannot look into {}: {}",
                describe_folder(folder),
                os_message(&e)
            ),
        )),
    }
}

fn not_a_folder(path: &Path, not_folder: &Path, m: &Metadata) -> ImageError {
    refused(
        path,
        format!(
            "{} is {}, not a folder",
            not_folder.display(),
            describe_kind(m)
        ),
    )
}

/// "a file", "a named pipe", … for a message.
fn describe_kind(m: &Metadata) -> &'static str {
    let kind = m.file_type();
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe";
        }
        if kind.is_socket() {
            return "a socket";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_file() {
        "a file"
    } else {
        "a special file"
    }
}

fn describe_folder(folder: &Path) -> String {
    if folder == Path::new(".") {
        "the current folder".to_string()
    } else {
        format!("the folder {}", folder.display())
    }
}

/// The system's words for an error, without the file names some errors
/// carry (a partial file's name would only confuse).
fn os_message(e: &io::Error) -> String {
    match e.raw_os_error() {
        Some(code) => io::Error::from_raw_os_error(code).to_string(),
        None => e.kind().to_string(),
    }
}

fn refused(path: &Path, why: String) -> ImageError {
    ImageError::Refused {
        path: path.to_path_buf(),
        why,
    }
}

/// The folder a file is written in (`.` for a bare file name).
pub(crate) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Gives the new file the old one's permission bits, and its owner and
/// group where the user may (else the group alone, else neither: the note
/// of [`Destination::notes`] said so).
pub(crate) fn keep_attributes(file: &File, existing: &ExistingFile) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{PermissionsExt, fchown};
        if fchown(file, Some(existing.owner), Some(existing.group)).is_err() {
            let _ = fchown(file, None, Some(existing.group));
        }
        file.set_permissions(std::fs::Permissions::from_mode(existing.mode & 0o777))?;
    }
    #[cfg(not(unix))]
    let _ = (file, existing);
    Ok(())
}

#[cfg(unix)]
fn facts(m: &Metadata) -> ExistingFile {
    use std::os::unix::fs::MetadataExt;
    ExistingFile {
        mode: m.mode(),
        owner: m.uid(),
        group: m.gid(),
        links: m.nlink(),
        device: m.dev(),
        inode: m.ino(),
    }
}

#[cfg(not(unix))]
fn facts(m: &Metadata) -> ExistingFile {
    ExistingFile {
        mode: u32::from(!m.permissions().readonly()),
        owner: 0,
        group: 0,
        links: 1,
        device: 0,
        inode: 0,
    }
}

/// Whether the user may write `path`, by the effective ids.
#[cfg(unix)]
fn may_write(path: &Path) -> io::Result<()> {
    use rustix::fs::{Access, AtFlags, CWD, accessat};
    accessat(CWD, path, Access::WRITE_OK, AtFlags::EACCESS).map_err(io::Error::from)
}

#[cfg(not(unix))]
fn may_write(path: &Path) -> io::Result<()> {
    if std::fs::metadata(path)?.permissions().readonly() {
        return Err(io::ErrorKind::PermissionDenied.into());
    }
    Ok(())
}

/// The effective user id, where there is one.
#[cfg(unix)]
fn user_id() -> Option<u32> {
    Some(rustix::process::geteuid().as_raw())
}

#[cfg(not(unix))]
fn user_id() -> Option<u32> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message(path: &Path) -> String {
        check_destination(path).unwrap_err().to_string()
    }

    #[test]
    fn a_drawing_must_be_named_as_one_and_knows_the_files_read() {
        let dir = tempfile::tempdir().unwrap();
        let svg = dir.path().join("tree.SVG");
        let d = check_text_destination(&svg, "svg").unwrap();
        assert_eq!(d.format(), None);
        let png = dir.path().join("tree.png");
        let error = check_text_destination(&png, "svg").unwrap_err();
        assert_eq!(
            error.to_string(),
            format!(
                "{}: this output is an .svg file; give a name ending in .svg",
                png.display()
            )
        );
        // An existing file read as input is recognised by any name.
        std::fs::write(&svg, "old").unwrap();
        std::fs::hard_link(&svg, dir.path().join("other.svg")).unwrap();
        let input = crate::limits::identify_input(&dir.path().join("other.svg")).unwrap();
        assert!(
            check_text_destination(&svg, "svg")
                .unwrap()
                .is_input(&input)
        );
        let fresh = check_text_destination(&dir.path().join("new.svg"), "svg").unwrap();
        assert!(!fresh.is_input(&input));
    }

    #[test]
    fn a_new_file_in_an_existing_folder_is_a_destination() {
        let dir = tempfile::tempdir().unwrap();
        let d = check_destination(&dir.path().join("a.exr")).unwrap();
        assert_eq!(d.format(), Some(ImageFormat::Exr));
        assert!(d.notes().is_empty());
        // The folder test leaves nothing behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn missing_folders_and_files_in_the_way_are_told_apart() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("no/such/a.png");
        assert_eq!(
            message(&missing),
            format!(
                "{}: the folder {} does not exist",
                missing.display(),
                dir.path().join("no/such").display()
            )
        );
        let file = dir.path().join("afile");
        std::fs::write(&file, b"x").unwrap();
        for below in ["afile/x.png", "afile/deeper/x.png"] {
            let path = dir.path().join(below);
            assert_eq!(
                message(&path),
                format!(
                    "{}: {} is a file, not a folder",
                    path.display(),
                    file.display()
                )
            );
        }
        let folder = dir.path().join("folder.png");
        std::fs::create_dir(&folder).unwrap();
        assert_eq!(
            message(&folder),
            format!("{}: this is a folder, not a file name", folder.display())
        );
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.png");
        rustix::fs::mkfifoat(
            rustix::fs::CWD,
            &fifo,
            rustix::fs::Mode::from_raw_mode(0o644),
        )
        .unwrap();
        assert_eq!(
            message(&fifo),
            format!(
                "{}: this is a named pipe, not a regular file; whitted writes images to regular \
                 files only",
                fifo.display()
            )
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_to_its_target() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let link = dir.path().join("link.png");
        std::os::unix::fs::symlink("sub/real.png", &link).unwrap();
        let d = check_destination(&link).unwrap();
        assert_eq!(d.target(), dir.path().join("sub/real.png"));
        let direct = check_destination(&dir.path().join("sub/../sub/real.png")).unwrap();
        assert!(d.is_same_file_as(&direct));

        let looped = dir.path().join("loop.png");
        std::os::unix::fs::symlink("loop.png", &looped).unwrap();
        assert!(message(&looped).contains("symbolic links in a row"));
    }

    #[cfg(unix)]
    #[test]
    fn hard_links_are_the_same_file_and_get_a_note() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.pfm");
        let b = dir.path().join("b.pfm");
        std::fs::write(&a, b"old").unwrap();
        std::fs::hard_link(&a, &b).unwrap();
        let (da, db) = (
            check_destination(&a).unwrap(),
            check_destination(&b).unwrap(),
        );
        assert!(da.is_same_file_as(&db));
        let notes = da.notes();
        assert!(
            notes.iter().any(|n| n.contains("has 2 names (hard links)")),
            "{notes:?}"
        );
        let other = check_destination(&dir.path().join("c.pfm")).unwrap();
        assert!(!da.is_same_file_as(&other));
    }

    #[cfg(unix)]
    #[test]
    fn a_file_the_user_may_not_write_is_refused() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ro.png");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o444)).unwrap();
        let writable = may_write(&path).is_ok();
        if rustix::process::geteuid().is_root() {
            // Root may write any file, as `cp` would: the check agrees.
            assert!(writable);
            assert!(check_destination(&path).is_ok());
        } else {
            assert!(!writable);
            assert_eq!(
                message(&path),
                format!(
                    "{}: you may not write this file (permission denied), so whitted does not \
                     replace it",
                    path.display()
                )
            );
        }
    }
}
