//! [`Program`]: a G-code source read line by line into [`Motion`]s, in
//! bounded memory (one line and one block's motions at a time).

use std::collections::VecDeque;
use std::io::BufRead;

use crate::error::GcodeError;
use crate::interpreter::Interpreter;
use crate::lexer::lex_line;
use crate::motion::Motion;
use crate::settings::ReaderSettings;

/// The longest line read \[bytes\]: a longer one is a syntax error (a
/// binary or single-line file would otherwise be read whole).
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// A program being read: an iterator of motions that stops at the first
/// error (which it yields) and at the end of the source.
#[derive(Debug)]
pub struct Program<R> {
    source: R,
    interpreter: Interpreter,
    line: usize,
    pending: VecDeque<Motion>,
    buffer: Vec<u8>,
    done: bool,
    skipped: usize,
    max_lines: Option<usize>,
}

impl<R: BufRead> Program<R> {
    /// Reads `source` with `settings`.
    ///
    /// # Errors
    /// [`ReaderSettings::validate`].
    pub fn new(source: R, settings: ReaderSettings) -> Result<Self, GcodeError> {
        Ok(Self {
            source,
            interpreter: Interpreter::new(settings)?,
            line: 0,
            pending: VecDeque::new(),
            buffer: Vec::new(),
            done: false,
            skipped: 0,
            max_lines: None,
        })
    }

    /// Reads at most `max` lines: a program with a line `max + 1` (whatever it holds: a
    /// comment, a blank line) is refused with [`GcodeError::TooManyLines`] naming that line
    /// as soon as it is reached, before it is read further (no limit by default).
    pub fn with_max_lines(mut self, max: usize) -> Self {
        self.max_lines = Some(max);
        self
    }

    /// Lines read so far.
    pub fn lines_read(&self) -> usize {
        self.line
    }

    /// Blocks skipped by the block delete switch so far
    /// ([`ReaderSettings::block_delete`]).
    pub fn skipped_blocks(&self) -> usize {
        self.skipped
    }

    /// The interpreter (modal state and position after the lines read).
    pub fn interpreter(&self) -> &Interpreter {
        &self.interpreter
    }

    /// Reads the next line into `self.buffer`; `Ok(false)` at the end.
    fn read_line(&mut self) -> Result<bool, GcodeError> {
        self.buffer.clear();
        let line = self.line + 1;
        let io = |e: std::io::Error| GcodeError::Io {
            line,
            message: e.to_string(),
        };
        loop {
            let available = self.source.fill_buf().map_err(io)?;
            if available.is_empty() {
                return Ok(!self.buffer.is_empty());
            }
            let (take, found) = match available.iter().position(|b| *b == b'\n') {
                Some(k) => (k + 1, true),
                None => (available.len(), false),
            };
            if self.buffer.len() + take > MAX_LINE_BYTES {
                return Err(GcodeError::Syntax {
                    line,
                    column: MAX_LINE_BYTES,
                    reason: format!("line longer than {MAX_LINE_BYTES} bytes"),
                });
            }
            self.buffer.extend_from_slice(&available[..take]);
            self.source.consume(take);
            if found {
                return Ok(true);
            }
        }
    }

    fn advance(&mut self) -> Result<bool, GcodeError> {
        if let Some(max) = self.max_lines.filter(|max| self.line >= *max) {
            // Only a line that is there is beyond the limit: a program of exactly `max`
            // lines (with or without its final line ending) is read whole.
            if self
                .source
                .fill_buf()
                .map_err(|e| GcodeError::Io {
                    line: self.line + 1,
                    message: e.to_string(),
                })?
                .is_empty()
            {
                return Ok(false);
            }
            return Err(GcodeError::TooManyLines { line: max + 1, max });
        }
        if !self.read_line()? {
            return Ok(false);
        }
        self.line += 1;
        let line = self.line;
        while matches!(self.buffer.last(), Some(b'\n' | b'\r')) {
            self.buffer.pop();
        }
        let text = std::str::from_utf8(&self.buffer).map_err(|e| GcodeError::Syntax {
            line,
            column: e.valid_up_to() + 1,
            reason: "not UTF-8 text".to_string(),
        })?;
        let block = lex_line(text, line)?;
        if block.deleted && self.interpreter.settings().block_delete && !block.is_empty() {
            self.skipped += 1;
        }
        let mut out = Vec::new();
        self.interpreter.execute(&block, &mut out)?;
        self.pending.extend(out);
        Ok(true)
    }
}

impl<R: BufRead> Iterator for Program<R> {
    type Item = Result<Motion, GcodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(m) = self.pending.pop_front() {
                return Some(Ok(m));
            }
            if self.done {
                return None;
            }
            match self.advance() {
                Ok(true) => {}
                Ok(false) => {
                    self.done = true;
                }
                Err(e) => {
                    self.done = true;
                    self.pending.clear();
                    return Some(Err(e));
                }
            }
        }
    }
}

/// Reads a whole program held in memory.
///
/// # Errors
/// The first [`GcodeError`] of the program.
pub fn read_program(text: &str, settings: ReaderSettings) -> Result<Vec<Motion>, GcodeError> {
    Program::new(text.as_bytes(), settings)?.collect()
}
