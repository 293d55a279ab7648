//! Frames on the socket between the node and its worker process.
//!
//! A frame is a 33-byte header (kind `u8`, then four little-endian `u64`: job id, two
//! kind-specific numbers, body length) and the body. Writes use `send(…, MSG_NOSIGNAL)`, so a
//! peer that died is an error (`EPIPE`), never a SIGPIPE that would end the node.

use std::{
    io::Read,
    os::unix::{io::AsRawFd, net::UnixStream},
};

/// Node → worker: plan a job (`a` = time limit in ns, `b` = memory limit in bytes).
pub(crate) const JOB: u8 = 1;
/// Node → worker: cancel job `id` (cooperatively, through its budget).
pub(crate) const CANCEL: u8 = 2;
/// Worker → node: the answer of job `id` (body: the encoded answer).
pub(crate) const ANSWER: u8 = 3;
/// Worker → node: job `id` panicked (body: the panic message, UTF-8).
pub(crate) const PANICKED: u8 = 4;

const HEADER: usize = 33;

/// One frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Frame {
    pub kind: u8,
    pub id: u64,
    pub a: u64,
    pub b: u64,
    pub body: Vec<u8>,
}

impl Frame {
    /// A frame without numbers.
    pub(crate) fn new(kind: u8, id: u64, body: Vec<u8>) -> Self {
        Self {
            kind,
            id,
            a: 0,
            b: 0,
            body,
        }
    }
}

/// Sends all of `bytes` on `stream`.
fn send_all(stream: &UnixStream, mut bytes: &[u8]) -> std::io::Result<()> {
    let fd = stream.as_raw_fd();
    while !bytes.is_empty() {
        // SAFETY: `bytes` is a valid buffer of its length; `fd` is an open socket.
        let n = unsafe { libc::send(fd, bytes.as_ptr().cast(), bytes.len(), libc::MSG_NOSIGNAL) };
        if n < 0 {
            let e = std::io::Error::last_os_error();
            if e.kind() == std::io::ErrorKind::Interrupted {
                continue;
            }
            return Err(e);
        }
        let n = usize::try_from(n).unwrap_or(0);
        bytes = bytes.get(n..).unwrap_or_default();
    }
    Ok(())
}

/// Writes one frame.
///
/// # Errors
/// The socket's error (`EPIPE` once the peer is gone).
pub(crate) fn write_frame(stream: &UnixStream, frame: &Frame) -> std::io::Result<()> {
    let mut header = [0u8; HEADER];
    header[0] = frame.kind;
    let numbers = [frame.id, frame.a, frame.b, frame.body.len() as u64];
    for (k, n) in numbers.iter().enumerate() {
        header[1 + 8 * k..9 + 8 * k].copy_from_slice(&n.to_le_bytes());
    }
    send_all(stream, &header)?;
    send_all(stream, &frame.body)
}

/// Reads one frame.
///
/// # Returns
/// `None` when the peer closed the socket before a new frame.
///
/// # Errors
/// A read error, a frame cut short, or a body over `max_body` bytes (nothing of it is read).
pub(crate) fn read_frame(stream: &mut impl Read, max_body: u64) -> std::io::Result<Option<Frame>> {
    let mut header = [0u8; HEADER];
    let mut got = 0;
    while got < HEADER {
        match stream.read(&mut header[got..]) {
            Ok(0) if got == 0 => return Ok(None),
            Ok(0) => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::UnexpectedEof,
                    "frame header cut short",
                ))
            }
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    let number = |k: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&header[1 + 8 * k..9 + 8 * k]);
        u64::from_le_bytes(b)
    };
    let len = number(3);
    if len > max_body {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("a frame of {len} bytes is over the limit of {max_body} bytes"),
        ));
    }
    let mut body = Vec::new();
    stream.take(len).read_to_end(&mut body)?;
    if body.len() as u64 != len {
        return Err(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            "frame body cut short",
        ));
    }
    Ok(Some(Frame {
        kind: header[0],
        id: number(0),
        a: number(1),
        b: number(2),
        body,
    }))
}

/// Encodes a value as little-endian CDR.
pub(crate) fn encode<T: serde::Serialize>(value: &T) -> Result<Vec<u8>, String> {
    cdr_encoding::to_vec::<T, byteorder::LittleEndian>(value).map_err(|e| e.to_string())
}

/// Decodes a value from little-endian CDR.
pub(crate) fn decode<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(bytes)
        .map(|(v, _)| v)
        .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip_and_oversized_ones_are_refused() {
        let (a, mut b) = UnixStream::pair().unwrap();
        let f = Frame {
            kind: JOB,
            id: 7,
            a: 1_500_000_000,
            b: 1 << 30,
            body: vec![1, 2, 3],
        };
        write_frame(&a, &f).unwrap();
        assert_eq!(read_frame(&mut b, 10).unwrap(), Some(f));
        write_frame(&a, &Frame::new(ANSWER, 1, vec![0; 11])).unwrap();
        assert!(read_frame(&mut b, 10).is_err());
        drop(a);
        let (a, mut b) = UnixStream::pair().unwrap();
        drop(a);
        assert_eq!(read_frame(&mut b, 10).unwrap(), None);
    }

    #[test]
    fn writing_to_a_closed_peer_is_an_error_not_a_signal() {
        let (a, b) = UnixStream::pair().unwrap();
        drop(b);
        assert!(write_frame(&a, &Frame::new(CANCEL, 1, vec![])).is_err());
    }

    #[test]
    fn cdr_keeps_nan_and_infinities() {
        let v = (f64::NAN, f64::INFINITY, "x".to_string(), Some(vec![1.5f64]));
        let back: (f64, f64, String, Option<Vec<f64>>) = decode(&encode(&v).unwrap()).unwrap();
        assert!(back.0.is_nan());
        assert_eq!(
            (back.1, back.2, back.3),
            (f64::INFINITY, "x".into(), Some(vec![1.5]))
        );
    }
}
