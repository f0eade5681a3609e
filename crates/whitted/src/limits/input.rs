//! Reading input files within bounds: every reader of scenes, meshes,
//! material libraries, textures and ray files goes through here.
//!
//! Only regular files are read (after following symbolic links): a device
//! such as `/dev/zero`, a FIFO or a folder is refused before it is opened,
//! naming what it is. A file is read no further than the memory budget
//! ([`MemoryBudget::current`]), whatever its size says (files in `/proc`
//! say 0), and one larger is refused before it is read.

use std::fs::{File, FileType};
use std::io::{self, Read};
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

use super::memory::MemoryBudget;

/// The bytes of the regular file at `path`, read within the memory budget.
/// The errors are [`io::Error`]s saying the true cause: "not a regular
/// file: a character device (such as /dev/zero)", or the size and the
/// budget.
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    read_within(path, MemoryBudget::current())
}

/// The text of the regular file at `path`, read like [`read_input`]; not
/// UTF-8 is an [`io::ErrorKind::InvalidData`] error.
pub fn read_input_text(path: &Path) -> io::Result<String> {
    String::from_utf8(read_input(path)?).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// [`read_input`] within `budget`.
fn read_within(path: &Path, budget: MemoryBudget) -> io::Result<Vec<u8>> {
    let metadata = std::fs::metadata(path)?;
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
    let file = File::open(path)?;
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
        let file = File::create(&path).unwrap();
        file.set_len(1 << 40).unwrap();
        let error = read_within(&path, MemoryBudget::given(1 << 20)).unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::FileTooLarge);
        assert_eq!(
            error.to_string(),
            "reading the file needs 1.0 TiB; the memory budget is 1.0 MiB (as given): use a \
             smaller file, or raise the budget with --max-memory"
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
