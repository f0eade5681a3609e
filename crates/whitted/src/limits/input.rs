//! Reading input files within bounds: every reader of scenes, meshes,
//! material libraries, textures and ray files goes through here.
//!
//! Only regular files are read (after following symbolic links): a device
//! such as `/dev/zero`, a FIFO or a folder is refused before anything is
//! read from it, naming what it is. The file is opened without waiting and
//! then checked, so one swapped for a FIFO between a check and the open
//! cannot block the reader. A file is read no further than the memory budget
//! ([`MemoryBudget::current`]), whatever its size says (files in `/proc`
//! say 0), and one larger is refused before it is read.
//!
//! Every file read is remembered by its identity ([`inputs_read`]), so
//! that a command refuses to write an output over a file it read (a scene,
//! a model, a texture, a part).

use std::collections::HashSet;
use std::fs::FileType;
use std::io::{self, Read};
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::memory::MemoryBudget;

/// A file read as input: the path it was read by, and which file that is
/// (its device and inode, whatever links led to it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputFile {
    /// The path as the reader was given it.
    pub path: PathBuf,
    /// The file system's device.
    pub device: u64,
    /// The file's inode on it.
    pub inode: u64,
}

/// The files read so far, in the order first read, and their identities
/// (a set made at the first file).
struct Ledger {
    files: Vec<InputFile>,
    identities: Option<HashSet<(u64, u64)>>,
}

/// The files this process has read.
static INPUTS: Mutex<Ledger> = Mutex::new(Ledger {
    files: Vec::new(),
    identities: None,
});

/// Every file this process has read through [`read_input`] (scenes, models,
/// material libraries, patches, textures, parts, ray files), each once,
/// in the order first read.
pub fn inputs_read() -> Vec<InputFile> {
    let inputs = INPUTS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    inputs.files.clone()
}

/// The identity of the file at `path` (its links followed), if there is
/// one: for a command to compare its outputs with the inputs it names
/// before it reads them.
pub fn identify_input(path: &Path) -> Option<InputFile> {
    let m = std::fs::metadata(path).ok()?;
    Some(InputFile {
        path: path.to_path_buf(),
        device: m.dev(),
        inode: m.ino(),
    })
}

/// Notes that the file at `path`, whose opened file's metadata is `m`, is
/// read.
fn remember(path: &Path, m: &std::fs::Metadata) {
    let mut inputs = INPUTS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let Ledger { files, identities } = &mut *inputs;
    if identities
        .get_or_insert_with(HashSet::new)
        .insert((m.dev(), m.ino()))
    {
        files.push(InputFile {
            path: path.to_path_buf(),
            device: m.dev(),
            inode: m.ino(),
        });
    }
}

/// The bytes of the regular file at `path`, read within the memory budget.
/// The errors are [`io::Error`]s saying the true cause: "not a regular
/// file: a character device (such as /dev/zero)", or the size and the
/// budget.
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    read_within(path, MemoryBudget::current())
}

/// The text of the regular file at `path`, read like [`read_input`]; not
/// UTF-8 is an [`io::ErrorKind::InvalidData`] error naming the line and
/// column of the first byte that is not ([`not_utf8`]).
pub fn read_input_text(path: &Path) -> io::Result<String> {
    String::from_utf8(read_input(path)?).map_err(|error| {
        let message = not_utf8(error.as_bytes(), error.utf8_error().valid_up_to());
        io::Error::new(io::ErrorKind::InvalidData, message)
    })
}

/// Why `bytes`, valid UTF-8 up to byte `valid`, are not text we read: a
/// UTF-16 file when its byte-order mark says so, otherwise where the
/// first bad byte is (its line, and its column in characters).
fn not_utf8(bytes: &[u8], valid: usize) -> String {
    if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        return "the file is UTF-16 (its byte-order mark says so); save it as UTF-8".to_string();
    }
    // Valid up to there, so these are whole characters.
    let before = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    format!(
        "not UTF-8 text: line {}, column {} holds the byte 0x{:02x}, which UTF-8 does not \
         allow there; save the file as UTF-8",
        before.matches('\n').count() + 1,
        before[line_start..].chars().count() + 1,
        bytes[valid]
    )
}

/// [`read_input`] within `budget`.
fn read_within(path: &Path, budget: MemoryBudget) -> io::Result<Vec<u8>> {
    // Opened first, without waiting (a FIFO with no writer would block the
    // open), then the opened file checked: a file swapped between a check
    // of the path and the open cannot slip through.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)?;
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file: {}", kind_of(metadata.file_type())),
        ));
    }
    let too_large = |needed: u64| {
        let error = budget
            .check("reading the file", needed, "use a smaller file")
            .err()?;
        Some(io::Error::new(
            io::ErrorKind::FileTooLarge,
            error.to_string(),
        ))
    };
    if let Some(error) = too_large(metadata.len()) {
        return Err(error);
    }
    remember(path, &metadata);
    let mut bytes = Vec::with_capacity(metadata.len() as usize);
    // One byte past the budget tells a file that grew beyond it.
    file.take(budget.bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    match too_large(bytes.len() as u64) {
        Some(error) => Err(error),
        None => Ok(bytes),
    }
}

/// What a file that is not a regular file is, for the message.
fn kind_of(file_type: FileType) -> &'static str {
    if file_type.is_dir() {
        "a folder"
    } else if file_type.is_char_device() {
        "a character device (such as /dev/zero)"
    } else if file_type.is_block_device() {
        "a block device"
    } else if file_type.is_fifo() {
        "a FIFO (named pipe)"
    } else if file_type.is_socket() {
        "a socket"
    } else {
        "not a file with contents"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_that_is_not_utf8_is_refused_at_its_first_bad_byte() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.toml");
        std::fs::write(&path, b"a = 1\nname = \"caf\xe9\"\n").unwrap();
        let error = read_input_text(&path).unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::InvalidData);
        assert_eq!(
            error.to_string(),
            "not UTF-8 text: line 2, column 12 holds the byte 0xe9, which UTF-8 does not allow \
             there; save the file as UTF-8"
        );
        std::fs::write(&path, b"\xff\xfea\x00=\x001\x00").unwrap();
        assert_eq!(
            read_input_text(&path).unwrap_err().to_string(),
            "the file is UTF-16 (its byte-order mark says so); save it as UTF-8"
        );
        // A character before the bad byte counts as one column.
        std::fs::write(&path, "é".bytes().chain([0xc0]).collect::<Vec<u8>>()).unwrap();
        assert!(
            read_input_text(&path)
                .unwrap_err()
                .to_string()
                .contains("line 1, column 2")
        );
    }

    #[test]
    fn every_file_read_is_remembered_once_by_identity() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("read.txt");
        std::fs::write(&path, "x").unwrap();
        let link = dir.path().join("link.txt");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        let named = identify_input(&link).unwrap();
        assert_eq!(
            identify_input(&path).map(|i| (i.device, i.inode)),
            Some((named.device, named.inode))
        );
        assert_eq!(identify_input(&dir.path().join("missing")), None);
        read_input(&path).unwrap();
        read_input(&link).unwrap();
        let same = |i: &&InputFile| (i.device, i.inode) == (named.device, named.inode);
        let read = inputs_read();
        let found: Vec<&InputFile> = read.iter().filter(same).collect();
        // Once, under the first path it was read by (here, or in another
        // test of this process whose deleted file had the same inode).
        assert_eq!(found.len(), 1, "{read:?}");
    }

    #[test]
    fn a_regular_file_is_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        std::fs::write(&path, "hello").unwrap();
        assert_eq!(read_input_text(&path).unwrap(), "hello");
        std::fs::write(&path, [0xff, 0xfe]).unwrap();
        let error = read_input_text(&path).unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::InvalidData);
    }

    #[test]
    fn devices_folders_and_fifos_are_refused_naming_what_they_are() {
        let dir = tempfile::tempdir().unwrap();
        let zero = dir.path().join("zero.toml");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let error = read_input(&zero).unwrap_err();
        assert_eq!(
            error.to_string(),
            "not a regular file: a character device (such as /dev/zero)"
        );
        let error = read_input(dir.path()).unwrap_err();
        assert_eq!(error.to_string(), "not a regular file: a folder");
        let fifo = dir.path().join("pipe.obj");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let error = read_input(&fifo).unwrap_err();
        assert_eq!(error.to_string(), "not a regular file: a FIFO (named pipe)");
    }

    #[test]
    fn a_file_larger_than_the_budget_is_refused_before_it_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.obj");
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(1 << 40).unwrap();
        let error = read_within(&path, MemoryBudget::given(1 << 20)).unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::FileTooLarge);
        // What other tests hold meanwhile may be named between the two.
        let said = error.to_string();
        assert!(
            said.starts_with("reading the file needs 1.0 TiB")
                && said.ends_with(
                    "the memory budget is 1.0 MiB (as given): use a smaller file, or raise the \
                     budget with --max-memory"
                ),
            "{said}"
        );
    }

    #[test]
    fn a_file_that_says_it_is_empty_is_still_read_no_further_than_the_budget() {
        let path = Path::new("/proc/self/status");
        let error = read_within(path, MemoryBudget::given(16)).unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::FileTooLarge);
        assert!(read_within(path, MemoryBudget::given(1 << 20)).is_ok());
    }
}
