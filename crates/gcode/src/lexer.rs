//! One line of G-code into a [`Block`] of [`Word`]s (RS-274/NGC syntax as
//! LinuxCNC reads it: Kramer, Proctor and Messina, "The NIST RS274NGC
//! Interpreter — Version 3", NISTIR 6556, 2000, section 3.3, "Format of a
//! Line"): an optional block delete `/`, an optional line number `N`,
//! words of a letter and a real number, `( )` and `;` comments; spaces and
//! tabs are ignored outside comments; letters are case-insensitive.
//! Parameters (`#`), expressions (`[ ]`) and O-words are refused, never
//! skipped.

use crate::error::GcodeError;

/// A letter and its number, with the column of the letter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Word {
    /// The letter, upper case.
    pub letter: char,
    /// The number, parsed with full `f64` precision (Rust's correctly
    /// rounded `str::parse`).
    pub value: f64,
    /// 1-based column of the letter.
    pub column: usize,
}

/// One line of a program.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// 1-based line in the source.
    pub line: usize,
    /// The line starts with the block delete character `/`.
    pub deleted: bool,
    /// The `N` number, if any.
    pub line_number: Option<f64>,
    /// The words in their order.
    pub words: Vec<Word>,
}

impl Block {
    /// Whether the block has no words (blank, comment only, or `%`).
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }
}

/// Reads one line (without its line ending).
///
/// # Arguments
/// * `text` — the line; `line` — its 1-based number, for errors and the
///   block.
///
/// # Returns
/// The block; a line holding only `%` (the program delimiter) is an empty
/// block.
///
/// # Errors
/// [`GcodeError::Syntax`] for an unclosed comment, a letter without a
/// number, a malformed number, a stray character, a line number that is not
/// first; [`GcodeError::Unsupported`] for `#`, `[`, `O`;
/// [`GcodeError::BadValue`] for a number too large to be finite.
pub fn lex_line(text: &str, line: usize) -> Result<Block, GcodeError> {
    let chars: Vec<char> = text.chars().collect();
    let syntax = |column: usize, reason: String| GcodeError::Syntax {
        line,
        column,
        reason,
    };
    let mut block = Block {
        line,
        deleted: false,
        line_number: None,
        words: Vec::new(),
    };
    let mut i = 0;
    let skip_blank = |i: &mut usize| {
        while *i < chars.len() && (chars[*i] == ' ' || chars[*i] == '\t' || chars[*i] == '\r') {
            *i += 1;
        }
    };
    skip_blank(&mut i);
    if i < chars.len() && chars[i] == '%' {
        let rest: String = chars[i + 1..].iter().collect();
        let rest = rest.trim();
        if rest.is_empty() || rest.starts_with('(') || rest.starts_with(';') {
            return Ok(block);
        }
        return Err(syntax(
            i + 1,
            "text after the program delimiter %".to_string(),
        ));
    }
    if i < chars.len() && chars[i] == '/' {
        block.deleted = true;
        i += 1;
    }
    let mut first_word = true;
    loop {
        skip_blank(&mut i);
        let Some(&c) = chars.get(i) else {
            break;
        };
        let column = i + 1;
        match c {
            '(' => {
                let Some(end) = chars[i + 1..].iter().position(|d| *d == ')') else {
                    return Err(syntax(
                        column,
                        "comment ( without its closing )".to_string(),
                    ));
                };
                if chars[i + 1..i + 1 + end].contains(&'(') {
                    return Err(syntax(column, "nested comment".to_string()));
                }
                i += end + 2;
            }
            ';' => break,
            '#' | '[' => {
                return Err(GcodeError::Unsupported {
                    line,
                    column,
                    code: c.to_string(),
                    reason: "parameters and expressions are not read".to_string(),
                })
            }
            c if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                if letter == 'O' {
                    return Err(GcodeError::Unsupported {
                        line,
                        column,
                        code: "O".to_string(),
                        reason: "subroutines and control flow are not read".to_string(),
                    });
                }
                i += 1;
                let value_start = chars[i..]
                    .iter()
                    .position(|d| *d != ' ' && *d != '\t')
                    .map(|k| i + k);
                if let Some(k) = value_start.filter(|k| chars[*k] == '#' || chars[*k] == '[') {
                    return Err(GcodeError::Unsupported {
                        line,
                        column: k + 1,
                        code: chars[k].to_string(),
                        reason: "parameters and expressions are not read".to_string(),
                    });
                }
                let (value, next) = number(&chars, i)
                    .map_err(|reason| syntax(column, format!("{letter}: {reason}")))?;
                i = next;
                if !value.is_finite() {
                    return Err(GcodeError::BadValue {
                        line,
                        column,
                        word: letter.to_string(),
                        value,
                        reason: "not a finite number".to_string(),
                    });
                }
                if letter == 'N' {
                    if !first_word || block.line_number.is_some() {
                        return Err(syntax(
                            column,
                            "a line number N must come first".to_string(),
                        ));
                    }
                    block.line_number = Some(value);
                } else {
                    block.words.push(Word {
                        letter,
                        value,
                        column,
                    });
                }
                first_word = false;
            }
            _ => return Err(syntax(column, format!("unexpected character {c:?}"))),
        }
    }
    Ok(block)
}

/// A real number starting at `chars[i]` (blanks allowed inside, as
/// RS-274/NGC allows): optional sign, digits, optional point and digits, at
/// least one digit. Returns the value and the index after it.
fn number(chars: &[char], mut i: usize) -> Result<(f64, usize), String> {
    let mut text = String::new();
    let blank = |c: char| c == ' ' || c == '\t';
    while i < chars.len() && blank(chars[i]) {
        i += 1;
    }
    if let Some(&s) = chars.get(i) {
        if s == '+' || s == '-' {
            text.push(s);
            i += 1;
        }
    }
    let mut digits = 0;
    let mut point = false;
    while let Some(&c) = chars.get(i) {
        if c.is_ascii_digit() {
            text.push(c);
            digits += 1;
        } else if c == '.' && !point {
            text.push(c);
            point = true;
        } else if !blank(c) {
            break;
        }
        i += 1;
    }
    if digits == 0 {
        return Err("needs a number".to_string());
    }
    let value: f64 = text
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    Ok((value, i))
}
