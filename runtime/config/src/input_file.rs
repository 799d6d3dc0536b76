//! Reading an input file (configuration, program, recording) without letting the file decide
//! how long the read takes or how much it allocates: only a regular file is read, it is opened
//! without blocking (a FIFO or a device is refused, never waited on), and its size is capped.

use std::fs::OpenOptions;
use std::io::{Error, ErrorKind, Read};
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

use cellrt_ethercat::esi::EsiFileError;

/// The largest configuration or program cellrt reads.
pub const MAX_TEXT_BYTES: u64 = 4 << 20;

/// The largest ESI file cellrt reads (vendor files with many devices run to a few MiB).
pub const MAX_ESI_BYTES: u64 = 64 << 20;

/// Reads `path` if it is a regular file of at most `max` bytes (`None`: any size).
pub fn read_bytes(path: &Path, max: Option<u64>) -> Result<Vec<u8>, Error> {
    let file = OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "not a regular file (a FIFO, device or directory is not read)",
        ));
    }
    let limit = max.unwrap_or(u64::MAX);
    if meta.len() > limit {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{} bytes, more than the {limit} read", meta.len()),
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // A file growing while it is read stops at the limit.
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("more than the {limit} bytes read"),
        ));
    }
    Ok(bytes)
}

/// Reads a text input (configuration, program): a regular UTF-8 file of at most
/// [`MAX_TEXT_BYTES`].
pub fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = read_bytes(path, Some(MAX_TEXT_BYTES))?;
    String::from_utf8(bytes).map_err(|e| Error::new(ErrorKind::InvalidData, e.utf8_error()))
}

/// Reads the devices of an ESI file: a regular file of at most [`MAX_ESI_BYTES`].
pub fn read_esi(path: &Path) -> Result<Vec<cellrt_ethercat::esi::EsiDevice>, EsiFileError> {
    let bytes = read_bytes(path, Some(MAX_ESI_BYTES)).map_err(|source| EsiFileError::Read {
        path: path.to_owned(),
        source,
    })?;
    cellrt_ethercat::esi::decode_file(path, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_of_a_bounded_size_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let ok = dir.path().join("cell.toml");
        std::fs::write(&ok, "[cell]\n").unwrap();
        assert_eq!(read_text(&ok).unwrap(), "[cell]\n");
        // A FIFO without a writer: refused at once, not waited on.
        let fifo = dir.path().join("fifo");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let e = read_text(&fifo).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        // /dev/zero would never end.
        let e = read_text(Path::new("/dev/zero")).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        // A directory, an oversized file, invalid UTF-8.
        assert!(read_text(dir.path()).is_err());
        let big = dir.path().join("big.toml");
        std::fs::File::create(&big)
            .unwrap()
            .set_len(MAX_TEXT_BYTES + 1)
            .unwrap();
        assert!(read_text(&big)
            .unwrap_err()
            .to_string()
            .contains("more than"));
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, [0xff, 0xfe]).unwrap();
        assert_eq!(read_text(&bad).unwrap_err().kind(), ErrorKind::InvalidData);
    }

    #[test]
    fn an_esi_that_is_no_regular_file_is_refused_unread() {
        let e = read_esi(Path::new("/dev/zero")).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("esi.xml");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let e = read_esi(&fifo).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
}
