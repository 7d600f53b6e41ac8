//! Writing files safely: every file wiperlab writes goes through [`write_atomic`], so a reader, a
//! crash or an interrupt never leaves a half-written file, and an existing file is replaced only
//! by a complete new one. A result names its input by the SHA-256 of its bytes ([`sha256_file`]).

use crate::{Error, Result};
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file in the same directory, renamed into place
/// (`tempfile`'s `persist`, an atomic rename on POSIX file systems). The directory must exist
/// (see [`create_dir`]): a mistyped output path is an error, not a new directory tree.
///
/// The file gets the mode `File::create` would give it: a new file 0666 without the process's
/// umask bits (0644 under umask 022), a replaced file the mode it had. A results folder shared
/// by a lab stays readable to it.
///
/// # Errors
/// [`Error::Io`] naming the directory when it does not exist or is not writable, or `path` when the
/// file cannot be written or renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| {
        w.write_all(bytes)
            .map_err(|e| Error::io(path, "cannot write", e))
    })
}

/// [`write_atomic`] for output made piece by piece: `write` streams into a buffered writer on the
/// temporary file, which is renamed into place only when `write` succeeds (a failed or partial
/// output is removed with the temporary file). A large file is never held in memory whole.
///
/// # Errors
/// As [`write_atomic`], and whatever `write` returns.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> Result<()>,
) -> Result<()> {
    use std::io::Write as _;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = temp_file_for(path, dir)?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(path, "cannot write", e))?;
    }
    tmp.persist(path)
        .map_err(|e| Error::io(path, "cannot rename into place", e.error))?;
    Ok(())
}

/// A temporary file in `dir` that will replace `path`, with the permissions `File::create` would
/// give `path`. On Unix it is opened with mode 0666, which the kernel narrows by the umask as it
/// does for any new file (no umask is read or changed, so threads cannot race), then given the
/// existing file's permission bits when `path` is replaced.
fn temp_file_for(path: &Path, dir: &Path) -> Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder
        .tempfile_in(dir)
        .map_err(|e| Error::io(dir, "cannot create a temporary file in", e))?;
    #[cfg(unix)]
    if let Some(old) = std::fs::metadata(path).ok().filter(|m| m.is_file()) {
        use std::os::unix::fs::PermissionsExt as _;
        let mode = old.permissions().mode() & 0o777;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))
            .map_err(|e| Error::io(path, "cannot give the new file the old one's mode", e))?;
    }
    Ok(tmp)
}

/// True when `name` can be used as a file or directory name beside another file: not empty, not
/// `.` or `..`, no `/` or `\\`, no leading `.`.
pub fn is_plain_stem(name: &str) -> bool {
    !name.is_empty() && !name.contains(['/', '\\']) && !name.starts_with('.')
}

/// Checks, before long work starts, that a file can later be written at `path`: it is not a
/// directory and its directory exists and takes a new file (a temporary one is created and
/// removed).
///
/// # Errors
/// [`Error::Io`] naming `path` (a directory there) or its directory.
pub fn check_writable_file(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::io(
            path,
            "cannot write a file over this directory",
            std::io::Error::from(std::io::ErrorKind::IsADirectory),
        ));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    tempfile::NamedTempFile::new_in(dir)
        .map(drop)
        .map_err(|e| Error::io(dir, "cannot write files in", e))
}

/// Checks, before long work starts, that `dir` exists as a writable directory or can be created:
/// its nearest existing ancestor is a directory that takes a new file. Creates nothing.
///
/// # Errors
/// [`Error::Io`] naming `dir` when a file is in the way, or the ancestor that cannot be written.
pub fn check_creatable_dir(dir: &Path) -> Result<()> {
    let nearest = dir
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .chain([Path::new(".")])
        .find(|a| a.exists());
    let Some(at) = nearest else {
        return Err(Error::io(
            dir,
            "cannot create this directory: no part of its path exists",
            std::io::Error::from(std::io::ErrorKind::NotFound),
        ));
    };
    if !at.is_dir() {
        return Err(Error::io(
            dir,
            "cannot create this directory: a file is in the way",
            std::io::Error::from(std::io::ErrorKind::NotADirectory),
        ));
    }
    tempfile::NamedTempFile::new_in(at)
        .map(drop)
        .map_err(|e| Error::io(at, "cannot write files in", e))
}

/// Creates `dir` and its parents if missing.
///
/// # Errors
/// [`Error::Io`] naming `dir`.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "cannot create directory", e))
}

/// Refuses to write `output` over `input` (the same file, also through another path or a link).
///
/// # Errors
/// [`Error::SameFile`] naming both paths when they are the same file.
pub fn refuse_overwriting_input(input: &Path, output: &Path) -> Result<()> {
    let same = match (std::fs::canonicalize(input), std::fs::canonicalize(output)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same {
        return Err(Error::SameFile {
            input: input.to_path_buf(),
            output: output.to_path_buf(),
        });
    }
    Ok(())
}

/// SHA-256 (FIPS 180-4) of a file's bytes, lower-case hex.
///
/// # Errors
/// [`Error::Io`] naming the file if it cannot be read.
pub fn sha256_file(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "cannot read", e))?;
    Ok(sha256_hex(&bytes))
}

/// SHA-256 of `bytes`, lower-case hex (64 characters).
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    use std::fmt::Write as _;
    let digest = sha2::Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest.iter() {
        let _ = write!(s, "{b:02x}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_fips_180_2_vectors() {
        // FIPS 180-2, Appendix B.1 ("abc") and B.2 (the 448-bit message); empty string: NIST CSRC
        // example values for SHA-256.
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_hex(b"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"
        );
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }

    #[test]
    fn replaces_whole_files_and_leaves_no_temporary_behind() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sub/out.txt");
        assert!(
            matches!(write_atomic(&p, b"x"), Err(Error::Io { .. })),
            "no sub/ yet"
        );
        create_dir(&dir.path().join("sub")).unwrap();
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second, longer").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "second, longer");
        let names: Vec<_> = std::fs::read_dir(p.parent().unwrap()).unwrap().collect();
        assert_eq!(names.len(), 1, "only the file itself");
    }

    #[test]
    fn an_output_equal_to_the_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(&a, "x").unwrap();
        let via_dot = dir.path().join(".").join("a.csv");
        assert!(refuse_overwriting_input(&a, &via_dot).is_err());
        assert!(refuse_overwriting_input(&a, &dir.path().join("b.csv")).is_ok());
    }

    #[test]
    fn a_directory_to_create_is_checked_without_creating_it() {
        let base = std::env::temp_dir().join(format!("wiperlab_io_dir_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(&base).unwrap();
        let deep = base.join("a/b/c");
        check_creatable_dir(&deep).unwrap();
        assert!(!base.join("a").exists(), "the check creates nothing");
        std::fs::write(base.join("file"), "x").unwrap();
        let err = check_creatable_dir(&base.join("file/sub")).unwrap_err();
        assert!(err.to_string().contains("a file is in the way"), "{err}");
        let err = check_writable_file(&base).unwrap_err();
        assert!(err.to_string().contains("over this directory"), "{err}");
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn an_unwritable_place_is_an_io_error_naming_it() {
        let e = write_atomic(Path::new("/proc/wiperlab/x.txt"), b"x").unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
        assert!(e.to_string().contains("/proc/wiperlab"), "{e}");
    }
}
