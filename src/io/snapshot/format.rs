//! The snapshot container: magic, format version, a postcard header with a column table,
//! raw little-endian column blobs, and a trailing xxh3 checksum of everything before the
//! columns. Columns are named, so new stores (cracks, fields) add columns, not versions.
//!
//! ```text
//! [0, 8)       magic "FISSNAP\x1a"
//! [8, 12)      format version, u32
//! [12, 20)     header length H, u64
//! [20, 20+H)   header (postcard): run identity, counts, column table
//! padding to a multiple of 8
//! columns      each at an 8-byte aligned offset from the start of the column section
//! last 8       xxh3-64 of bytes [0, 20+H)
//! ```

use crate::base::columnar::{Columnar, Scalar};
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;
use xxhash_rust::xxh3::{Xxh3, xxh3_64};

#[cfg(not(target_endian = "little"))]
compile_error!(
    "snapshots store columns as raw little-endian bytes; big-endian targets need a byte-swapping reader"
);

/// First bytes of every snapshot.
pub const MAGIC: [u8; 8] = *b"FISSNAP\x1a";
/// Container format version this build writes and the newest it reads.
pub const FORMAT_VERSION: u32 = 1;
/// Bytes before the header.
const PREAMBLE: u64 = 20;
/// Bytes of the trailing header checksum.
const TRAILER: u64 = 8;

/// One entry of the column table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Column {
    /// Name, e.g. `particles.x`.
    pub name: String,
    /// Scalar type.
    pub elem: Scalar,
    /// Number of scalars.
    pub len: u64,
    /// Byte offset from the start of the column section.
    pub offset: u64,
    /// xxh3-64 of the column's bytes.
    pub checksum: u64,
}

/// Everything ahead of the columns: what run this is, where it stands, and the column table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// 2 or 3.
    pub dimension: u8,
    /// Particle count.
    pub particles: u64,
    /// Grid node count.
    pub nodes: u64,
    /// Steps taken.
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Time step (s).
    pub dt: f64,
    /// Scenario name.
    pub scenario: String,
    /// xxh3-64 of the scenario text (after overrides).
    pub scenario_hash: u64,
    /// Version of the fissure build that wrote the snapshot.
    pub build: String,
    /// Bytes in the column section, padding included.
    pub data_len: u64,
    /// Column table.
    pub columns: Vec<Column>,
}

/// Why a snapshot cannot be read.
#[derive(Debug, Error)]
pub enum SnapshotError {
    /// The file cannot be opened or read.
    #[error("{path}: cannot read the snapshot: {cause}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause (in the message, not a separate source, so that an error chain prints it
        /// once).
        cause: std::io::Error,
    },
    /// The file is not a snapshot, is damaged, or cannot be used here.
    #[error("{path}: {message}")]
    Invalid {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Result type of snapshot reading.
pub type Result<T> = std::result::Result<T, SnapshotError>;

fn align8(n: u64) -> u64 {
    n.div_ceil(8) * 8
}

/// Columns gathered for writing: borrowed bytes, laid out at 8-byte aligned offsets.
#[derive(Default)]
pub struct ColumnSet<'a> {
    table: Vec<Column>,
    blobs: Vec<&'a [u8]>,
    len: u64,
}

impl<'a> ColumnSet<'a> {
    /// Adds column `name` holding `data`.
    pub fn add<T: Columnar>(&mut self, name: &str, data: &'a [T]) {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        self.table.push(Column {
            name: name.to_string(),
            elem: T::SCALAR,
            len: bytes.len() as u64 / T::SCALAR.size(),
            offset: self.len,
            checksum: xxh3_64(bytes),
        });
        self.blobs.push(bytes);
        self.len = align8(self.len + bytes.len() as u64);
    }

    /// Bytes of the column section (the bulk of the file).
    pub fn bytes(&self) -> u64 {
        self.len
    }

    /// Fixes the header (column table, data length) and its checksum, which identifies
    /// the whole file since the table holds every column's checksum.
    pub fn seal(self, mut header: Header) -> std::io::Result<Sealed<'a>> {
        header.data_len = self.len;
        header.columns = self.table;
        let head = postcard::to_stdvec(&header).map_err(std::io::Error::other)?;
        let mut pre = Vec::with_capacity(PREAMBLE as usize + head.len());
        pre.extend_from_slice(&MAGIC);
        pre.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        pre.extend_from_slice(&(head.len() as u64).to_le_bytes());
        pre.extend_from_slice(&head);
        Ok(Sealed {
            checksum: xxh3_64(&pre),
            pre,
            header,
            blobs: self.blobs,
        })
    }

    /// Writes the snapshot to `path` atomically (see [`Sealed::write`]).
    pub fn write(self, path: &Path, header: Header) -> std::io::Result<()> {
        self.seal(header)?.write(path)
    }
}

/// A snapshot ready to write: its header fixed and checksummed.
pub struct Sealed<'a> {
    /// The header checksum (the file's last 8 bytes).
    pub checksum: u64,
    pre: Vec<u8>,
    header: Header,
    blobs: Vec<&'a [u8]>,
}

impl Sealed<'_> {
    /// Bytes of the column section (the bulk of the file).
    pub fn bytes(&self) -> u64 {
        self.header.data_len
    }

    /// Writes the snapshot to `path` atomically: into a temporary file in the same folder,
    /// flushed and synced, then renamed over `path` (and the folder synced), so a crash at
    /// any moment leaves the old file or the new one, never a torn one.
    pub fn write(self, path: &Path) -> std::io::Result<()> {
        let pad = |n: u64| vec![0u8; (align8(n) - n) as usize];
        let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
        let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
        tmp_name.push(".tmp");
        let tmp = path.with_file_name(tmp_name);
        let written = (|| {
            let mut f = std::io::BufWriter::with_capacity(1 << 20, File::create(&tmp)?);
            f.write_all(&self.pre)?;
            f.write_all(&pad(self.pre.len() as u64))?;
            for (col, blob) in self.header.columns.iter().zip(&self.blobs) {
                debug_assert_eq!(col.len * col.elem.size(), blob.len() as u64);
                f.write_all(blob)?;
                f.write_all(&pad(blob.len() as u64))?;
            }
            f.write_all(&self.checksum.to_le_bytes())?;
            let f = f.into_inner().map_err(|e| e.into_error())?;
            f.sync_all()?;
            drop(f);
            std::fs::rename(&tmp, path)
        })();
        if written.is_err() {
            // A write cut short (a full disk) leaves no partial file to fill the disk.
            std::fs::remove_file(&tmp).ok();
        }
        written?;
        if let Some(d) = dir {
            // Persist the rename itself; opening a folder for sync is Unix-only.
            #[cfg(unix)]
            File::open(d)?.sync_all()?;
            #[cfg(not(unix))]
            let _ = d;
        }
        Ok(())
    }
}

/// An open snapshot whose header has been checked; columns are read and verified on demand.
pub struct Reader {
    path: PathBuf,
    file: File,
    /// The verified header.
    pub header: Header,
    /// The header checksum, which identifies the file (see [`ColumnSet::seal`]).
    pub checksum: u64,
    data_start: u64,
}

impl Reader {
    /// Opens `path` and checks magic, version, size and header checksum, and that every
    /// column lies inside the file (so no count in a hostile header can cause a large
    /// allocation).
    pub fn open(path: &Path) -> Result<Self> {
        let io = |cause| SnapshotError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let bad = |message: String| SnapshotError::Invalid {
            path: path.to_path_buf(),
            message,
        };
        // A FIFO or a device would block or never end: only regular files are read (the
        // check comes before opening, which blocks on a FIFO).
        if !std::fs::metadata(path).map_err(io)?.is_file() {
            return Err(bad("not a regular file".into()));
        }
        let mut file = File::open(path).map_err(io)?;
        let size = file.metadata().map_err(io)?.len();
        let mut pre = [0u8; PREAMBLE as usize];
        if size < PREAMBLE + TRAILER {
            return Err(bad(format!(
                "not a Fissure snapshot: {size} bytes is shorter than the fixed preamble"
            )));
        }
        file.read_exact(&mut pre).map_err(io)?;
        if pre[..8] != MAGIC {
            return Err(bad(
                "not a Fissure snapshot (wrong magic bytes at the start of the file)".into(),
            ));
        }
        let version = u32::from_le_bytes(pre[8..12].try_into().expect("4 bytes"));
        if version > FORMAT_VERSION {
            return Err(bad(format!(
                "snapshot format version {version} is newer than this build reads \
                 (up to {FORMAT_VERSION}); resume it with a newer fissure"
            )));
        }
        if version == 0 {
            return Err(bad(
                "snapshot format version 0 does not exist (corrupt)".into()
            ));
        }
        let head_len = u64::from_le_bytes(pre[12..20].try_into().expect("8 bytes"));
        if head_len > size - PREAMBLE - TRAILER {
            return Err(bad(format!(
                "header length {head_len} exceeds the file size {size} (truncated or corrupt)"
            )));
        }
        let mut head = vec![0u8; head_len as usize];
        file.read_exact(&mut head).map_err(io)?;
        let mut trailer = [0u8; TRAILER as usize];
        file.seek(SeekFrom::Start(size - TRAILER)).map_err(io)?;
        file.read_exact(&mut trailer).map_err(io)?;
        let mut h = Xxh3::new();
        h.update(&pre);
        h.update(&head);
        let decoded: Option<Header> = postcard::from_bytes(&head).ok();
        let data_start = align8(PREAMBLE + head_len);
        let checksum = u64::from_le_bytes(trailer);
        if h.digest() != checksum {
            let expected = decoded
                .as_ref()
                .and_then(|d| data_start.checked_add(d.data_len)?.checked_add(TRAILER));
            return Err(bad(match expected {
                Some(e) if e != size => {
                    format!(
                        "truncated or extended: the header describes {e} bytes, the file has {size}"
                    )
                }
                _ => "header checksum mismatch (the file is corrupt)".into(),
            }));
        }
        let header = decoded.ok_or_else(|| bad("header cannot be decoded (corrupt)".into()))?;
        if data_start
            .checked_add(header.data_len)
            .and_then(|n| n.checked_add(TRAILER))
            != Some(size)
        {
            return Err(bad(format!(
                "the header describes {} bytes of columns but the file holds {}",
                header.data_len,
                size.saturating_sub(data_start + TRAILER)
            )));
        }
        for c in &header.columns {
            let end = c
                .len
                .checked_mul(c.elem.size())
                .and_then(|b| b.checked_add(c.offset));
            if end.is_none_or(|e| e > header.data_len) {
                return Err(bad(format!(
                    "column `{}` lies outside the file (corrupt column table)",
                    c.name
                )));
            }
        }
        Ok(Reader {
            path: path.to_path_buf(),
            file,
            header,
            checksum,
            data_start,
        })
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// An error about this snapshot.
    pub fn invalid(&self, message: impl Into<String>) -> SnapshotError {
        SnapshotError::Invalid {
            path: self.path.clone(),
            message: message.into(),
        }
    }

    /// Byte offset of column `name` from the start of the file.
    pub fn offset_of(&self, name: &str) -> Option<u64> {
        let c = self.header.columns.iter().find(|c| c.name == name)?;
        Some(self.data_start + c.offset)
    }

    /// Reads column `name` as `count` items of `T`, verifying its checksum.
    pub fn column<T: Columnar>(&mut self, name: &str, count: usize) -> Result<Vec<T>> {
        let c = self
            .header
            .columns
            .iter()
            .find(|c| c.name == name)
            .cloned()
            .ok_or_else(|| self.invalid(format!("column `{name}` is missing")))?;
        let bytes = (count as u64).checked_mul(std::mem::size_of::<T>() as u64);
        if c.elem != T::SCALAR || Some(c.len * c.elem.size()) != bytes {
            return Err(self.invalid(format!(
                "column `{name}` holds {} {:?} scalars; expected {count} items of {} bytes",
                c.len,
                c.elem,
                std::mem::size_of::<T>()
            )));
        }
        let mut out = vec![T::zeroed(); count];
        let io = |cause| SnapshotError::Io {
            path: self.path.clone(),
            cause,
        };
        self.file
            .seek(SeekFrom::Start(self.data_start + c.offset))
            .map_err(io)?;
        self.file
            .read_exact(bytemuck::cast_slice_mut(&mut out))
            .map_err(io)?;
        if xxh3_64(bytemuck::cast_slice(&out)) != c.checksum {
            return Err(self.invalid(format!(
                "column `{name}` fails its checksum (the file is corrupt)"
            )));
        }
        Ok(out)
    }

    /// Reads column `name` whatever its length (at most the file size, checked at open).
    pub fn column_any<T: Columnar>(&mut self, name: &str) -> Result<Vec<T>> {
        let c = self
            .header
            .columns
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| self.invalid(format!("column `{name}` is missing")))?;
        let count = (c.len * c.elem.size()) / std::mem::size_of::<T>() as u64;
        self.column(name, count as usize)
    }

    /// Verifies every column's checksum: (name, ok) in table order.
    pub fn verify(&mut self) -> Result<Vec<(String, bool)>> {
        let mut out = Vec::new();
        let mut buf = Vec::new();
        for c in self.header.columns.clone() {
            buf.resize((c.len * c.elem.size()) as usize, 0u8);
            let io = |cause| SnapshotError::Io {
                path: self.path.clone(),
                cause,
            };
            self.file
                .seek(SeekFrom::Start(self.data_start + c.offset))
                .map_err(io)?;
            self.file.read_exact(&mut buf).map_err(io)?;
            out.push((c.name, xxh3_64(&buf) == c.checksum));
        }
        Ok(out)
    }
}
